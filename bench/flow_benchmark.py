"""Side-by-side benchmark of YADE's FlowEngine and PFV's FlowEngine.

Run with YADE (the driver re-invokes yade-double on this file for every measurement):

    yade-double -n -x bench/flow_benchmark.py [--quick] [--sizes=1000,10000,50000] [--rounds=3]
                [--threads=1,2] [--out=doc/benchmarks.md] [--json=FILE] [--no-memory] [--no-oedometer]
                [--no-multithread] [--no-double] [--oedo-sizes=1000,10000] [--oedo-steps=600] [--oedo-interval=200]
                [--steady=20]
                [--gen-threads=T]    (threads of the child that generates a missing packing; default max of --threads)
    yade-double -n -x bench/flow_benchmark.py --report-only --json=FILE [--out=doc/benchmarks.md]
    yade-double -n -x bench/flow_benchmark.py --startup --report-only --json=FILE [--out=doc/benchmarks.md]
                (the report of an earlier full run from its JSON, for a change of the report's layout)
    yade-double -n -x bench/flow_benchmark.py --startup [--sizes=10000,50000] [--rounds=3] [--threads=1]
                [--steady=5] [--out=doc/benchmarks.md]

--startup: only the start-up of the engines (issue 19 item 1): YADE and PFV trials (as in 2. below, 5 steady steps
unless --steady is given, the order swapped every round) at --sizes (default 10000,50000) and -j1; reports the
first-step/remesh ratio of PFV (target <= 1.2), PFV/YADE first step (target <= 0.5) and where PFV's first step spends
the time it does not spend in a remesh (ordering, factorisation, the cold collective viscous limit, Python), into its
own markers in --out (the full report's section is left alone), JSON in /tmp/bench/flow_benchmark-startup.json.

--quick: 300 spheres, 1 round, -j1, 10 steady steps, oedometer 60 steps with a remesh every 20, report written to
/tmp/bench/benchmarks-quick.md unless --out is given (tests/yade/test_bench_quick.py runs it).

What it does
  1. Packings: dense packings of N spheres (N in --sizes) in a cube of side (N/1000)^(1/3) (so the sphere size does not
     depend on N), made once by radius growth under a TriaxialStressController (makeCloud at porosity 0.7, growth to a
     mean stress of 10 kPa with E = 1 MPa, 3 deg friction, damping 0.5) and cached as text in
     $PFV_CACHE_DIR or ~/.cache/pfv (bench_packing_v1_n<N>_s1.txt).  Every scene below is built from that file.
  2. Timing (one yade process per thread count, `yade-double -jT`): for each N the permeameter scene (the packing,
     six fixed walls, spheres *dynamic* (no blocked DOFs), friction 30 deg, no gravity, pressure drop 100 Pa along y =
     1 % of the confining stress, viscosity 1e-3, O.dt = 0.5 P-wave step, slipBoundary=False in both engines) is
     settled (damping 0.5 until the unbalanced force is < 0.01: the file has no contact history), saved once with
     O.saveTmp, and every trial starts from it.  Trials are interleaved YADE / PFV / dry / PFV-double (PFV with
     mixed_precision=False, the direct double solve the default is refined towards; not with --no-double), rotating
     the order every round.  A trial runs
     W=3 first steps, S steady steps, a forced remesh (updateTriangulation=True) followed by W steps, and 3 more steps,
     timing every O.step() (wall clock) and the engine's execTime (O.timingEnabled).  Both engines use CHOLMOD
     (useSolver=3), meshUpdateInterval=1e9, defTolerance=0, everything else at its default.
  3. Memory (one fresh `yade-double -j1` per engine and N): VmRSS before the engine is added, peak (VmHWM after
     resetting it through /proc/self/clear_refs) and VmRSS after a first step, S steady steps and a forced remesh.
  4. Oedometer (coupled/dry cost ratio): the packing with the top wall under a TriaxialStressController (stressMask=2,
     load step 10 -> 11 kPa), drained top, impermeable other walls, viscosity 10, meshUpdateInterval=200,
     defTolerance=0.3, O.dt=1e-4 (as in YADE's examples/FluidCouplingPFV/oedometer.py), O.run(M) timed for YADE,
     PFV and dry, interleaved like the trials; and (unless --no-multithread) both engines again with
     multithread=True, the remesh built in a background thread while the DEM runs (PFV's background_remesh).
  Children run with OPENBLAS_NUM_THREADS = OMP_NUM_THREADS = T (Debian's OpenBLAS would use every core otherwise).

Definitions (medians over rounds of per-trial medians)
  flow step   : engine execTime of a steady step (no remesh)
  remesh      : engine execTime summed over the W steps from the forced remesh minus (W-1) flow steps, i.e. one flow
                step with remesh (triangulation, geometry, assembly, ordering, factorisation, first solve, forces).
                YADE remeshes at the end of the step and factorises in the next one: the window covers both.
  coupled     : wall clock of O.step() in a steady step with the engine;  dry: the same without flow engine.

Output: a Markdown report (between markers in --out, text outside the markers is kept), the same tables on stdout, and
the raw per-trial data as JSON (--json, default /tmp/bench/flow_benchmark.json).  No timing is asserted anywhere.
"""
import datetime
import gc
import ast
import json
import math
import os
import platform
import shutil
import statistics
import subprocess
import sys
import time
import traceback

FORMAT_VERSION = 1          # of the packing files
REPORT_VERSION = 1          # of the Markdown/JSON layout
SEED = 1
BEGIN_MARK = '<!-- BEGIN flow_benchmark output (generated by bench/flow_benchmark.py; edits inside are overwritten) -->'
END_MARK = '<!-- END flow_benchmark output -->'
STARTUP_BEGIN_MARK = ('<!-- BEGIN flow_benchmark --startup output (generated by bench/flow_benchmark.py --startup; '
                      'edits inside are overwritten) -->')
STARTUP_END_MARK = '<!-- END flow_benchmark --startup output -->'

WINDOW = 3                  # steps timed after a (forced) remesh
DP = 100.0                  # permeameter pressure drop [Pa] (1 % of the 10 kPa confinement)
VISCOSITY = 1e-3            # permeameter viscosity [Pa s]
STRESS = -1.0e4             # confining stress of the packings [Pa]
YOUNG = 1.0e6
OEDO_VISCOSITY = 10.0
OEDO_LOAD = -1.1e4
OEDO_DT = 1e-4
AXIS = 1                    # flow along y


def _here():
    if sys.argv and sys.argv[0].endswith('.py'):
        return os.path.dirname(os.path.abspath(sys.argv[0]))
    return os.path.dirname(os.path.abspath(__file__))


SCRIPT = os.path.join(_here(), os.path.basename(sys.argv[0]) if sys.argv and sys.argv[0].endswith('.py')
                      else 'flow_benchmark.py')
REPO = os.path.dirname(_here())
sys.path.insert(0, _here())
from proc_memory import reset_peak, rss_kb  # noqa: E402


def log(*args):
    print('bench:', *args, flush=True)


# ---------------------------------------------------------------------------------------------------------------
# options
# ---------------------------------------------------------------------------------------------------------------
def parse_args(argv):
    quick = '--quick' in argv
    startup = '--startup' in argv
    opts = dict(
        quick=quick,
        startup=startup,
        sizes=[300] if quick else [10000, 50000] if startup else [1000, 10000, 50000],
        rounds=1 if quick else 3,
        threads=[1] if quick or startup else [1, 2],
        out=None,
        json=None,
        memory=True,
        oedometer=True,
        multithread=True,
        double=True,
        oedo_sizes=None,
        oedo_steps=60 if quick else 600,
        oedo_interval=20 if quick else 200,
        steady=10 if quick else 5 if startup else 20,
        child=None,
        size=None,
        engine=None,
        child_json=None,
        gen_threads=None,
        report_only=False,
    )
    for a in argv:
        if a in ('--quick', '--startup'):
            continue
        if a == '--report-only':
            opts['report_only'] = True
            continue
        if a == '--no-memory':
            opts['memory'] = False
            continue
        if a == '--no-oedometer':
            opts['oedometer'] = False
            continue
        if a == '--no-multithread':
            opts['multithread'] = False
            continue
        if a == '--no-double':
            opts['double'] = False
            continue
        if not a.startswith('--') or '=' not in a:
            raise SystemExit('flow_benchmark: unknown argument %r (see the docstring)' % a)
        k, v = a[2:].split('=', 1)
        k = k.replace('-', '_')
        if k in ('sizes', 'threads', 'oedo_sizes'):
            opts[k] = [int(x) for x in v.split(',') if x]
        elif k in ('rounds', 'oedo_steps', 'oedo_interval', 'steady', 'size', 'gen_threads'):
            opts[k] = int(v)
        elif k in ('out', 'json', 'child', 'engine', 'child_json'):
            opts[k] = v
        else:
            raise SystemExit('flow_benchmark: unknown option --%s' % k)
    if opts['oedo_sizes'] is None:
        opts['oedo_sizes'] = [n for n in opts['sizes'] if n <= 10000] or [min(opts['sizes'])]
    if opts['out'] is None:
        opts['out'] = '/tmp/bench/benchmarks-quick.md' if quick else os.path.join(REPO, 'doc', 'benchmarks.md')
    if opts['json'] is None:
        opts['json'] = '/tmp/bench/flow_benchmark%s.json' % ('-quick' if quick else '-startup' if startup else '')
    return opts


def median(xs):
    xs = [x for x in xs if x is not None and x == x]
    return statistics.median(xs) if xs else float('nan')


# ---------------------------------------------------------------------------------------------------------------
# packings
# ---------------------------------------------------------------------------------------------------------------
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
                    meta = json.loads(line[len('# meta '):])
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
    from yade.wrapper import (Bo1_Box_Aabb, Bo1_Sphere_Aabb, ForceResetter, FrictMat, GlobalStiffnessTimeStepper,
                              Ig2_Box_Sphere_ScGeom, Ig2_Sphere_Sphere_ScGeom, InsertionSortCollider, InteractionLoop,
                              Ip2_FrictMat_FrictMat_FrictPhys, Law2_ScGeom_FrictPhys_CundallStrack, NewtonIntegrator,
                              TriaxialStressController)
    t0 = time.time()
    L = box_side(n)
    O.reset()
    O.materials.append(FrictMat(young=YOUNG, poisson=0.5, frictionAngle=math.radians(3), density=2600, label='spheres'))
    O.materials.append(FrictMat(young=YOUNG, poisson=0.5, frictionAngle=0, density=0, label='walls'))
    O.bodies.append(utils.aabbWalls([(0, 0, 0), (L, L, L)], thickness=0, material='walls'))
    sp = pack.SpherePack()
    sp.makeCloud((0, 0, 0), (L, L, L), -1, 0.3333, n, False, 0.7, seed=SEED)
    sp.toSimulation(material='spheres')
    triax = TriaxialStressController(maxMultiplier=1. + 2e4 / YOUNG, finalMaxMultiplier=1. + 2e3 / YOUNG, thickness=0,
                                     stressMask=7, max_vel=0.005, internalCompaction=True)
    triax.goal1 = triax.goal2 = triax.goal3 = STRESS
    O.engines = [
        ForceResetter(),
        InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Box_Aabb()]),
        InteractionLoop([Ig2_Sphere_Sphere_ScGeom(), Ig2_Box_Sphere_ScGeom()], [Ip2_FrictMat_FrictMat_FrictPhys()],
                        [Law2_ScGeom_FrictPhys_CundallStrack()]),
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
    meta = dict(n=n, seed=SEED, box=L, porosity=1 - vs / L ** 3, iterations=O.iter, seconds=time.time() - t0,
                unbalanced=unb, mean_stress=triax.meanStress, r_min=min(radii), r_max=max(radii),
                r_mean=sum(radii) / len(radii), threads=O.numThreads, date=datetime.date.today().isoformat(),
                method='makeCloud(porosity 0.7, rRelFuzz 1/3, seed %d) + radius growth (TriaxialStressController '
                       'internalCompaction, E=1e6, 3 deg, damping 0.5) to 10 kPa, unbalanced force < 0.01' % SEED)
    O.reset()
    os.makedirs(cache_dir(), exist_ok=True)
    tmp = packing_path(n) + '.tmp%d' % os.getpid()
    with open(tmp, 'w') as f:
        f.write('# pfv benchmark packing: x y z r (repr floats); walls = cube [0, box]^3\n')
        f.write('# meta ' + json.dumps(meta) + '\n')
        for s in spheres:
            f.write(' '.join(repr(float(v)) for v in s) + '\n')
    os.replace(tmp, packing_path(n))
    log('packing n=%d: %d iterations, %.1f s, porosity %.4f, unbalanced force %.3g'
        % (n, meta['iterations'], meta['seconds'], meta['porosity'], unb))
    return meta


# ---------------------------------------------------------------------------------------------------------------
# scenes
# ---------------------------------------------------------------------------------------------------------------
def build_scene(n, oedometer=False, settle=True):
    """Build the scene from the cached packing in a reset O. Returns info dict."""
    from yade import O, utils
    from yade.wrapper import (Bo1_Box_Aabb, Bo1_Sphere_Aabb, ForceResetter, FrictMat, Ig2_Box_Sphere_ScGeom,
                              Ig2_Sphere_Sphere_ScGeom, InsertionSortCollider, InteractionLoop,
                              Ip2_FrictMat_FrictMat_FrictPhys, Law2_ScGeom_FrictPhys_CundallStrack, NewtonIntegrator,
                              TriaxialStressController)
    spheres, meta = read_packing(n)
    L = meta.get('box', box_side(n))
    O.reset()
    O.materials.append(FrictMat(young=YOUNG, poisson=0.5, frictionAngle=math.radians(30), density=2600,
                                label='spheres'))
    O.materials.append(FrictMat(young=YOUNG, poisson=0.5, frictionAngle=0, density=0, label='walls'))
    walls = O.bodies.append(utils.aabbWalls([(0, 0, 0), (L, L, L)], thickness=0, material='walls'))
    assert walls == list(range(6)), walls
    sphere = utils.sphere
    O.bodies.append([sphere((x, y, z), r, material='spheres') for x, y, z, r in spheres])
    engines = [
        ForceResetter(),
        InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Box_Aabb()]),
        InteractionLoop([Ig2_Sphere_Sphere_ScGeom(), Ig2_Box_Sphere_ScGeom()], [Ip2_FrictMat_FrictMat_FrictPhys()],
                        [Law2_ScGeom_FrictPhys_CundallStrack()]),
    ]
    if oedometer:
        triax = TriaxialStressController(thickness=0, stressMask=2, max_vel=0.005, internalCompaction=False,
                                         label='triax')
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
    return dict(n=n, box=L, digest=packing_digest(spheres), meta=meta, dt=O.dt, bodies=len(O.bodies),
                settle_steps=steps, unbalanced=unb)


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
        flow.meshUpdateInterval = 10 ** 9
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


# ---------------------------------------------------------------------------------------------------------------
# timing child
# ---------------------------------------------------------------------------------------------------------------
def _yade_td(flow):
    """YADE FlowEngine timingDeltas as {label: seconds} (cumulative)."""
    try:
        return {lab: t * 1e-9 for lab, t, c in flow.timingDeltas.data}
    except Exception:
        return {}


def _td_diff(a, b):
    return {k: b.get(k, 0.0) - a.get(k, 0.0) for k in b}


def _dem_exec(flow):
    """Seconds of execTime of every engine but the flow engine so far (O.timingEnabled): the DEM
    part of a step, to compare the DEM of the coupled steps with the dry steps."""
    from yade import O
    return sum(e.execTime for e in O.engines if e is not flow) * 1e-9


def run_trial(kind, info, steady, warnings_seen):
    """One trial on the saved permeameter scene. kind in yade, pfv, dry."""
    import warnings
    from yade import O
    O.loadTmp('bench')
    O.timingEnabled = True
    gc.collect()
    res = dict(kind=kind)
    if kind == 'dry':
        for _ in range(WINDOW):
            O.step()
        wall, dem = [], []
        for _ in range(steady):
            d0 = _dem_exec(None)
            t0 = time.perf_counter()
            O.step()
            wall.append(time.perf_counter() - t0)
            dem.append(_dem_exec(None) - d0)
        res['steady_wall'] = wall
        res['steady_dem'] = dem
        res['vmax'] = max(b.state.vel.norm() for b in O.bodies)
        O.reset()
        return res

    flow = make_engine(kind)
    proxy = core_timer(flow) if kind.startswith('pfv') else None
    insert_engine(flow)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter('always')

        def step(record):
            e0 = flow.execTime
            d0 = _dem_exec(flow)
            t0 = time.perf_counter()
            O.step()
            wall = time.perf_counter() - t0
            ex = (flow.execTime - e0) * 1e-9
            record['wall'].append(wall)
            record['exec'].append(ex)
            record.setdefault('dem', []).append(_dem_exec(flow) - d0)
            if kind.startswith('pfv'):
                core = flow.core
                record.setdefault('step_times', []).append(dict(core.step_times()))
                record.setdefault('remesh_count', []).append(core.remesh_count)
                if proxy is not None:
                    record.setdefault('core_step', []).append(proxy.step_times()['total'])

        first = dict(wall=[], exec=[])
        td0 = _yade_td(flow)
        for _ in range(WINDOW):
            step(first)
        if kind.startswith('pfv'):
            first['remesh_times'] = dict(flow.core.remesh_times())
        st = dict(wall=[], exec=[])
        td1 = _yade_td(flow)
        c0, w0 = time.process_time(), time.perf_counter()
        for _ in range(steady):
            step(st)
        st['cpu_share'] = (time.process_time() - c0) / (time.perf_counter() - w0)
        td2 = _yade_td(flow)
        flow.updateTriangulation = True
        rem = dict(wall=[], exec=[])
        for _ in range(WINDOW):
            step(rem)
        td3 = _yade_td(flow)
        if kind.startswith('pfv'):
            rem['remesh_times'] = dict(flow.core.remesh_times())
        tail = dict(wall=[], exec=[])
        for _ in range(3):
            step(tail)
    for w in caught:
        msg = '%s: %s' % (w.category.__name__, str(w.message)[:200])
        if msg not in warnings_seen:
            warnings_seen.append(msg)
            log('warning from %s engine: %s' % (kind, msg))
    res.update(first=first, steady=st, remesh=rem, tail=tail, n_cells=flow.nCells())
    if kind == 'yade':
        res['td_first'] = _td_diff(td0, td1)
        res['td_steady'] = _td_diff(td1, td2)
        res['td_remesh'] = _td_diff(td2, td3)
    L = info['box']
    res['vmax'] = max(b.state.vel.norm() for b in O.bodies)
    res['probes'] = [flow.getPorePressure(p) for p in probe_points(L)]
    res['flux'] = [flow.getBoundaryFlux(2 * AXIS), flow.getBoundaryFlux(2 * AXIS + 1)]
    res['core_timer'] = proxy is not None
    if kind.startswith('pfv'):
        res['reduced'] = bool(flow.core.reduced_precision_factor())
        res['guard'] = [dict(h) for h in flow.collective_viscous_history]
        res['factor_nonzeros'] = flow.core.factor_nonzeros()
    # Release the engine before O.reset(); assigned, not deleted, because step() closes over both names.
    flow = proxy = None
    O.engines = O.engines[:1]
    O.reset()
    gc.collect()
    return res


def exchange_reference(info):
    """Times of the primitive exchange operations on the dry scene (for reference)."""
    import numpy as np
    import yade
    from yade import O
    O.loadTmp('bench')
    cad = yade._utils.coordsAndDisplacements
    ids = list(range(6, len(O.bodies)))
    zero = (0.0, 0.0, 0.0)
    read, write = [], []
    for _ in range(7):
        t0 = time.perf_counter()
        np.array([cad(0)[0], cad(1)[0], cad(2)[0]]).T
        read.append(time.perf_counter() - t0)
        add = O.forces.addF
        t0 = time.perf_counter()
        for i in ids:
            add(i, zero)
        write.append(time.perf_counter() - t0)
    O.reset()
    return dict(read_positions=median(read), write_forces=median(write))


def oedometer_trial(kind, n, steps, interval):
    from yade import O
    O.loadTmp('oedo')
    triax = [e for e in O.engines if type(e).__name__ == 'TriaxialStressController'][0]
    triax.goal2 = OEDO_LOAD
    flow = None
    if kind != 'dry':
        engine, _, variant = kind.partition('-')
        flow = make_engine(engine, oedometer=True, oedo_interval=interval)
        insert_engine(flow)
    O.timingEnabled = True
    gc.collect()
    y0 = O.bodies[3].state.pos[1]
    t0 = time.perf_counter()
    if kind.endswith('-mt'):
        # Remesh in a background thread while the DEM runs, switched on after the first step: YADE 2023.02a
        # segfaults when multithread=True before its first triangulation. The first mesh is foreground in both.
        O.run(1, True)
        flow.multithread = True
        O.run(steps - 1, True)
    else:
        O.run(steps, True)
    wall = time.perf_counter() - t0
    res = dict(kind=kind, seconds=wall, steps=steps, settlement=y0 - O.bodies[3].state.pos[1])
    if flow is not None:
        res['exec'] = flow.execTime * 1e-9
        res['p_mid'] = flow.getPorePressure((0.5 * O.bodies[1].state.pos[0], 0.1 * y0, 0.5 * O.bodies[5].state.pos[2]))
        if kind.startswith('pfv'):
            res['remeshes'] = flow.core.remesh_count
    del flow
    O.reset()
    gc.collect()
    return res


def timing_child(opts):
    from yade import O
    out = dict(threads=O.numThreads, sizes={}, oedometer={}, warnings=[], load_start=os.getloadavg())
    rounds = opts['rounds']
    for n in opts['sizes']:
        info = build_scene(n)
        O.saveTmp('bench')
        steady = opts['steady'] if n <= 20000 else max(5, opts['steady'] // 2)
        log('timing n=%d (%d bodies, dt %.3g, settled in %d steps to unbalanced force %.3g) threads=%d, %d rounds, '
            '%d steady steps' % (n, info['bodies'], info['dt'], info['settle_steps'], info['unbalanced'], O.numThreads,
                                 rounds, steady))
        order = ['yade', 'pfv', 'dry'] + (['pfv-double'] if opts['double'] else [])
        trials = {kind: [] for kind in order}
        for r in range(rounds):
            k = r % 3
            for kind in order[k:] + order[:k]:
                t0 = time.time()
                trials[kind].append(run_trial(kind, info, steady, out['warnings']))
                log('  n=%d round %d %-4s done in %.1f s' % (n, r + 1, kind, time.time() - t0))
        ref = exchange_reference(info)
        out['sizes'][str(n)] = dict(info=info, trials=trials, exchange_reference=ref, steady=steady)
        O.reset()
        gc.collect()
    if opts['oedometer']:
        for n in opts['oedo_sizes']:
            build_scene(n, oedometer=True)
            O.saveTmp('oedo')
            log('oedometer n=%d threads=%d: %d steps per trial' % (n, O.numThreads, opts['oedo_steps']))
            order = ['yade', 'pfv', 'dry'] + (['yade-mt', 'pfv-mt'] if opts['multithread'] else [])
            trials = {kind: [] for kind in order}
            for r in range(rounds):
                k = r % len(order)
                for kind in order[k:] + order[:k]:
                    res = oedometer_trial(kind, n, opts['oedo_steps'], opts['oedo_interval'])
                    trials[kind].append(res)
                    log('  oedometer n=%d round %d %-4s %.2f s' % (n, r + 1, kind, res['seconds']))
            out['oedometer'][str(n)] = dict(trials=trials, steps=opts['oedo_steps'], interval=opts['oedo_interval'])
            O.reset()
    out['load_end'] = os.getloadavg()
    return out


# ---------------------------------------------------------------------------------------------------------------
# start-up (--startup): the first step of a fresh engine against a forced remesh of the same engine
# ---------------------------------------------------------------------------------------------------------------
def startup_child(opts):
    """YADE and PFV trials only (run_trial), the order swapped every round."""
    from yade import O
    out = dict(threads=O.numThreads, sizes={}, warnings=[], load_start=os.getloadavg())
    for n in opts['sizes']:
        info = build_scene(n)
        O.saveTmp('bench')
        log('startup n=%d (%d bodies, settled in %d steps) threads=%d, %d rounds, %d steady steps'
            % (n, info['bodies'], info['settle_steps'], O.numThreads, opts['rounds'], opts['steady']))
        trials = dict(yade=[], pfv=[])
        for r in range(opts['rounds']):
            for kind in (('yade', 'pfv') if r % 2 == 0 else ('pfv', 'yade')):
                t0 = time.time()
                trials[kind].append(run_trial(kind, info, opts['steady'], out['warnings']))
                log('  n=%d round %d %-4s done in %.1f s' % (n, r + 1, kind, time.time() - t0))
        out['sizes'][str(n)] = dict(info=info, trials=trials, steady=opts['steady'])
        O.reset()
        gc.collect()
    out['load_end'] = os.getloadavg()
    return out


def _window_cost(record, flow_step):
    """Engine time of a WINDOW-step window minus WINDOW-1 steady flow steps (the summary's definition)."""
    return sum(record['exec']) - (WINDOW - 1) * flow_step


def startup_summary(data):
    """Per size: medians over rounds of the per-trial first step, remesh, their ratio and PFV's breakdown."""
    rows = {}
    for n, d in sorted(data['sizes'].items(), key=lambda kv: int(kv[0])):
        row = dict(cells=None)
        for kind, trials in d['trials'].items():
            first, remesh, ratio, cpu = [], [], [], []
            parts = {}
            for x in trials:
                fs = median(x['steady']['exec'])
                f, r = _window_cost(x['first'], fs), _window_cost(x['remesh'], fs)
                first.append(f)
                remesh.append(r)
                ratio.append(f / r)
                cpu.append(x['steady'].get('cpu_share', float('nan')))
                if kind != 'pfv':
                    continue
                row['cells'] = x['n_cells']
                tf, tr = x['first']['remesh_times'], x['remesh']['remesh_times']
                cold = [g for g in x['guard'] if g['remesh_count'] == 1]
                warm = [g for g in x['guard'] if g['remesh_count'] == 2]
                for key, a, b in (
                        ('ordering', tf['analysis'], tr['analysis']),
                        ('factorization', tf['factorization'], tr['factorization']),
                        ('triangulation + geometry', tf['triangulation'] + tf['geometry'],
                         tr['triangulation'] + tr['geometry']),
                        ('time-step guard', sum(g['seconds'] for g in cold), sum(g['seconds'] for g in warm)),
                        ('python + exchange', x['first']['exec'][0] - x['first']['core_step'][0],
                         x['remesh']['exec'][0] - x['remesh']['core_step'][0])):
                    parts.setdefault(key, []).append((a, b))
                parts.setdefault('applications', []).append((sum(g['iterations'] for g in cold),
                                                             sum(g['iterations'] for g in warm)))
                parts.setdefault('methods', []).append(('+'.join(g.get('method', '?') for g in cold),
                                                        '+'.join(g.get('method', '?') for g in warm)))
                parts.setdefault('factor nonzeros', []).append((x['factor_nonzeros'], x['factor_nonzeros']))
            pair_medians = {k: v[0] if k == 'methods' else (median([a for a, _ in v]), median([b for _, b in v]))
                            for k, v in parts.items()}
            row[kind] = dict(first=median(first), remesh=median(remesh), ratio=median(ratio), first_per_round=first,
                             first_range=(min(first), max(first)), ratio_range=(min(ratio), max(ratio)),
                             cpu_share=median(cpu),
                             parts=pair_medians)
        row['pfv_over_yade_first'] = row['pfv']['first'] / row['yade']['first']
        # Per round: the two engines' trials of one round ran next to each other, at the same machine speed.
        per_round = [p / y for y, p in zip(row['yade']['first_per_round'], row['pfv']['first_per_round'])]
        row['pfv_over_yade_range'] = (min(per_round), max(per_round))
        rows[n] = row
    return rows


def startup_report(opts, machine, rows, command, threads):
    L = []
    w = L.append
    w('Command: `%s` (%s, `yade -j%d`, OMP_NUM_THREADS = OPENBLAS_NUM_THREADS = %d). Scene and trials as in '
      'the full benchmark (permeameter, CHOLMOD, no automatic remesh), %d rounds of YADE and PFV interleaved, %d '
      'steady steps. **first step** = engine execTime of the first %d steps of a fresh engine minus %d steady flow '
      'steps, **remesh** = the same from a forced remesh (`updateTriangulation=True`) of that engine; medians over '
      'rounds of the per-trial values (the ratio first/remesh per trial; first PFV / first YADE is the ratio of the '
      'medians, its range over the rounds that of the two trials of each round). Targets: first/remesh <= 1.2, '
      'first PFV / first YADE <= 0.5.' % (command, machine.get('Model name', '?'), threads, threads,
                                          opts['rounds'], opts['steady'], WINDOW, WINDOW - 1))
    w('')
    w('| N | cells | first step YADE | first step PFV | remesh PFV | **first / remesh PFV** (range) | '
      '**first PFV / first YADE** (range) | CPU/wall steady Y / P |')
    w('|---|---|---|---|---|---|---|---|')
    for n, r in rows.items():
        y, p = r['yade'], r['pfv']
        w('| %s | %s | %s | %s | %s | **%.2f** (%.2f-%.2f) | **%.2f** (%.2f-%.2f) | %.2f / %.2f |' % (
            n, r['cells'], fmt_t(y['first']), fmt_t(p['first']), fmt_t(p['remesh']), p['ratio'],
            p['ratio_range'][0], p['ratio_range'][1], r['pfv_over_yade_first'], r['pfv_over_yade_range'][0],
            r['pfv_over_yade_range'][1], y['cpu_share'], p['cpu_share']))
    w('')
    w('PFV, first step / forced remesh, by stage (medians; `remesh_times()`; the time-step guard from '
      '`collective_viscous_history`: the certified bound, and the collective limit itself where the bound '
      'cannot show O.dt safe, "methods" as recorded in the first round; python + exchange = execTime minus the '
      'core step, guard included):')
    w('')
    keys = ('ordering', 'factorization', 'triangulation + geometry', 'time-step guard', 'python + exchange')
    w('| N | ' + ' | '.join(keys) + ' | guard methods | operator applications | nnz(L) |')
    w('|---|' + '---|' * (len(keys) + 3))
    for n, r in rows.items():
        pp = r['pfv']['parts']
        cells = ['%s / %s' % (fmt_t(pp[k][0]), fmt_t(pp[k][1])) for k in keys]
        w('| %s | %s | %s / %s | %d / %d | %.3g |' % (
            n, ' | '.join(cells), pp['methods'][0] or '-', pp['methods'][1] or '-', pp['applications'][0],
            pp['applications'][1], pp['factor nonzeros'][0]))
    w('')
    w('Load average (1, 5, 15 min) at start: %s; at end: %s.'
      % (machine['load average at start'], machine['load average at end']))
    return '\n'.join(L)


def startup_driver(opts, argv):
    command = 'yade-double -n -x bench/flow_benchmark.py ' + ' '.join(argv)
    machine = machine_description()
    for n in opts['sizes']:
        if not os.path.exists(packing_path(n)):
            log('generating packing n=%d into %s (once; cached)' % (n, packing_path(n)))
            run_child(['--child=generate', '--size=%d' % n], opts['gen_threads'] or 1, 'generate-%d' % n)
    child_opts = ['--startup', '--sizes=' + ','.join(map(str, opts['sizes'])), '--rounds=%d' % opts['rounds'],
                  '--steady=%d' % opts['steady']]
    texts, raw = [], {}
    for t in opts['threads']:
        data = run_child(['--child=startup'] + child_opts, t, 'startup-j%d' % t)
        raw[str(t)] = data
        machine['load average at end'] = ' '.join('%.2f' % x for x in os.getloadavg())
        rows = startup_summary(data)
        texts.append(startup_report(opts, machine, rows, command, t))
    text = '\n\n'.join(texts)
    print('\n' + text + '\n', flush=True)
    write_report(opts['out'], text, STARTUP_BEGIN_MARK, STARTUP_END_MARK)
    os.makedirs(os.path.dirname(os.path.abspath(opts['json'])), exist_ok=True)
    with open(opts['json'], 'w') as f:
        json.dump(dict(version=REPORT_VERSION, command=command, machine=machine, timing=raw), f, indent=1, default=str)
    log('report written to %s, raw data to %s' % (opts['out'], opts['json']))
    return 0


# ---------------------------------------------------------------------------------------------------------------
# memory child
# ---------------------------------------------------------------------------------------------------------------
def memory_child(opts):
    from yade import O
    n, kind = opts['size'], opts['engine']
    build_scene(n, settle=False)
    gc.collect()
    before = rss_kb()
    exact = reset_peak()
    if kind != 'dry':
        flow = make_engine(kind)
        insert_engine(flow)
    for _ in range(WINDOW + opts['steady']):
        O.step()
    peak_first, mid = rss_kb('VmHWM'), rss_kb()
    reset_peak()
    if kind != 'dry':
        flow.updateTriangulation = True
    for _ in range(WINDOW):
        O.step()
    peak_remesh, after = rss_kb('VmHWM'), rss_kb()
    if not exact:
        peak_remesh = max(peak_remesh, peak_first)
    return dict(n=n, kind=kind, rss_before_kb=before, peak_kb=max(peak_first, peak_remesh), peak_first_kb=peak_first,
                rss_mid_kb=mid, peak_remesh_kb=peak_remesh, rss_after_kb=after, peak_reset=exact,
                threads=O.numThreads)


# ---------------------------------------------------------------------------------------------------------------
# driver
# ---------------------------------------------------------------------------------------------------------------
def run_child(args, threads, label):
    exe = shutil.which('yade-double') or 'yade-double'
    os.makedirs('/tmp/bench', exist_ok=True)
    path = '/tmp/bench/child-%d-%s.json' % (os.getpid(), label)
    if os.path.exists(path):
        os.remove(path)
    cmd = [exe, '-j%d' % threads, '-n', '-x', SCRIPT] + args + ['--child-json=%s' % path]
    t0 = time.time()
    # CHOLMOD's supernodal factorisation calls BLAS; Debian's OpenBLAS (pthread build) would otherwise use every
    # core whatever yade's -jN: pin it to the thread count being measured, for both engines alike.
    env = dict(os.environ, OPENBLAS_NUM_THREADS=str(threads), OMP_NUM_THREADS=str(threads))
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, cwd=REPO, env=env)
    tail = []
    for line in proc.stdout:
        line = line.rstrip('\n')
        tail = (tail + [line])[-60:]
        if line.startswith('bench:') or 'Error' in line or 'Traceback' in line:
            print('  [%s] %s' % (label, line), flush=True)
    rc = proc.wait()
    if rc != 0 or not os.path.exists(path):
        raise RuntimeError('child %s failed (exit %d): %s\n%s' % (label, rc, ' '.join(cmd), '\n'.join(tail)))
    with open(path) as f:
        data = json.load(f)
    os.remove(path)
    log('%s finished in %.0f s' % (label, time.time() - t0))
    return data


def sh(cmd):
    try:
        return subprocess.run(cmd, shell=True, capture_output=True, text=True, timeout=20).stdout.strip()
    except Exception:
        return ''


def machine_description():
    import yade
    d = {}
    lscpu = sh('lscpu')
    for key in ('Model name', 'CPU(s)', 'Thread(s) per core', 'Core(s) per socket', 'Socket(s)', 'Hypervisor vendor',
                'L2 cache', 'L3 cache', 'CPU max MHz', 'BogoMIPS'):
        for line in lscpu.splitlines():
            if line.startswith(key + ':'):
                d[key] = line.split(':', 1)[1].strip()
    mem = sh("grep MemTotal /proc/meminfo").split()
    d['RAM'] = '%.1f GiB' % (int(mem[1]) / 2 ** 20) if len(mem) > 1 else '?'
    d['kernel'] = platform.release()
    d['os'] = sh('. /etc/os-release && echo "$PRETTY_NAME"')
    d['compiler'] = sh('c++ --version | head -1')
    cache = os.path.join(REPO, 'build', 'CMakeCache.txt')
    flags = []
    if os.path.exists(cache):
        for line in open(cache):
            for key in ('CMAKE_BUILD_TYPE:', 'CMAKE_CXX_FLAGS_RELEASE:', 'CMAKE_CXX_FLAGS:', 'OpenMP_CXX_FLAGS:'):
                if line.startswith(key):
                    flags.append('%s=%s' % (key.split(':')[0], line.split('=', 1)[1].strip()))
    d['pfv build'] = ', '.join(flags)
    pkgs = sh("dpkg-query -W -f='${Package} ${Version}\\n' yade libcgal-dev libsuitesparse-dev libmetis-dev "
              "libeigen3-dev pybind11-dev python3-numpy libboost-dev 2>/dev/null")
    d['packages'] = '; '.join(pkgs.splitlines())
    d['python'] = platform.python_version()
    d['yade'] = getattr(yade.config, 'version', '?') if hasattr(yade, 'config') else '?'
    try:
        import pfv
        d['pfv module'] = os.path.dirname(pfv.__file__)
    except Exception as e:
        d['pfv module'] = 'IMPORT FAILED: %s' % e
    d['git'] = (sh('git -C %s rev-parse --short HEAD' % REPO) +
                (' (working tree modified in lib/ pkg/)'
                 if sh('git -C %s status --porcelain lib pkg CMakeLists.txt' % REPO) else ''))
    d['BLAS'] = (os.path.realpath('/usr/lib/x86_64-linux-gnu/libblas.so.3') +
                 ' (children run with OPENBLAS_NUM_THREADS = OMP_NUM_THREADS = yade -jN)')
    d['load average at start'] = ' '.join('%.2f' % x for x in os.getloadavg())
    return d


def thesis_fits():
    """Table 5.6 fits (seconds for N spheres), model-spec section 9 / claim 21."""
    return {
        'triangulation': ('T_TRG = 5.8e-6 N log2 N', lambda n: 5.8e-6 * n * math.log2(n)),
        'geometry+conductance': ('T_G = 5.4e-5 N', lambda n: 5.4e-5 * n),
        'assembly+factorization': ('T_LTL = 5.25e-9 N^2 + 6.38e-5 N (TAUCS)', lambda n: 5.25e-9 * n * n + 6.38e-5 * n),
        'force_cache': ('T_F = 5e-6 N', lambda n: 5e-6 * n),
        'volumes': ('T_DEF = 8e-7 N', lambda n: 8e-7 * n),
        'solve': ('T_SLV = 1.72e-7 N^1.33 (TAUCS)', lambda n: 1.72e-7 * n ** 1.33),
        'forces': ('T_Fcache = 1.35e-6 N', lambda n: 1.35e-6 * n),
    }


def summarise(timing, memory):
    """Per threads and size: medians. Returns nested dict used by the report and stored in the JSON."""
    summ = {}
    for t, data in timing.items():
        st = {}
        for ns, sd in data['sizes'].items():
            tr = sd['trials']
            row = dict(n=int(ns))
            dry = [median(x['steady_wall']) for x in tr['dry']]
            row['dry'] = median(dry)
            dry_dem = [median(x['steady_dem']) for x in tr['dry'] if x.get('steady_dem')]
            row['dry_dem'] = median(dry_dem) if dry_dem else None
            row['dry_range'] = (min(dry), max(dry)) if dry else None
            row['vmax'] = {k: max([x.get('vmax', float('nan')) for x in tr[k]] or [float('nan')]) for k in tr}
            for kind in [k for k in ('yade', 'pfv', 'pfv-double') if tr.get(k)]:
                flow_step, remesh, first, coupled = [], [], [], []
                for x in tr[kind]:
                    fs = median(x['steady']['exec'])
                    flow_step.append(fs)
                    coupled.append(median(x['steady']['wall']))
                    remesh.append(sum(x['remesh']['exec']) - (WINDOW - 1) * fs)
                    first.append(sum(x['first']['exec']) - (WINDOW - 1) * fs)
                row[kind] = dict(flow=median(flow_step), remesh=median(remesh), first=median(first),
                                 cpu_share=median([x['steady'].get('cpu_share') for x in tr[kind]]),
                                 coupled=median(coupled), flow_range=(min(flow_step), max(flow_step)),
                                 remesh_range=(min(remesh), max(remesh)),
                                 cells=tr[kind][0]['n_cells'] if tr[kind] else None)
                row[kind]['coupled_minus_dry'] = row[kind]['coupled'] - row['dry']
                dem = [median(x['steady']['dem']) for x in tr[kind] if x['steady'].get('dem')]
                row[kind]['dem'] = median(dem) if dem else None
            # pressure agreement (first round of each engine: same number of steps from the same state)
            if tr['yade'] and tr['pfv']:
                py, pp = tr['yade'][0]['probes'], tr['pfv'][0]['probes']
                diffs = [abs(a - b) / DP for a, b in zip(py, pp)]
                fy, fp = tr['yade'][0]['flux'], tr['pfv'][0]['flux']
                row['agreement'] = dict(max_dp=max(diffs), mean_dp=sum(diffs) / len(diffs),
                                        flux_in_rel=abs(fp[0] - fy[0]) / abs(fy[0]) if fy[0] else float('nan'),
                                        flux_out_rel=abs(fp[1] - fy[1]) / abs(fy[1]) if fy[1] else float('nan'),
                                        flux_yade=fy, flux_pfv=fp,
                                        probe_yade=py[13], probe_pfv=pp[13])
            if tr['pfv'] and tr.get('pfv-double'):
                # the default (32-bit factor, refined) against the direct double solve, same steps from the same state
                pp, pd = tr['pfv'][0]['probes'], tr['pfv-double'][0]['probes']
                row['double_agreement'] = dict(max_dp=max(abs(a - b) / DP for a, b in zip(pp, pd)))
                row['default_factor'] = '32-bit' if tr['pfv'][0].get('reduced') else 'double'
            # PFV breakdown
            step_stages = ('volumes', 'solve', 'forces')
            br = {'remesh': {}, 'steady': {}}
            per_trial_r, per_trial_s = [], []
            for x in tr['pfv']:
                rt = x['remesh']['remesh_times']
                rem_stages = [k2 for k2 in rt if k2 not in step_stages]  # whatever stages the core reports
                counts = x['remesh'].get('remesh_count', [])
                base = x['first']['remesh_count'][-1] if x['first'].get('remesh_count') else None
                # the window step in which PFV remeshed
                k = next((i for i, c in enumerate(counts) if base is not None and c > base), 0)
                stt = x['remesh']['step_times'][k]
                d = {s: rt[s] for s in rem_stages}
                d.update({'first ' + s: stt[s] for s in step_stages})
                cpp = sum(d.values())
                d['python + exchange'] = (x['remesh']['exec'][k] -
                                          (x['remesh']['core_step'][k] if x['core_timer'] else cpp))
                if x['core_timer']:
                    d['C++ untimed'] = x['remesh']['core_step'][k] - cpp
                d['total (engine exec)'] = x['remesh']['exec'][k]
                per_trial_r.append(d)
                steps = x['steady']['step_times']
                s = {k2: median([q[k2] for q in steps]) for k2 in step_stages}
                cpp = [sum(q[k2] for k2 in step_stages) for q in steps]
                ex = x['steady']['exec']
                if x['core_timer']:
                    cs = x['steady']['core_step']
                    s['C++ untimed'] = median([c - p for c, p in zip(cs, cpp)])
                    s['python + exchange'] = median([e - c for e, c in zip(ex, cs)])
                else:
                    s['python + exchange'] = median([e - p for e, p in zip(ex, cpp)])
                s['total (engine exec)'] = median(ex)
                per_trial_s.append(s)
            for key, lst in (('remesh', per_trial_r), ('steady', per_trial_s)):
                if lst:
                    br[key] = {k2: median([q.get(k2) for q in lst]) for k2 in lst[0]}
            row['pfv_breakdown'] = br
            # YADE's own timingDeltas breakdown
            yb = {'steady': {}, 'remesh': {}}
            ys, yr = [], []
            for x in tr['yade']:
                S = len(x['steady']['exec'])
                s = {k2: v / S for k2, v in x.get('td_steady', {}).items()}
                ys.append(s)
                yr.append({k2: v - (WINDOW - 1) * s.get(k2, 0.0) for k2, v in x.get('td_remesh', {}).items()})
            for key, lst in (('steady', ys), ('remesh', yr)):
                if lst and lst[0]:
                    yb[key] = {k2: median([q.get(k2) for q in lst]) for k2 in lst[0]}
            row['yade_breakdown'] = yb
            row['exchange_reference'] = sd['exchange_reference']
            row['info'] = sd['info']
            st[ns] = row
        oe = {}
        for ns, od in data.get('oedometer', {}).items():
            tr = od['trials']
            dry = median([x['seconds'] / x['steps'] for x in tr['dry']])
            r = dict(n=int(ns), steps=od['steps'], interval=od['interval'], dry=dry)
            for kind in [k for k in ('yade', 'pfv', 'yade-mt', 'pfv-mt') if tr.get(k)]:
                c = median([x['seconds'] / x['steps'] for x in tr[kind]])
                r[kind] = dict(coupled=c, ratio=c / dry if dry else float('nan'),
                               exec=median([x['exec'] / x['steps'] for x in tr[kind]]),
                               p_mid=tr[kind][0].get('p_mid'), remeshes=tr[kind][0].get('remeshes'),
                               settlement=tr[kind][0].get('settlement'))
            r['dry_settlement'] = tr['dry'][0]['settlement'] if tr['dry'] else None
            oe[ns] = r
        summ[t] = dict(sizes=st, oedometer=oe, load=(data.get('load_start'), data.get('load_end')))
    mem = {}
    for m in memory:
        mem.setdefault(str(m['n']), {})[m['kind']] = m
    return summ, mem


# ---------------------------------------------------------------------------------------------------------------
# report
# ---------------------------------------------------------------------------------------------------------------
def fmt_t(s):
    """seconds -> compact string in ms or s."""
    if s is None or s != s:
        return 'n/a'
    if abs(s) >= 1.0:
        return '%.2f s' % s
    if abs(s) >= 0.01:
        return '%.1f ms' % (s * 1e3)
    if abs(s) >= 0.001:
        return '%.2f ms' % (s * 1e3)
    return '%.3f ms' % (s * 1e3)


def fmt_r(a, b):
    if a is None or b is None or a != a or b != b or b == 0:
        return 'n/a'
    return '%.2f' % (a / b)


def fmt_mb(kb):
    return 'n/a' if kb is None else '%.0f MB' % (kb / 1024.0)


def slope(ns, ts):
    pts = [(math.log(n), math.log(t)) for n, t in zip(ns, ts) if t and t > 0 and t == t]
    if len(pts) < 2:
        return float('nan')
    mx = sum(p[0] for p in pts) / len(pts)
    my = sum(p[1] for p in pts) / len(pts)
    sxx = sum((p[0] - mx) ** 2 for p in pts)
    return sum((p[0] - mx) * (p[1] - my) for p in pts) / sxx if sxx else float('nan')


def report(opts, machine, packings, summ, mem, command):
    L = []
    w = L.append
    w('## Run')
    w('')
    w('Command: `%s` (%s).' % (command, 'quick mode' if opts['quick'] else '%d rounds' % opts['rounds']))
    w('')
    w('Machine and software:')
    w('')
    # The commit and the packings' digests identify a run for comparing JSON files; the report lives in doc/,
    # which holds no history, so they stay in the JSON (and the log).
    for k, v in machine.items():
        if k != 'git':
            w('- %s: %s' % (k, v))
    w('')
    w('### Packings')
    w('')
    w('| N | box side | porosity | radii min / mean / max | compaction |')
    w('|---|---|---|---|---|')
    for n in sorted(packings):
        m = packings[n]
        w('| %d | %.4f | %.4f | %.4f / %.4f / %.4f | %d iter, %.0f s (-j%s) |'
          % (n, m['box'], m['porosity'], m['r_min'], m['r_mean'], m['r_max'], m['iterations'], m['seconds'],
             m.get('threads', '?')))
    w('')
    w('Scene: permeameter along y (dp = %g Pa, viscosity %g, p = 0 at ymax), six fixed walls (boundaries at the walls),'
      ' dynamic spheres with friction 30 deg, Newton damping 0.2, no gravity, O.dt = 0.5 P-wave step; the packing is '
      'at equilibrium under 10 kPa, so the drag (1 %% of the confinement) hardly moves it.  Both engines: CHOLMOD '
      '(useSolver=3), slipBoundary=False, no automatic remesh (meshUpdateInterval=1e9, defTolerance=0); '
      'other attributes at their defaults (YADE: multithread=False).' % (DP, VISCOSITY))
    w('')
    for t in sorted(summ, key=int):
        sizes = summ[t]['sizes']
        w('### Timings, %s thread%s (yade -j%s)' % (t, '' if t == '1' else 's', t))
        w('')
        w('| N | cells Y / P | remesh YADE | remesh PFV | P/Y | flow step YADE | flow step PFV | P/Y '
          '| coupled YADE | coupled PFV | dry | (coupled-dry) P/Y | first step YADE | first step PFV |')
        w('|---|---|---|---|---|---|---|---|---|---|---|---|---|---|')
        for ns in sorted(sizes, key=int):
            r = sizes[ns]
            y, p = r['yade'], r['pfv']
            w('| %s | %s / %s | %s | %s | **%s** | %s | %s | **%s** | %s | %s | %s | %s | %s | %s |'
              % (ns, y['cells'], p['cells'], fmt_t(y['remesh']), fmt_t(p['remesh']), fmt_r(p['remesh'], y['remesh']),
                 fmt_t(y['flow']), fmt_t(p['flow']), fmt_r(p['flow'], y['flow']), fmt_t(y['coupled']),
                 fmt_t(p['coupled']), fmt_t(r['dry']), fmt_r(p['coupled_minus_dry'], y['coupled_minus_dry']),
                 fmt_t(y['first']), fmt_t(p['first'])))
        w('')
        dbl = [ns for ns in sorted(sizes, key=int) if 'pfv-double' in sizes[ns]]
        if dbl:
            w('PFV with the double factor (`mixed_precision=False`: every solve a direct double substitution; by '
              'default a factor of at least `mixed_precision_min_entries` = 2e6 entries is kept in 32 bits and each '
              'solve refined to `refinement_tolerance` = 1e-10 of the pressure spread), same trials:')
            w('')
            w('| N | default factor | remesh PFV double | P/Y | flow step PFV double | P/Y | coupled PFV double '
              '| (coupled-dry) P/Y | default / double flow step | max abs(p default - p double) / dp over 27 probes |')
            w('|---|---|---|---|---|---|---|---|---|---|')
            for ns in dbl:
                r = sizes[ns]
                y, p, d = r['yade'], r['pfv'], r['pfv-double']
                w('| %s | %s | %s | %s | %s | %s | %s | %s | %.2f | %.1e |'
                  % (ns, r.get('default_factor', '?'), fmt_t(d['remesh']), fmt_r(d['remesh'], y['remesh']),
                     fmt_t(d['flow']), fmt_r(d['flow'], y['flow']), fmt_t(d['coupled']),
                     fmt_r(d['coupled_minus_dry'], y['coupled_minus_dry']), p['flow'] / d['flow'],
                     r.get('double_agreement', {}).get('max_dp', float('nan'))))
            w('')
        w('Spread over rounds (min-max): ' + '; '.join(
            'N=%s remesh Y %s-%s P %s-%s, flow Y %s-%s P %s-%s' % (
                ns, fmt_t(sizes[ns]['yade']['remesh_range'][0]), fmt_t(sizes[ns]['yade']['remesh_range'][1]),
                fmt_t(sizes[ns]['pfv']['remesh_range'][0]), fmt_t(sizes[ns]['pfv']['remesh_range'][1]),
                fmt_t(sizes[ns]['yade']['flow_range'][0]), fmt_t(sizes[ns]['yade']['flow_range'][1]),
                fmt_t(sizes[ns]['pfv']['flow_range'][0]), fmt_t(sizes[ns]['pfv']['flow_range'][1]))
            for ns in sorted(sizes, key=int)) + '.')
        w('')
        if all(sizes[ns].get('dry_dem') is not None for ns in sizes):
            w('DEM engines per steady step (execTime of every engine but the flow engine; medians as above; the '
              'difference between "coupled - dry" and the flow step): ' + '; '.join(
                  'N=%s dry %s, with YADE %s, with PFV %s' % (
                      ns, fmt_t(sizes[ns]['dry_dem']), fmt_t(sizes[ns]['yade'].get('dem')),
                      fmt_t(sizes[ns]['pfv'].get('dem'))) for ns in sorted(sizes, key=int)) + '.')
            w('')
        ld = summ[t].get('load') or (None, None)
        if ld[0]:
            w('Load average (1, 5, 15 min) of the machine when this yade process started: %s; when it ended: %s.  '
              'CPU time / wall time of the steady steps (1 = one core fully ours%s): %s.'
              % (' '.join('%.2f' % v for v in ld[0]), ' '.join('%.2f' % v for v in ld[1]),
                 '' if t == '1' else ', up to %s with %s threads' % (t, t),
                 '; '.join('N=%s YADE %.2f PFV %.2f' % (ns, sizes[ns]['yade'].get('cpu_share') or float('nan'),
                                                        sizes[ns]['pfv'].get('cpu_share') or float('nan'))
                           for ns in sorted(sizes, key=int))))
            w('')
        w('Scene before the trials (settled with damping 0.5): ' + '; '.join(
            'N=%s: %s steps, unbalanced force %.3g, dt %.3g s' % (ns, sizes[ns]['info'].get('settle_steps'),
                                                                  sizes[ns]['info'].get('unbalanced', float('nan')),
                                                                  sizes[ns]['info']['dt'])
            for ns in sorted(sizes, key=int)) + '.')
        w('')
    if mem:
        w('### Peak memory (fresh `yade-double -j1` per engine; growth over the scene without engine)')
        w('')
        w('| N | scene RSS | dry peak growth | YADE peak growth | PFV peak growth | P/Y (net of dry) | YADE retained '
          '| PFV retained | YADE peak first mesh / forced remesh | PFV peak first mesh / forced remesh |')
        w('|---|---|---|---|---|---|---|---|---|---|')
        for ns in sorted(mem, key=int):
            m = mem[ns]
            g = {k: m[k]['peak_kb'] - m[k]['rss_before_kb'] for k in m}
            ret = {k: m[k]['rss_after_kb'] - m[k]['rss_before_kb'] for k in m}
            d = g.get('dry', 0)

            def split(k):
                x = m.get(k, {})
                if 'peak_first_kb' not in x:
                    return 'n/a'
                return '%s / %s' % (fmt_mb(x['peak_first_kb'] - x['rss_before_kb']),
                                    fmt_mb(x['peak_remesh_kb'] - x['rss_before_kb']))
            w('| %s | %s | %s | %s | %s | **%s** | %s | %s | %s | %s |'
              % (ns, fmt_mb(m.get('dry', m.get('yade'))['rss_before_kb']), fmt_mb(g.get('dry')),
                 fmt_mb(g.get('yade')), fmt_mb(g.get('pfv')), fmt_r(g.get('pfv', 0) - d, g.get('yade', 0) - d),
                 fmt_mb(ret.get('yade')), fmt_mb(ret.get('pfv')), split('yade'), split('pfv')))
        exact = all(m[k]['peak_reset'] for m in mem.values() for k in m)
        w('')
        w('Peak = VmHWM %s minus VmRSS before the engine was added (the larger of the first-mesh phase: first step + '
          'steady steps, and of the forced-remesh phase, the high-water mark being reset in between); retained = VmRSS '
          'at the end minus before.'
          % ('after a reset through /proc/self/clear_refs' if exact
             else '(could NOT be reset: includes scene building)'))
        w('')
    w('### Pressure agreement (PFV vs YADE, same scene, same step)')
    w('')
    w('| threads | N | max abs(dp) / dp over 27 probes | mean | Qin rel. diff | Qout rel. diff | p(centre) YADE | PFV '
      '| max sphere speed dry / YADE / PFV |')
    w('|---|---|---|---|---|---|---|---|---|')
    for t in sorted(summ, key=int):
        for ns in sorted(summ[t]['sizes'], key=int):
            a = summ[t]['sizes'][ns].get('agreement')
            if a:
                v = summ[t]['sizes'][ns]['vmax']
                w('| %s | %s | %.2e | %.2e | %.2e | %.2e | %.4g | %.4g | %.2g / %.2g / %.2g m/s |'
                  % (t, ns, a['max_dp'], a['mean_dp'], a['flux_in_rel'], a['flux_out_rel'], a['probe_yade'],
                     a['probe_pfv'], v['dry'], v['yade'], v['pfv']))
    w('')
    for t in sorted(summ, key=int):
        sizes = summ[t]['sizes']
        ns_list = sorted(sizes, key=int)
        w('### PFV breakdown per stage, %s thread%s' % (t, '' if t == '1' else 's'))
        w('')
        w('Remesh step (C++ stage timers of `flow.core.remesh_times()` and `step_times()` of that step; '
          '"python + exchange" = engine execTime minus the C++ `core.step()` call):')
        w('')
        keys = []
        for ns in ns_list:
            for k in sizes[ns]['pfv_breakdown'].get('remesh', {}):
                if k not in keys:
                    keys.append(k)
        w('| stage | ' + ' | '.join('N=%s' % ns for ns in ns_list) + ' | ' +
          ' | '.join('share N=%s' % ns for ns in ns_list[-1:]) + ' |')
        w('|---|' + '---|' * (len(ns_list) + 1))
        for k in keys:
            last = sizes[ns_list[-1]]['pfv_breakdown']['remesh']
            tot = last.get('total (engine exec)')
            w('| %s | %s | %s |'
              % (k, ' | '.join(fmt_t(sizes[ns]['pfv_breakdown']['remesh'].get(k)) for ns in ns_list),
                 '%.0f %%' % (100 * last.get(k, 0) / tot) if tot and k != 'total (engine exec)' else ''))
        w('')
        w('Steady step:')
        w('')
        keys = []
        for ns in ns_list:
            for k in sizes[ns]['pfv_breakdown'].get('steady', {}):
                if k not in keys:
                    keys.append(k)
        w('| stage | ' + ' | '.join('N=%s' % ns for ns in ns_list) + ' | share N=%s |' % ns_list[-1])
        w('|---|' + '---|' * (len(ns_list) + 1))
        for k in keys:
            last = sizes[ns_list[-1]]['pfv_breakdown']['steady']
            tot = last.get('total (engine exec)')
            w('| %s | %s | %s |'
              % (k, ' | '.join(fmt_t(sizes[ns]['pfv_breakdown']['steady'].get(k)) for ns in ns_list),
                 '%.0f %%' % (100 * last.get(k, 0) / tot) if tot and k != 'total (engine exec)' else ''))
        w('')
        w('Reference, on the dry scene: reading all positions with 3x `coordsAndDisplacements` + numpy: %s; '
          '`O.forces.addF(id, tuple)` for every sphere: %s.'
          % (', '.join('%s (N=%s)' % (fmt_t(sizes[ns]['exchange_reference']['read_positions']), ns) for ns in ns_list),
             ', '.join('%s (N=%s)' % (fmt_t(sizes[ns]['exchange_reference']['write_forces']), ns) for ns in ns_list)))
        w('')
        w('YADE\'s own breakdown (its `timingDeltas`, same definitions):')
        w('')
        keys = []
        for ns in ns_list:
            for k in (list(sizes[ns]['yade_breakdown'].get('remesh', {})) +
                      list(sizes[ns]['yade_breakdown'].get('steady', {}))):
                if k not in keys:
                    keys.append(k)
        w('| YADE checkpoint | ' + ' | '.join('remesh N=%s' % ns for ns in ns_list) + ' | ' +
          ' | '.join('steady N=%s' % ns for ns in ns_list) + ' |')
        w('|---|' + '---|' * (2 * len(ns_list)))
        for k in keys:
            w('| %s | %s | %s |'
              % (k, ' | '.join(fmt_t(sizes[ns]['yade_breakdown'].get('remesh', {}).get(k)) for ns in ns_list),
                 ' | '.join(fmt_t(sizes[ns]['yade_breakdown'].get('steady', {}).get(k)) for ns in ns_list)))
        w('')
    # scaling
    t1 = sorted(summ, key=int)[0]
    sizes = summ[t1]['sizes']
    ns_list = sorted(sizes, key=int)
    nvals = [int(ns) for ns in ns_list]
    w('### Scaling with N (%s thread%s) against the thesis fits (Table 5.6, model-spec section 9 / claim 21)'
      % (t1, '' if t1 == '1' else 's'))
    w('')
    w('PFV stage time per sphere (us/sphere), fitted exponent b of t ~ N^b, and the thesis fit evaluated at the same N '
      '(Xeon 2.67 GHz, 2011, sequential).  Mapping: triangulation = T_TRG, geometry + conductance = T_G, '
      'assembly + analysis (ordering) + factorization = T_LTL, force_cache = T_F, volumes = T_DEF, '
      'solve = T_SLV, forces = T_Fcache.')
    w('')
    w('| stage | ' + ' | '.join('PFV us/sph N=%s' % ns for ns in ns_list) + ' | b (PFV) | ' +
      ' | '.join('thesis us/sph N=%s' % ns for ns in ns_list) + ' | b (thesis) | PFV/thesis at N=%s |' % ns_list[-1])
    w('|---|' + '---|' * (2 * len(ns_list) + 3))
    fits = thesis_fits()

    def stage_value(row, name):
        b = row['pfv_breakdown']
        r, s = b.get('remesh', {}), b.get('steady', {})
        if name == 'geometry+conductance':
            return r.get('geometry', 0) + r.get('conductance', 0)
        if name == 'assembly+factorization':
            return r.get('assembly', 0) + r.get('analysis', 0) + r.get('factorization', 0)
        if name in r:
            return r[name]
        return s.get(name)

    for name, (label, f) in fits.items():
        vals = [stage_value(sizes[ns], name) for ns in ns_list]
        th = [f(n) for n in nvals]
        w('| %s | %s | %.2f | %s | %.2f | %s |' % (
            name, ' | '.join('%.3g' % (v / n * 1e6) if v else 'n/a' for v, n in zip(vals, nvals)), slope(nvals, vals),
            ' | '.join('%.3g' % (v / n * 1e6) for v, n in zip(th, nvals)), slope(nvals, th),
            fmt_r(vals[-1], th[-1])))
    pad = ' |' * (len(ns_list) + 2)
    for kind, lab in (('yade', 'YADE'), ('pfv', 'PFV')):
        for what in ('remesh', 'flow'):
            vals = [sizes[ns][kind][what] for ns in ns_list]
            w('| %s %s (total) | %s | %.2f |'
              % (lab, what, ' | '.join('%.3g' % (v / n * 1e6) for v, n in zip(vals, nvals)), slope(nvals, vals))
              + pad)
    vals = [sizes[ns]['dry'] for ns in ns_list]
    w('| dry DEM step | %s | %.2f |' % (' | '.join('%.3g' % (v / n * 1e6) for v, n in zip(vals, nvals)),
                                        slope(nvals, vals)) + pad)
    w('')
    w('Thesis fit formulas: ' + '; '.join('%s: %s' % (k, v[0]) for k, v in fits.items()) + '.')
    w('')
    # oedometer
    if any(summ[t]['oedometer'] for t in summ):
        w('### Coupled / dry cost on the oedometer-like scene')
        w('')
        w('Top wall driven by a TriaxialStressController (stressMask=2) from 10 to 11 kPa, drained top, viscosity %g, '
          'Newton damping 0, O.dt = %g, meshUpdateInterval (below) and defTolerance 0.3 as in YADE\'s oedometer '
          'example; wall-clock time of O.run(M) per step, remeshing included.' % (OEDO_VISCOSITY, OEDO_DT))
        w('')
        w('| threads | N | M steps | remesh interval | dry | YADE coupled | YADE coupled/dry | PFV coupled '
          '| PFV coupled/dry | PFV remeshes | p(0.1 H) YADE / PFV | settlement dry / YADE / PFV |')
        w('|---|---|---|---|---|---|---|---|---|---|---|---|')
        for t in sorted(summ, key=int):
            for ns, r in sorted(summ[t]['oedometer'].items(), key=lambda kv: int(kv[0])):
                w('| %s | %s | %d | %d | %s | %s | **%.2f** | %s | **%.2f** | %s | %.4g / %.4g | %.3g / %.3g / %.3g |'
                  % (t, ns, r['steps'], r['interval'], fmt_t(r['dry']), fmt_t(r['yade']['coupled']), r['yade']['ratio'],
                     fmt_t(r['pfv']['coupled']), r['pfv']['ratio'], r['pfv']['remeshes'], r['yade']['p_mid'] or 0,
                     r['pfv']['p_mid'] or 0, r['dry_settlement'] or 0, r['yade']['settlement'] or 0,
                     r['pfv']['settlement'] or 0))
        w('')
        if any(r.get('pfv-mt') for t in summ for r in summ[t]['oedometer'].values()):
            w('Background remesh (`multithread=True` in both engines: the next mesh and factor are built in a second '
              'thread while the DEM runs on the current one, and adopted when ready, so a few steps after each remesh '
              'use a mesh built from slightly older positions; the accuracy cost is measured as the change of the '
              'pressure probe and of the settlement against the same engine without it):')
            w('')
            w('| threads | N | YADE mt coupled | YADE mt coupled/dry | PFV mt coupled | PFV mt coupled/dry '
              '| mt/foreground YADE | mt/foreground PFV | p(0.1 H) change YADE / PFV | settlement change YADE / PFV |')
            w('|---|---|---|---|---|---|---|---|---|---|')

            def change(r, kind, key):
                a, b = r[kind + '-mt'].get(key), r[kind].get(key)
                return '%.2g %%' % (100 * (a - b) / abs(b)) if a is not None and b else 'n/a'
            for t in sorted(summ, key=int):
                for ns, r in sorted(summ[t]['oedometer'].items(), key=lambda kv: int(kv[0])):
                    if not r.get('pfv-mt'):
                        continue
                    w('| %s | %s | %s | **%.2f** | %s | **%.2f** | %.2f | %.2f | %s / %s | %s / %s |'
                      % (t, ns, fmt_t(r['yade-mt']['coupled']), r['yade-mt']['ratio'], fmt_t(r['pfv-mt']['coupled']),
                         r['pfv-mt']['ratio'], r['yade-mt']['coupled'] / r['yade']['coupled'],
                         r['pfv-mt']['coupled'] / r['pfv']['coupled'], change(r, 'yade', 'p_mid'),
                         change(r, 'pfv', 'p_mid'), change(r, 'yade', 'settlement'), change(r, 'pfv', 'settlement')))
            w('')
    w('Amortised coupled/dry ratio of the permeameter for a remesh every R steps, (dry + flow + remesh/R) / dry:')
    w('')
    w('| threads | N | YADE R=200 | PFV R=200 | YADE R=1000 | PFV R=1000 |')
    w('|---|---|---|---|---|---|')
    for t in sorted(summ, key=int):
        for ns in sorted(summ[t]['sizes'], key=int):
            r = summ[t]['sizes'][ns]
            cells = []
            for R in (200, 1000):
                for kind in ('yade', 'pfv'):
                    e = r[kind]
                    cells.append('%.2f' % ((r['dry'] + e['flow'] + e['remesh'] / R) / r['dry']) if r['dry'] else 'n/a')
            w('| %s | %s | %s | %s | %s | %s |' % (t, ns, cells[0], cells[1], cells[2], cells[3]))
    w('')
    return '\n'.join(L)


def write_report(path, text, begin=BEGIN_MARK, end=END_MARK):
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    block = begin + '\n\n' + text + '\n' + end + '\n'
    if os.path.exists(path):
        old = open(path).read()
        if begin in old and end in old:
            head, rest = old.split(begin, 1)
            tail = rest.split(end, 1)[1]
            new = head + block + tail.lstrip('\n')
        else:
            new = old.rstrip('\n') + '\n\n' + block
    else:
        new = ('# Benchmarks: PFV vs YADE\'s FlowEngine\n\nGenerated by `bench/flow_benchmark.py` '
               '(see its docstring for the protocol). Text outside the markers is kept when the script is re-run.\n\n'
               + block)
    with open(path, 'w') as f:
        f.write(new)


def driver(opts, argv):
    started = datetime.datetime.now().strftime('%Y-%m-%d %H:%M')
    command = 'yade-double -n -x bench/flow_benchmark.py' + ('' if not argv else ' ' + ' '.join(argv))
    machine = machine_description()
    log('machine: %s, %s CPUs, %s; load %s' % (machine.get('Model name'), machine.get('CPU(s)'), machine.get('RAM'),
                                               machine['load average at start']))
    need = sorted(set(opts['sizes']) | (set(opts['oedo_sizes']) if opts['oedometer'] else set()))
    gen_threads = opts['gen_threads'] or max(opts['threads'] + [1])
    packings = {}
    for n in need:
        if not os.path.exists(packing_path(n)):
            log('generating packing n=%d into %s (once; cached)' % (n, packing_path(n)))
            run_child(['--child=generate', '--size=%d' % n], gen_threads, 'generate-%d' % n)
        spheres, meta = read_packing(n)
        meta['digest'] = packing_digest(spheres)
        packings[n] = meta
        log('packing n=%d: %s, porosity %.4f, digest %s' % (n, packing_path(n), meta['porosity'], meta['digest']))
    child_opts = ['--sizes=' + ','.join(map(str, opts['sizes'])), '--rounds=%d' % opts['rounds'],
                  '--steady=%d' % opts['steady'], '--oedo-sizes=' + ','.join(map(str, opts['oedo_sizes'])),
                  '--oedo-steps=%d' % opts['oedo_steps'], '--oedo-interval=%d' % opts['oedo_interval']]
    if not opts['oedometer']:
        child_opts.append('--no-oedometer')
    if not opts['multithread']:
        child_opts.append('--no-multithread')
    if not opts['double']:
        child_opts.append('--no-double')
    if opts['quick']:
        child_opts.append('--quick')
    timing = {}
    for t in opts['threads']:
        timing[str(t)] = run_child(['--child=timing'] + child_opts, t, 'timing-j%d' % t)
    memory = []
    if opts['memory']:
        for n in opts['sizes']:
            for kind in ('dry', 'yade', 'pfv'):
                memory.append(run_child(['--child=memory', '--size=%d' % n, '--engine=' + kind,
                                         '--steady=%d' % opts['steady']] + (['--quick'] if opts['quick'] else []),
                                        1, 'memory-%s-%d' % (kind, n)))
    finished = datetime.datetime.now().strftime('%Y-%m-%d %H:%M')
    builds = sorted(set(d.get('pfv_build') for d in list(timing.values()) + memory if d.get('pfv_build')))
    machine['pfv extension'] = ' | '.join(builds) + (' -- WARNING: the children used different pfv builds '
                                                     '(pfv was reinstalled during the run)' if len(builds) > 1 else '')
    if len(builds) > 1:
        log('WARNING: pfv was reinstalled during the run: %s' % builds)
    machine['load average at end'] = ' '.join('%.2f' % x for x in os.getloadavg())
    summ, mem = summarise(timing, memory)
    text = report(opts, machine, {n: packings[n] for n in opts['sizes']}, summ, mem, command)
    print('\n' + text + '\n', flush=True)
    write_report(opts['out'], text)
    os.makedirs(os.path.dirname(os.path.abspath(opts['json'])), exist_ok=True)
    with open(opts['json'], 'w') as f:
        json.dump(dict(version=REPORT_VERSION, command=command, started=started, finished=finished, machine=machine,
                       packings={str(k): v for k, v in packings.items()}, summary=summ, memory=mem, timing=timing,
                       memory_raw=memory), f, indent=1, default=str)
    log('report written to %s, raw data to %s' % (opts['out'], opts['json']))
    return 0


def report_only(opts):
    """The report of an earlier full run, from its JSON (--json), written to --out: for a change of the report's
    layout, without measuring again. The run's own options come from the command stored in the JSON."""
    with open(opts['json']) as f:
        data = json.load(f)
    if data.get('version') != REPORT_VERSION:
        raise SystemExit('flow_benchmark: %s has layout version %s, this script writes %s'
                         % (opts['json'], data.get('version'), REPORT_VERSION))
    run = parse_args(data['command'].split()[4:])
    packings = {int(n): m for n, m in data['packings'].items() if int(n) in run['sizes']}
    summ, mem = summarise(data['timing'], data['memory_raw'])
    text = report(run, data['machine'], packings, summ, mem, data['command'])
    write_report(opts['out'], text)
    log('report of %s written to %s' % (opts['json'], opts['out']))
    return 0


def startup_report_only(opts):
    """The start-up report of an earlier --startup run, from its JSON (--json), written to --out. The load average
    at the end of each thread count's child is the one the child recorded."""
    with open(opts['json']) as f:
        data = json.load(f)
    run = parse_args(data['command'].split()[4:])
    machine, texts = data['machine'], []
    for t, child in sorted(data['timing'].items(), key=lambda kv: int(kv[0])):
        machine['load average at end'] = ' '.join('%.2f' % x for x in child['load_end'])
        texts.append(startup_report(run, machine, startup_summary(child), data['command'], int(t)))
    write_report(opts['out'], '\n\n'.join(texts), STARTUP_BEGIN_MARK, STARTUP_END_MARK)
    log('start-up report of %s written to %s' % (opts['json'], opts['out']))
    return 0


def main(argv):
    opts = parse_args(argv)
    child = opts['child']
    if opts['report_only']:
        return startup_report_only(opts) if opts['startup'] else report_only(opts)
    if child is None:
        return startup_driver(opts, argv) if opts['startup'] else driver(opts, argv)
    try:
        if child == 'generate':
            data = generate_packing(opts['size'])
        elif child == 'timing':
            data = timing_child(opts)
        elif child == 'startup':
            data = startup_child(opts)
        elif child == 'memory':
            data = memory_child(opts)
        else:
            raise SystemExit('unknown --child=%s' % child)
    except Exception:
        traceback.print_exc()
        sys.stdout.flush()
        return 1
    data['pfv_build'] = pfv_fingerprint()
    with open(opts['child_json'], 'w') as f:
        json.dump(data, f, default=str)
    return 0


def pfv_fingerprint():
    """Where the pfv extension module loaded by this process lives and when it was built: colleagues may reinstall
    pfv while a long benchmark runs; the driver reports it if its children did not all use the same build."""
    mod = sys.modules.get('pfv._core')
    if mod is None:
        return None
    return getattr(mod, '__file__', '?')


if __name__ == '__main__' and 'yade' in sys.modules:
    sys.exit(main(sys.argv[1:]))
elif __name__ == '__main__':
    print('run me with: yade-double -n -x %s [--quick] ...' % sys.argv[0])
    sys.exit(2)
