"""Stage measurements behind doc/benchmarks.md (stage measurements) and doc/solvers.md, on the cached benchmark
packing (made by bench/flow_benchmark.py).

    yade-double -j1 -n -x bench/solver_stages.py [--size=10000] [--sections=1,2,3,4,5,6,7,8,9]

1. ordering reuse: CHOLMOD analysis with a fresh METIS ordering and with the ordering carried over from the previous
   mesh, for the same positions and after moving every sphere at random by 0.5 % and 2 % of the mean radius
   (fill per unknown, kept or not, share of new cells);
2. mixed precision: solve time of the double and of the refined 32-bit factor in a loop, with the factor
   in cache and evicted before every solve, refinement passes, contraction estimate, largest pressure difference /
   max|p|;
3. force write to YADE: the engine's bridge (Vector3 written in place) against addF with tuples from Python;
4. positions read: coordsAndDisplacements for the three axes with the lists alive together, and one at a time,
   against SpherePack.fromSimulation() plus the engine's in-place read of the pack (gather_sphere_pack);
5. successive forced remeshes of one pfv.FlowEngine on the settled permeameter scene of bench/flow_benchmark.py (the
   benchmark's "remesh" is the second mesh of an engine): C++ stage times per remesh, and CHOLMOD's numeric
   factorisation with its own OpenMP teams (4 threads, its compiled-in CHOLMOD_OMP_NUM_THREADS;
   `flow.core.cholmod_openmp_teams`) against the engine's default, PFV's numeric factorisation on CHOLMOD's
   symbolic factor, and the page faults of each remesh step (getrusage: the factor's storage is reused from the
   second mesh on);
6. the collective viscous limit of a first mesh (drained top, viscosity 10, density 2600): the engine's Arnoldi
   (at most 40 operator applications) against power iteration from the same fixed start, 40 and 120 iterations,
   and the certified lower bounds, global (what the time-step guard asks first) and local (their ratios to the
   limit and their cost);
7. the first ordering against the size (the threshold kGeometricFrom of ordering="auto"): sub-cubes of the packing
   of about 1 000 to 32 000 spheres and the whole packing, each ordered by AMD alone, METIS alone, the geometric
   nested dissection (ordering="geometric") and CHOLMOD's rule (ordering="cholmod": AMD, then METIS if AMD fills
   badly, the better kept; what "auto" does below the threshold):
   analysis and factorisation times, nnz(L), the solve, and which ordering the rule keeps.
8. first touch: writing a block the size of this packing's factor (8 bytes per entry of L) that the process has
   never written (a fresh mapping, which the kernel zeroes page by page on the first write) against writing it
   again, with transparent huge pages (numpy's madvise) and with 4 kB pages, three fresh blocks each, alternating and
   all kept: the cost a first factorisation pays and a remesh, reusing its storage, does not.
9. the first geometric ordering on one and on two OpenMP threads (the dissection's subtrees split in parallel):
   fresh engines, the two thread counts alternating; the analysis stage (the ordering and CHOLMOD's symbolic
   factorisation) and nnz(L), which is the same when the order is.
Minimum and median over repetitions; no DEM runs between the solves (doc/benchmarks.md gives the in-loop numbers;
section 2 imitates the DEM's eviction of the factor).
"""
import resource
import sys
import time

import numpy as np

from pfv_testing.cli import option
from pfv_testing.flow_bench import scene as fb  # the packing cache

import pfv  # noqa: E402
import yade  # noqa: E402
from yade import O, utils  # noqa: E402
from yade.minieigenHP import Vector3  # noqa: E402
from yade._packSpheres import SpherePack  # noqa: E402


def stats(times):
    return 'min %.2f ms, median %.2f ms' % (1e3 * min(times), 1e3 * float(np.median(times)))


def engine(mixed=False, reuse=True):
    e = pfv.Engine()
    e.bnd_is_pressure = [False, False, True, True, False, False]
    e.bnd_value = [0, 0, 100.0, 0, 0, 0]
    e.viscosity = 1e-3
    e.slip_boundary = False
    e.mesh_update_interval = 10**9
    e.mixed_precision = mixed
    e.mixed_precision_min_entries = 0  # with mixed: the 32-bit factor whatever the size
    e.reuse_ordering = reuse
    return e


def ordering(pos, rad, walls):
    print('1. ordering reuse')
    rng = np.random.default_rng(1)
    for amplitude in (0.0, 0.005, 0.02):
        fresh, reused = engine(reuse=False), engine()
        reused.step(pos, rad, walls, 1e-4)
        moved = pos + rng.normal(0, amplitude * rad.mean(), pos.shape)
        for e in (fresh, reused):
            e.request_remesh()
            e.step(moved, rad, walls, 1e-4)
        old = set(tuple(sorted(c)) for c in np.asarray(engine_cells(pos, rad, walls)).tolist())
        new = [tuple(sorted(c)) for c in np.asarray(reused.cell_vertices()).tolist()]
        share_new = sum(c not in old for c in new) / len(new)
        print(
            '   moved by %.1f %% of a radius (%.1f %% new cells): fresh analysis %.3f s, fill %.1f; carried over: '
            'analysis %.3f s, fill %.1f, kept %s'
            % (
                100 * amplitude,
                100 * share_new,
                fresh.remesh_times()['analysis'],
                fresh.factor_fill(),
                reused.remesh_times()['analysis'],
                reused.factor_fill(),
                reused.ordering_reused(),
            )
        )


def engine_cells(pos, rad, walls):
    e = engine()
    e.step(pos, rad, walls, 1e-4)
    return e.cell_vertices()


def mixed_precision(pos, rad, walls):
    print(
        '2. mixed precision, the factor in cache (a loop of solves) and evicted before each solve (a 256 MB buffer '
        'written in between, as the DEM does in a run)'
    )
    rng = np.random.default_rng(2)
    vel = rng.normal(0, 1e-3, pos.shape)
    evictor = np.zeros(32 * 2**20)
    for evict in (False, True):
        result = {}
        for mixed in (False, True):
            e, p, times, pressures = engine(mixed=mixed), pos.copy(), [], []
            for i in range(30):
                p = p + vel * 1e-4
                if evict:
                    evictor += 1.0
                e.step(p, rad, walls, 1e-4)
                times.append(e.step_times()['solve'])
                pressures.append(e.pressure())
            result[mixed] = pressures
            print(
                '   %s, %s: solve %s (steps 4-30), passes at the last step %d, contraction %.2g'
                % (
                    'evicted ' if evict else 'in cache',
                    'mixed ' if mixed else 'double',
                    stats(times[3:]),
                    e.refinement_passes,
                    e.refinement_contraction(),
                )
            )
        diff = max(np.abs(a - b).max() / np.abs(b).max() for a, b in zip(result[True], result[False]))
        print('   largest |p_mixed - p_double| / max|p| over the 30 steps: %.2g' % diff)


def exchange(pos, rad, L):
    O.reset()
    O.bodies.append(utils.aabbWalls([(0, 0, 0), (L, L, L)], thickness=0))
    for x, r in zip(pos, rad):
        O.bodies.append(utils.sphere(tuple(x), r))
    n = len(O.bodies)
    print('3. force write to YADE, %d bodies' % n)
    ids = np.arange(n, dtype=np.int64)
    forces = np.random.default_rng(3).normal(size=(n, 3))
    bridge = pfv._core.YadeForceBridge(Vector3, ids, ids)
    add = O.forces.addF
    tuples = [tuple(f) for f in forces.tolist()]
    t_bridge, t_tuples = [], []
    for k in range(20):
        t0 = time.perf_counter()
        bridge.apply(add, forces)
        t_bridge.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        for i in range(n):
            add(i, tuples[i])
        t_tuples.append(time.perf_counter() - t0)
    print(
        '   bridge (in place: %s): %s; addF with tuples from Python: %s'
        % (bridge.writes_in_place, stats(t_bridge), stats(t_tuples))
    )
    print('4. positions read, %d bodies' % n)
    read = yade._utils.coordsAndDisplacements
    together, apart = [], []
    for k in range(10):
        t0 = time.perf_counter()
        lists = [read(axis)[0] for axis in range(3)]
        together.append(time.perf_counter() - t0)
        del lists
        t0 = time.perf_counter()
        for axis in range(3):
            c = read(axis)[0]
            del c
        apart.append(time.perf_counter() - t0)
    pack = SpherePack()
    index = np.arange(len(pos), dtype=np.int64)
    centres = np.empty((len(pos), 3))
    fill, packed = [], []
    for k in range(10):
        t0 = time.perf_counter()
        pack.fromSimulation()
        fill.append(time.perf_counter() - t0)
        pfv._core.gather_sphere_pack(pack, index, centres)
        packed.append(time.perf_counter() - t0)
    print('   three lists alive together: %s; one axis at a time: %s' % (stats(together), stats(apart)))
    print(
        '   SpherePack.fromSimulation(): %s; with the in-place read of its centres: %s' % (stats(fill), stats(packed))
    )


def remesh_sequence(n):
    print('5. successive forced remeshes, pfv.FlowEngine in the DEM scene')
    fb.build_scene(n)
    flow = fb.make_engine('pfv')
    fb.insert_engine(flow)
    for _ in range(3):
        O.step()
    core = flow.core
    keys = ('triangulation', 'geometry', 'conductance', 'factorization', 'force_cache')
    for serial in (True, True, True, False, True):
        core.cholmod_openmp_teams = not serial
        flow.updateTriangulation = True
        faults = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
        O.step()
        faults = resource.getrusage(resource.RUSAGE_SELF).ru_minflt - faults
        t = core.remesh_times()
        print(
            '   mesh %d, %s: %s; %d page faults'
            % (
                core.remesh_count,
                "PFV's numeric factorisation" if serial else "CHOLMOD's, in its teams of 4",
                ', '.join('%s %.1f ms' % (k, 1e3 * t[k]) for k in keys),
                faults,
            )
        )
    O.engines = O.engines[:1]


def collective_limit(pos, rad, walls):
    print('6. collective viscous limit, first mesh')
    e = engine()
    e.bnd_is_pressure = [False, False, False, True, False, False]
    e.viscosity = 10.0
    for _ in range(2):  # the operator is linearised about the previous step's positions
        e.step(pos, rad, walls, 1e-4)
    mass = 2600 * 4 / 3 * np.pi * rad**3
    t0 = time.perf_counter()
    arnoldi = e.viscous_stability_limit(mass, 40)
    t_arnoldi = time.perf_counter() - t0
    k = np.arange(len(rad))  # the engine's fixed start, continued 3 power iterations per call
    mode = np.stack([np.sin(1.0 + 3.1 * k), np.cos(2.0 + 1.7 * k), np.sin(0.5 + 2.3 * k)], axis=1)
    t0 = time.perf_counter()
    power = []
    for _ in range(40):
        limit, mode, _ = e.viscous_stability_mode(mass, 3, mode)
        power.append(limit)
    t_power = (time.perf_counter() - t0) / 3  # per 40 iterations
    print(
        '   Arnoldi %.7g s in %.3f s; power iteration: %.7g after 39 iterations (%.3f s), %.7g after 120; '
        'power-39 / Arnoldi - 1 = %.2g' % (arnoldi, t_arnoldi, power[12], t_power, power[-1], power[12] / arnoldi - 1)
    )
    for name, method in (
        ('global bound (what the time-step guard asks first)', e.viscous_stability_bound),
        ('local bound', e.viscous_stability_local_bound),
    ):
        times = []
        for _ in range(3):
            t0 = time.perf_counter()
            bound = method(mass)
            times.append(time.perf_counter() - t0)
        print(
            '   certified %s %.4g s = %.3g x Arnoldi\'s limit, in %.3f s (min of 3; the first %.3f s)'
            % (name, bound, bound / arnoldi, min(times), times[0])
        )


def ordering_threshold(pos, rad, L, repeats=3):
    """Section 7: the first ordering of sub-cubes of the packing: AMD alone, METIS alone, the geometric nested
    dissection and CHOLMOD's rule."""
    print(
        '7. first ordering against the size (medians of %d fresh engines each; the solve: the double factor)' % repeats
    )
    print(
        '   %8s %8s | %-38s | %-38s | %-38s | %-24s'
        % (
            'spheres',
            'unknowns',
            'AMD: analysis, factor, nnz(L), solve',
            'METIS: analysis, factor, nnz(L), solve',
            'geometric: analysis, factor, nnz(L), solve',
            "CHOLMOD's rule: analysis, kept",
        )
    )
    for target in (1000, 2000, 3000, 4000, 8000, 16000, 32000, 64000):
        if target > 1.2 * len(rad):
            break
        side = L * min(1.0, target / len(rad)) ** (1.0 / 3.0)
        inside = np.all(pos - rad[:, None] >= 0, axis=1) & np.all(pos + rad[:, None] <= side, axis=1)
        p, r, walls = pos[inside].copy(), rad[inside].copy(), [0, side, 0, side, 0, side]
        row = {}
        for name in ('amd', 'metis', 'geometric', 'cholmod'):
            runs = []
            for _ in range(repeats):
                e = engine()
                e.ordering = name
                e.step(p, r, walls, 1e-4)
                t = e.remesh_times()
                e.step(p, r, walls, 1e-4)
                runs.append(
                    (t['analysis'], t['factorization'], e.factor_nonzeros(), e.step_times()['solve'], e.metis_used())
                )
                unknowns = e.n_unknowns()
            row[name] = [float(np.median([x[k] for x in runs])) for k in range(4)] + [{x[4] for x in runs}]
        kept = '/'.join(sorted('METIS' if m else 'AMD' for m in row['cholmod'][4]))
        cells = ' | '.join(
            '%7.3f s %7.3f s %8.3g %6.2f ms' % (*row[k][:3], 1e3 * row[k][3]) for k in ('amd', 'metis', 'geometric')
        )
        print('   %8d %8d | %s | %7.3f s  %s' % (len(r), unknowns, cells, row['cholmod'][0], kept))
    print(
        '   ordering="auto" is CHOLMOD\'s rule below %d unknowns and the geometric nested dissection from there on'
        % pfv.Engine.geometric_from
    )


def first_touch(pos, rad, walls):
    print('8. first touch of a block the size of the factor')
    e = engine()
    e.step(pos, rad, walls, 1e-4)
    n = int(e.factor_nonzeros())
    print('   %d entries of L: %.0f MB' % (n, 8e-6 * n))
    huge = np.core.multiarray._set_madvise_hugepage(False)
    rates = {False: [], True: []}
    blocks = []  # all kept until the end: a freed block's pages would serve the next one already written
    try:
        for advise in (True, False) * 3:
            np.core.multiarray._set_madvise_hugepage(advise)
            block = np.empty(n)  # beyond glibc's mmap threshold: a mapping of its own, untouched
            t0 = time.perf_counter()
            block.fill(1.0)
            t1 = time.perf_counter()
            block.fill(2.0)
            t2 = time.perf_counter()
            rates[advise].append((8e-9 * n / (t1 - t0), 8e-9 * n / (t2 - t1)))
            blocks.append(block)
    finally:
        np.core.multiarray._set_madvise_hugepage(huge)
    for advise, pages in ((False, '4 kB pages'), (True, 'huge pages')):
        r = rates[advise]
        print(
            '   %s: first write %s GB/s, second %s GB/s'
            % (pages, ', '.join('%.2f' % x[0] for x in r), ', '.join('%.1f' % x[1] for x in r))
        )


def parallel_ordering(pos, rad, walls, repeats=5):
    """Section 9: the first geometric ordering on one and on two threads."""
    print('9. first geometric ordering, 1 and 2 OpenMP threads alternating (%d fresh engines each)' % repeats)
    threads = pfv.get_max_threads()
    analysis, entries = {1: [], 2: []}, {1: set(), 2: set()}
    try:
        for _ in range(repeats):
            for t in (1, 2):
                pfv.set_num_threads(t)
                e = engine()
                e.ordering = 'geometric'
                e.step(pos, rad, walls, 1e-4)
                analysis[t].append(e.remesh_times()['analysis'])
                entries[t].add(e.factor_nonzeros())
    finally:
        pfv.set_num_threads(threads)
    for t in (1, 2):
        print(
            '   %d thread%s: analysis %s; nnz(L) %s'
            % (t, 's' if t > 1 else '', stats(analysis[t]), ', '.join('%d' % x for x in sorted(entries[t])))
        )
    print('   two threads / one (medians): %.2f' % (np.median(analysis[2]) / np.median(analysis[1])))


def main():
    n = option(sys.argv[1:], 'size', 10000)
    spheres, meta = fb.read_packing(n)
    a = np.array(spheres, dtype=float)
    pos, rad = a[:, :3].copy(), a[:, 3].copy()
    L = meta.get('box', fb.box_side(n))
    walls = [0, L, 0, L, 0, L]
    print('solver_stages: N = %d, packing %s' % (n, fb.packing_path(n)))
    sections = option(sys.argv[1:], 'sections', '1,2,3,4,5,6,7,8,9').split(',')
    if '1' in sections:
        ordering(pos, rad, walls)
    if '2' in sections:
        mixed_precision(pos, rad, walls)
    if '3' in sections or '4' in sections:
        exchange(pos, rad, L)
    if '6' in sections:
        collective_limit(pos, rad, walls)
    if '7' in sections:
        ordering_threshold(pos, rad, L)
    if '8' in sections:
        first_touch(pos, rad, walls)
    if '9' in sections:
        parallel_ordering(pos, rad, walls)
    if '5' in sections:
        remesh_sequence(n)
    return 0


if __name__ == '__main__' and 'yade' in sys.modules:
    sys.exit(main())
