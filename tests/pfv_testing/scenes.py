"""Deterministic scenes for side-by-side runs of YADE's FlowEngine and pfv.FlowEngine.

Import from a script run by yade-double (build/python on PYTHONPATH):

    from pfv_testing import scenes
    ids = scenes.build_permeameter()            # walls 0..5, then the spheres
    flow = FlowEngine(label='flow')
    scenes.configure_flow(flow, axis=1, dp=1.0)

The 1000-sphere packing (seed 1, unit box) is shipped in tests/data/packings/ (made with yade-double -j1), so it is
bit-identical on every machine.  Other packings are produced once by DEM compaction (makeCloud with a fixed seed,
then particle growth under a TriaxialStressController until the mean stress is reached), written to a text cache
with every float in repr()
form, and every scene is built *from that file*, so two builds of the same scene are bit-identical (the first
build included).  The cache lives in $PFV_SCENE_CACHE or /tmp/pfv-yade-scenes.  The compaction runs every
engine with ompThreads=1; regenerating the cache gives the same packing for the same `yade -jN` (it does differ
between -j1 and -j2, in the last digits: the collider's parallel code ignores ompThreads).
"""
import hashlib
import math
import os
import tempfile

from pfv_testing import paths
from yade import O, pack, utils
from yade.wrapper import (
    Bo1_Box_Aabb,
    Bo1_Sphere_Aabb,
    ForceResetter,
    FrictMat,
    Ig2_Box_Sphere_ScGeom,
    Ig2_Sphere_Sphere_ScGeom,
    InsertionSortCollider,
    InteractionLoop,
    Ip2_FrictMat_FrictMat_FrictPhys,
    Law2_ScGeom_FrictPhys_CundallStrack,
    NewtonIntegrator,
    GlobalStiffnessTimeStepper,
    TriaxialStressController,
)

CACHE_DIR = os.environ.get('PFV_SCENE_CACHE', '/tmp/pfv-yade-scenes')
DATA_DIR = paths.PACKINGS
FORMAT_VERSION = 1

# wall order of utils.aabbWalls and of FlowEngine.wallIds / bndCondIsPressure / bndCondValue
XMIN, XMAX, YMIN, YMAX, ZMIN, ZMAX = range(6)
WALL_NAMES = ('xmin', 'xmax', 'ymin', 'ymax', 'zmin', 'zmax')


def _cache_path(num, seed, box):
    tag = 'perm_v%d_n%d_s%d_%s' % (FORMAT_VERSION, num, seed, '_'.join('%g' % v for v in box))
    return os.path.join(CACHE_DIR, tag + '.txt')


def _compact(num, seed, box, stress=-1.0e4, young=1.0e6, maxIter=200000):
    """DEM compaction in the current (reset) scene. Returns [(x, y, z, r), ...] in sphere order."""
    mn, mx = (0.0, 0.0, 0.0), tuple(box)
    O.reset()
    O.materials.append(FrictMat(young=young, poisson=0.5, frictionAngle=math.radians(3), density=2600, label='spheres'))
    O.materials.append(FrictMat(young=young, poisson=0.5, frictionAngle=0, density=0, label='walls'))
    O.bodies.append(utils.aabbWalls([mn, mx], thickness=0, material='walls'))
    sp = pack.SpherePack()
    sp.makeCloud(mn, mx, -1, 0.3333, num, False, 0.95, seed=seed)
    sp.toSimulation(material='spheres')
    triax = TriaxialStressController(
        maxMultiplier=1.0 + 2e4 / young,
        finalMaxMultiplier=1.0 + 2e3 / young,
        thickness=0,
        stressMask=7,
        max_vel=0.005,
        internalCompaction=True,
    )
    triax.goal1 = triax.goal2 = triax.goal3 = stress
    O.engines = [
        ForceResetter(),
        InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Box_Aabb()]),
        InteractionLoop(
            [Ig2_Sphere_Sphere_ScGeom(), Ig2_Box_Sphere_ScGeom()],
            [Ip2_FrictMat_FrictMat_FrictPhys()],
            [Law2_ScGeom_FrictPhys_CundallStrack()],
        ),
        GlobalStiffnessTimeStepper(active=1, timeStepUpdateInterval=100, timestepSafetyCoefficient=0.8),
        triax,
        NewtonIntegrator(damping=0.2),
    ]
    for e in O.engines:  # one thread everywhere: the packing must not depend on yade -jN
        e.ompThreads = 1
    while O.iter < maxIter:
        O.run(500, True)
        if utils.unbalancedForce() < 0.01 and abs(stress - triax.meanStress) / abs(stress) < 0.01:
            break
    else:
        raise RuntimeError('scenes: compaction did not converge in %d iterations' % maxIter)
    print(
        'scenes: compacted %d spheres in %d iterations, mean stress %g, unbalanced force %g'
        % (num, O.iter, triax.meanStress, utils.unbalancedForce())
    )
    out = [(b.state.pos[0], b.state.pos[1], b.state.pos[2], b.shape.radius) for b in O.bodies if b.id >= 6]
    O.reset()
    return out


def packing(num=1000, seed=1, box=(1.0, 1.0, 1.0), regenerate=False):
    """[(x, y, z, r), ...] of the dense packing.

    Read from tests/data/packings/ if the file for these parameters is shipped there, else from the cache, else made by
    compaction and cached. Destroys the current scene when it has to generate the packing."""
    shipped = os.path.join(DATA_DIR, os.path.basename(_cache_path(num, seed, box)))
    path = _cache_path(num, seed, box)
    if not regenerate and os.path.exists(shipped):
        path = shipped
    elif regenerate or not os.path.exists(path):
        spheres = _compact(num, seed, box)
        os.makedirs(CACHE_DIR, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=CACHE_DIR, prefix='.tmp-')
        with os.fdopen(fd, 'w') as f:
            f.write(
                '# pfv permeameter packing: num=%d seed=%d box=%r; x y z r (repr floats)\n' % (num, seed, tuple(box))
            )
            for s in spheres:
                f.write(' '.join(repr(float(v)) for v in s) + '\n')
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)  # atomic: concurrent runs never see a half-written file
    with open(path) as f:
        return [tuple(float(v) for v in line.split()) for line in f if line.strip() and not line.startswith('#')]


def packing_digest(spheres):
    """Short sha256 of the packing, to print and compare across runs."""
    h = hashlib.sha256()
    for s in spheres:
        h.update((' '.join(repr(v) for v in s) + '\n').encode())
    return h.hexdigest()[:16]


def build_permeameter(num=1000, seed=1, box=(1.0, 1.0, 1.0), frozen=True, reset=True):
    """Build the permeameter in O: aabbWalls (ids 0..5: xmin,xmax,ymin,ymax,zmin,zmax), then the spheres.

    frozen=True blocks all DOFs of the spheres (blockedDOFs='xyzXYZ'); the walls are non-dynamic anyway.
    Also sets basic DEM engines (ForceResetter, collider, InteractionLoop, NewtonIntegrator(damping=0)) and O.dt;
    a flow engine is to be inserted before NewtonIntegrator by the caller (see insert_flow).
    Returns dict(walls=[0..5], spheres=[ids], digest=str, box=box)."""
    spheres = packing(num, seed, box)
    return dict(build_box(spheres, box, frozen, reset), digest=packing_digest(spheres))


def build_box(spheres, box, frozen=True, reset=True):
    """The permeameter of build_permeameter with the spheres [(x, y, z, r), ...] in the box [0, box]: walls 0..5,
    then the spheres, the DEM engines and O.dt. Returns dict(walls=[0..5], spheres=[ids], box=box)."""
    if reset:
        O.reset()
    O.materials.append(FrictMat(young=1e6, poisson=0.5, frictionAngle=math.radians(30), density=2600, label='spheres'))
    O.materials.append(FrictMat(young=1e6, poisson=0.5, frictionAngle=0, density=0, label='walls'))
    walls = O.bodies.append(utils.aabbWalls([(0.0, 0.0, 0.0), tuple(box)], thickness=0, material='walls'))
    assert walls == list(range(6)), walls
    ids = []
    for x, y, z, r in spheres:
        b = utils.sphere((x, y, z), r, material='spheres')
        if frozen:
            b.state.blockedDOFs = 'xyzXYZ'
        ids.append(O.bodies.append(b))
    O.engines = [
        ForceResetter(),
        InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Box_Aabb()]),
        InteractionLoop(
            [Ig2_Sphere_Sphere_ScGeom(), Ig2_Box_Sphere_ScGeom()],
            [Ip2_FrictMat_FrictMat_FrictPhys()],
            [Law2_ScGeom_FrictPhys_CundallStrack()],
        ),
        NewtonIntegrator(damping=0, label='newton'),
    ]
    O.dt = 1e-5
    return dict(walls=walls, spheres=ids, box=tuple(box))


def insert_flow(flow):
    """Put `flow` into O.engines just before NewtonIntegrator (replacing any engine labelled like it or any
    existing flow engine at that place). Returns the engine list index."""
    engines = [e for e in O.engines if not (flow.label and getattr(e, 'label', None) == flow.label)]
    i = [k for k, e in enumerate(engines) if isinstance(e, NewtonIntegrator)][0]
    engines.insert(i, flow)
    O.engines = engines
    return i


def configure_flow(flow, axis=1, dp=1.0, p_out=0.0, viscosity=1.0, permeabilityFactor=1.0, useWalls=True, **extra):
    """Common settings for a permeameter, for YADE's FlowEngine or any object with the same attribute names.

    Pressure p_out+dp on the min wall of `axis` (0=x, 1=y, 2=z), p_out on the max wall, the four other walls
    impermeable; boundaries at the wall positions (boundaryUseMaxMin all False) if useWalls.
    Remaining keyword arguments are set as attributes as they are (e.g. useSolver=3, meshUpdateInterval=1000).
    Returns the flow object."""
    lo, hi = 2 * axis, 2 * axis + 1
    isP = [False] * 6
    val = [0.0] * 6
    isP[lo] = isP[hi] = True
    val[lo] = float(p_out + dp)
    val[hi] = float(p_out)
    flow.wallIds = [0, 1, 2, 3, 4, 5]
    flow.bndCondIsPressure = isP
    flow.bndCondValue = val
    flow.boundaryUseMaxMin = [not useWalls] * 6
    flow.viscosity = float(viscosity)
    flow.permeabilityFactor = float(permeabilityFactor)
    for k, v in extra.items():
        if not hasattr(flow, k):
            raise AttributeError('%s has no attribute %r' % (type(flow).__name__, k))
        setattr(flow, k, v)
    return flow


def probe_points(box=(1.0, 1.0, 1.0), n=3, margin=0.25):
    """n^3 points on a regular grid inside the box, at relative positions margin..1-margin."""
    if n == 1:
        rel = [0.5]
    else:
        rel = [margin + (1 - 2 * margin) * k / (n - 1) for k in range(n)]
    return [(box[0] * a, box[1] * b, box[2] * c) for a in rel for b in rel for c in rel]
