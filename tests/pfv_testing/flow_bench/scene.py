"""The benchmark's scenes: dense packings of N spheres made once by radius growth and cached, the permeameter and
oedometer built from them in YADE, and the two engines set up alike."""
import ast
import datetime
import json
import math
import os
import time

FORMAT_VERSION = 1  # of the packing files
SEED = 1
DP = 100.0  # permeameter pressure drop [Pa] (1 % of the 10 kPa confinement)
VISCOSITY = 1e-3  # permeameter viscosity [Pa s]
STRESS = -1.0e4  # confining stress of the packings [Pa]
YOUNG = 1.0e6
OEDO_VISCOSITY = 10.0
OEDO_LOAD = -1.1e4
OEDO_DT = 1e-4
AXIS = 1  # flow along y


def log(*args):
    print('bench:', *args, flush=True)


def cache_dir():
    return os.environ.get('PFV_CACHE_DIR') or os.path.join(os.path.expanduser('~'), '.cache', 'pfv')


def packing_path(n):
    return os.path.join(cache_dir(), 'bench_packing_v%d_n%d_s%d.txt' % (FORMAT_VERSION, n, SEED))


def box_side(n):
    return (n / 1000.0) ** (1.0 / 3.0)


def read_packing(n):
    """(spheres [(x,y,z,r)], meta dict) from the cache file."""
    meta, spheres = {}, []
    with open(packing_path(n)) as f:
        for line in f:
            if line.startswith('#'):
                if line.startswith('# meta '):
                    meta = json.loads(line[len('# meta ') :])
                continue
            if line.strip():
                spheres.append(tuple(float(v) for v in line.split()))
    return spheres, meta


def packing_digest(spheres):
    import hashlib

    h = hashlib.sha256()
    for s in spheres:
        h.update((' '.join(repr(v) for v in s) + '\n').encode())
    return h.hexdigest()[:16]


def generate_packing(n):
    """Radius-growth compaction (runs in a child yade process); writes the cache file."""
    from yade import O, pack, utils
    from yade.wrapper import (
        Bo1_Box_Aabb,
        Bo1_Sphere_Aabb,
        ForceResetter,
        FrictMat,
        GlobalStiffnessTimeStepper,
        Ig2_Box_Sphere_ScGeom,
        Ig2_Sphere_Sphere_ScGeom,
        InsertionSortCollider,
        InteractionLoop,
        Ip2_FrictMat_FrictMat_FrictPhys,
        Law2_ScGeom_FrictPhys_CundallStrack,
        NewtonIntegrator,
        TriaxialStressController,
    )

    t0 = time.time()
    L = box_side(n)
    O.reset()
    O.materials.append(FrictMat(young=YOUNG, poisson=0.5, frictionAngle=math.radians(3), density=2600, label='spheres'))
    O.materials.append(FrictMat(young=YOUNG, poisson=0.5, frictionAngle=0, density=0, label='walls'))
    O.bodies.append(utils.aabbWalls([(0, 0, 0), (L, L, L)], thickness=0, material='walls'))
    sp = pack.SpherePack()
    sp.makeCloud((0, 0, 0), (L, L, L), -1, 0.3333, n, False, 0.7, seed=SEED)
    sp.toSimulation(material='spheres')
    triax = TriaxialStressController(
        maxMultiplier=1.0 + 2e4 / YOUNG,
        finalMaxMultiplier=1.0 + 2e3 / YOUNG,
        thickness=0,
        stressMask=7,
        max_vel=0.005,
        internalCompaction=True,
    )
    triax.goal1 = triax.goal2 = triax.goal3 = STRESS
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
        NewtonIntegrator(damping=0.5),
    ]
    max_iter = 30000
    while True:
        O.run(100, True)
        unb = utils.unbalancedForce()
        if unb < 0.01 and abs(STRESS - triax.meanStress) / abs(STRESS) < 0.01:
            break
        if O.iter >= max_iter:
            log('WARNING: compaction of %d spheres stopped at %d iterations (unbalanced force %.3g)' % (n, O.iter, unb))
            break
        if O.iter % 1000 == 0:
            log('  compaction n=%d iter %d unbalanced %.3g mean stress %.4g' % (n, O.iter, unb, triax.meanStress))
    spheres = [(b.state.pos[0], b.state.pos[1], b.state.pos[2], b.shape.radius) for b in O.bodies if b.id >= 6]
    vs = sum(4.0 / 3.0 * math.pi * s[3] ** 3 for s in spheres)
    radii = [s[3] for s in spheres]
    meta = dict(
        n=n,
        seed=SEED,
        box=L,
        porosity=1 - vs / L**3,
        iterations=O.iter,
        seconds=time.time() - t0,
        unbalanced=unb,
        mean_stress=triax.meanStress,
        r_min=min(radii),
        r_max=max(radii),
        r_mean=sum(radii) / len(radii),
        threads=O.numThreads,
        date=datetime.date.today().isoformat(),
        method='makeCloud(porosity 0.7, rRelFuzz 1/3, seed %d) + radius growth (TriaxialStressController '
        'internalCompaction, E=1e6, 3 deg, damping 0.5) to 10 kPa, unbalanced force < 0.01' % SEED,
    )
    O.reset()
    os.makedirs(cache_dir(), exist_ok=True)
    tmp = packing_path(n) + '.tmp%d' % os.getpid()
    with open(tmp, 'w') as f:
        f.write('# pfv benchmark packing: x y z r (repr floats); walls = cube [0, box]^3\n')
        f.write('# meta ' + json.dumps(meta) + '\n')
        for s in spheres:
            f.write(' '.join(repr(float(v)) for v in s) + '\n')
    os.replace(tmp, packing_path(n))
    log(
        'packing n=%d: %d iterations, %.1f s, porosity %.4f, unbalanced force %.3g'
        % (n, meta['iterations'], meta['seconds'], meta['porosity'], unb)
    )
    return meta


def build_scene(n, oedometer=False, settle=True):
    """Build the scene from the cached packing in a reset O. Returns info dict."""
    from yade import O, utils
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
        TriaxialStressController,
    )

    spheres, meta = read_packing(n)
    L = meta.get('box', box_side(n))
    O.reset()
    O.materials.append(
        FrictMat(young=YOUNG, poisson=0.5, frictionAngle=math.radians(30), density=2600, label='spheres')
    )
    O.materials.append(FrictMat(young=YOUNG, poisson=0.5, frictionAngle=0, density=0, label='walls'))
    walls = O.bodies.append(utils.aabbWalls([(0, 0, 0), (L, L, L)], thickness=0, material='walls'))
    assert walls == list(range(6)), walls
    sphere = utils.sphere
    O.bodies.append([sphere((x, y, z), r, material='spheres') for x, y, z, r in spheres])
    engines = [
        ForceResetter(),
        InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Box_Aabb()]),
        InteractionLoop(
            [Ig2_Sphere_Sphere_ScGeom(), Ig2_Box_Sphere_ScGeom()],
            [Ip2_FrictMat_FrictMat_FrictPhys()],
            [Law2_ScGeom_FrictPhys_CundallStrack()],
        ),
    ]
    if oedometer:
        triax = TriaxialStressController(
            thickness=0, stressMask=2, max_vel=0.005, internalCompaction=False, label='triax'
        )
        triax.goal1 = triax.goal3 = 0
        triax.goal2 = STRESS
        triax.wall_bottom_activated = False
        engines.append(triax)
    engines.append(NewtonIntegrator(damping=0.0 if oedometer else 0.2, label='newton'))
    O.engines = engines
    # Oedometer: O.dt = 1e-4 as in YADE's example (viscosity 10: the explicit coupling is unstable at 0.5 P-wave
    # step, about 9e-4, with either engine).
    O.dt = OEDO_DT if oedometer else 0.5 * utils.PWaveTimeStep()
    O.dynDt = False
    # Settle: the file has no contact history (the shear forces of the compaction are lost, unbalanced force ~0.05
    # after rebuilding); relax with damping 0.5 until the unbalanced force is below 0.01 so that the steps measured
    # are quasi-static.  The first collider pass and the contact creation also happen here.
    newton = O.engines[-1]
    newton.damping = 0.5
    steps = 0
    while True:
        O.run(50, True)
        steps += 50
        unb = utils.unbalancedForce()
        if not settle or unb < 0.01 or steps >= 1000:
            break
    newton.damping = 0.0 if oedometer else 0.2
    return dict(
        n=n,
        box=L,
        digest=packing_digest(spheres),
        meta=meta,
        dt=O.dt,
        bodies=len(O.bodies),
        settle_steps=steps,
        unbalanced=unb,
    )


def make_engine(kind, oedometer=False, oedo_interval=200):
    """kind: 'yade', 'pfv' (defaults) or 'pfv-double' (pfv with mixed_precision=False)."""
    if kind == 'yade':
        from yade.wrapper import FlowEngine as Flow
    else:
        from pfv import FlowEngine as Flow
    flow = Flow()
    flow.label = 'flow'
    isP, val = [False] * 6, [0.0] * 6
    if oedometer:
        isP[3] = True  # drained top (ymax), p = 0; the rest impermeable
        flow.viscosity = OEDO_VISCOSITY
        flow.meshUpdateInterval = oedo_interval
        flow.defTolerance = 0.3
    else:
        isP[2 * AXIS] = isP[2 * AXIS + 1] = True
        val[2 * AXIS] = DP
        flow.viscosity = VISCOSITY
        flow.meshUpdateInterval = 10**9
        flow.defTolerance = 0.0
    flow.wallIds = [0, 1, 2, 3, 4, 5]
    flow.bndCondIsPressure = isP
    flow.bndCondValue = val
    flow.boundaryUseMaxMin = [False] * 6
    flow.permeabilityFactor = 1.0
    flow.useSolver = 3
    flow.slipBoundary = False  # YADE's slip factor on wall throats is a known model difference (-15 % flux)
    if kind.startswith('pfv'):
        # PFV options under test, e.g. PFV_BENCH_SET="mixed_precision=False" (inherited by the children).
        for item in filter(None, os.environ.get('PFV_BENCH_SET', '').split(',')):
            name, value = item.split('=', 1)
            setattr(flow, name.strip(), ast.literal_eval(value.strip()))
    if kind == 'pfv-double':
        flow.mixed_precision = False  # the double factor, every solve direct: the reference of the default
    return flow


def insert_engine(flow):
    from yade import O
    from yade.wrapper import NewtonIntegrator

    engines = list(O.engines)
    i = [k for k, e in enumerate(engines) if isinstance(e, NewtonIntegrator)][0]
    engines.insert(i, flow)
    O.engines = engines


def core_timer(flow):
    """The C++ engine of a pfv FlowEngine, whose step_times()['total'] is the wall time of its last
    core step (to split C++ from Python/exchange time), or None for YADE's engine."""
    return getattr(flow, 'core', None)


def probe_points(L, n=3, margin=0.25):
    rel = [margin + (1 - 2 * margin) * k / (n - 1) for k in range(n)]
    return [(L * a, L * b, L * c) for a in rel for b in rel for c in rel]
