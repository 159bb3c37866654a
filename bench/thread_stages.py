"""The flow step's stages at one and two threads in a moving packing, and the exchange with YADE.

    PYTHONPATH=build/python /usr/bin/python3.11 bench/thread_stages.py [--n=10000,50000,200000]
        [--solvers=cholesky,multigrid] [--rounds=7] [--exchange=1] [--bandwidth_cores=8]

The packing: pfv_testing.lattice.jittered_lattice(N) in the box of its extent plus 0.2, flow along y (100 against 0),
every sphere drifting with its own constant random velocity of 2e-4 lattice spacings per step, no scheduled remesh.
Two engines, one stepped at one OpenMP thread and one at two (pfv.set_num_threads before each step), take the same
positions at every step; the order of the two alternates from round to round, so both see the same load of the
shared cores. After a warm-up the stages of `Engine.step_times()` are recorded each round: dV/dt (volumes), the solve,
the forces, and the rest of the core's step (validation, the right-hand side, the commit), and the wall time of
`Engine.step` seen from Python (which adds the copy of the positions). Every round also checks that the two engines'
pressures and forces agree (printed as the largest relative difference; 0 means bit-identical).

With --exchange=1 (the default) the script also runs itself under `yade-double -n -x` for the exchange with YADE at
each N: the lattice scene of pfv_testing.lattice_scene with every sphere a non-fixed body drifting at constant
velocity (no contacts), a pfv.FlowEngine, and the two halves of its exchange timed directly: reading the positions
(`scan.read_positions`, YADE's SpherePack.fromSimulation and PFV's gather) and adding the forces (`force_bridge.apply`
into O.forces), at ompThreads 1 and 2 alternately. Prints one table: per N, solver and stage the median time at one
and two threads (ms), the per-round range, the speed-up of the medians (x) and of the best rounds (best: the
rounds least disturbed by other processes on shared cores). No time is asserted.

Then two models of the flow step (the core step plus the exchange) at 1, 2, 8, 16, 32 and 64 threads, each stage's
one-thread median scaled by Amdahl's law, s + (1 - s) / p: with the serial fractions s fitted to the best rounds
(t2 / t1 = s + (1 - s) / 2), and with those of the code (MODEL_STAGES). Stages that stream memory are held at no less
than 1 / --bandwidth_cores (default 8) of their one-thread time. Beyond two threads both are extrapolations.
"""
import json
import os
import statistics
import subprocess
import sys
import time

import numpy as np

from pfv_testing.cli import option
from pfv_testing.lattice import jittered_lattice, permeameter_engine, walls_around

DRIFT = 2e-4  # lattice spacings per step
STAGES = ('volumes', 'solve', 'forces', 'rest', 'core total', 'Engine.step')
EXCHANGE = ('read positions', 'add forces')
ROW = '| %7s | %-9s | %-14s | %9s | %-15s | %9s | %-15s | %4s | %4s |'


def option_list(argv, name, default, kind=str):
    return [kind(float(x)) if kind is int else kind(x) for x in str(option(argv, name, default)).split(',')]


def drifting_packing(n):
    pos, rad = jittered_lattice(n)
    walls = walls_around(pos, rad, 0.2)
    rng = np.random.default_rng(3)
    velocity = rng.normal(size=pos.shape)
    velocity *= DRIFT / np.linalg.norm(velocity, axis=1)[:, None]
    return pos, rad, walls, velocity


def timed_step(engine, threads, pos, rad, walls):
    import pfv

    pfv.set_num_threads(threads)
    t0 = time.perf_counter()
    engine.step(pos, rad, walls, 1e-5)
    wall = time.perf_counter() - t0
    st = engine.step_times()
    staged = st['volumes'] + st['solve'] + st['forces']
    return {
        'volumes': st['volumes'],
        'solve': st['solve'],
        'forces': st['forces'],
        'rest': st['total'] - staged,
        'core total': st['total'],
        'Engine.step': wall,
    }


def largest_difference(a, b):
    scale = max(np.abs(a).max(), np.abs(b).max(), 1e-300)
    return float(np.abs(a - b).max() / scale)


def core_rows(n, solver, rounds, warmup=3):
    """Per stage: the times at 1 and at 2 threads, one per round; and the largest difference seen."""
    pos, rad, walls, velocity = drifting_packing(n)
    engines = {1: permeameter_engine(solver), 2: permeameter_engine(solver)}
    times = {t: {s: [] for s in STAGES} for t in engines}
    diff = 0.0
    for k in range(warmup + rounds):
        order = (1, 2) if k % 2 == 0 else (2, 1)
        for t in order:
            step = timed_step(engines[t], t, pos, rad, walls)
            if k >= warmup:
                for s in STAGES:
                    times[t][s].append(step[s])
        p1, p2 = np.asarray(engines[1].pressure()), np.asarray(engines[2].pressure())
        f1, f2 = np.asarray(engines[1].forces()), np.asarray(engines[2].forces())
        diff = max(diff, largest_difference(p1, p2), largest_difference(f1, f2))
        pos = pos + velocity
    return times, diff


def exchange_child(n, rounds):
    """Under YADE: the exchange's two halves at ompThreads 1 and 2, printed as one JSON line."""
    from yade import O
    from yade.minieigenHP import Vector3

    from pfv_testing.lattice_scene import build_scene, insert, make_flow

    build_scene(n)
    rng = np.random.default_rng(3)
    for b in O.bodies:
        if b.id >= 6:
            b.state.blockedDOFs = ''
            v = rng.normal(size=3)
            v *= DRIFT / np.linalg.norm(v) / O.dt
            b.state.vel = Vector3(*v)
            b.state.angVel = Vector3(0, 0, 0)
    O.engines = [e for e in O.engines if type(e).__name__ in ('ForceResetter', 'NewtonIntegrator')]
    for e in O.engines:
        if type(e).__name__ == 'NewtonIntegrator':
            e.damping = 0
    flow = make_flow('pfv-multigrid')
    insert(flow)
    for _ in range(3):
        O.step()
    bodies = flow._bodies
    times = {t: {s: [] for s in EXCHANGE} for t in (1, 2)}
    for k in range(rounds):
        for t in (1, 2) if k % 2 == 0 else (2, 1):
            flow.ompThreads = t
            O.step()  # the engine sets its threads in its step; the next step's exchange runs at them
            scan = bodies.scan
            t0 = time.perf_counter()
            scan.read_positions(bodies.boundaryUseMaxMin)
            t1 = time.perf_counter()
            scan.force_bridge.apply(O.forces.addF, flow.core)
            t2 = time.perf_counter()
            times[t]['read positions'].append(t1 - t0)
            times[t]['add forces'].append(t2 - t1)
    print('EXCHANGE ' + json.dumps({str(t): v for t, v in times.items()}), flush=True)


def exchange_rows(n, rounds):
    here = os.path.abspath(__file__)
    out = subprocess.run(
        ['yade-double', '-j2', '-n', '-x', here, '--child=exchange', '--n=%d' % n, '--rounds=%d' % rounds],
        capture_output=True,
        text=True,
        check=True,
    ).stdout
    line = [x for x in out.splitlines() if x.startswith('EXCHANGE ')][-1]
    return {int(t): v for t, v in json.loads(line[len('EXCHANGE ') :]).items()}


def print_row(n, solver, stage, one, two, note=''):
    """Median (ms) and range of each, the speed-up of the medians and of the best rounds."""
    m1, m2 = statistics.median(one) * 1e3, statistics.median(two) * 1e3
    r1 = '%.2f-%.2f' % (min(one) * 1e3, max(one) * 1e3)
    r2 = '%.2f-%.2f' % (min(two) * 1e3, max(two) * 1e3)
    x, best = '%.2f' % (m1 / m2), '%.2f' % (min(one) / min(two))
    print(ROW % (n, solver, stage, '%.2f' % m1, r1, '%.2f' % m2, r2, x, best) + note, flush=True)


# The stages the model extrapolates: (name, where its times are, bandwidth-bound, structural serial fraction, most
# threads it can use). The structural fractions are those of the code: dV/dt and the forces are single loops over
# cells and vertices on the team; the rest of the core's step and the exchange with YADE run on one thread; the
# Cholesky solve is the substitution, planned for two groups of subtrees (ParallelSubstitution::plan(view, 2)), and
# the refinement's residual, both on the team (its O(n) vector operations are left out); the multigrid solve is PFV's
# V-cycle, CG and the solution history on the team, over at most 16 Gauss-Seidel blocks per level
# (AmgCycle::kMaxBlocks), the copies in and out on one thread: s = 0.08 is an upper bound, the share measured at
# 200 000 spheres for the copies and the history together, before the history's passes went to the team.
# Bandwidth-bound: both solves (the factor, the hierarchy's matrices) and the forces (S, 28 bytes per two flops);
# dV/dt computes a determinant per cell from four gathered centres.
MODEL_STAGES = (
    ('volumes', 'core', False, {'cholesky': 0.0, 'multigrid': 0.0}, None),
    ('solve', 'core', True, {'cholesky': 0.0, 'multigrid': 0.08}, {'cholesky': 2, 'multigrid': 16}),
    ('forces', 'core', True, {'cholesky': 0.0, 'multigrid': 0.0}, None),
    ('rest', 'core', True, {'cholesky': 1.0, 'multigrid': 1.0}, None),
    ('read positions', 'exchange', True, {'cholesky': 1.0, 'multigrid': 1.0}, None),
    ('add forces', 'exchange', False, {'cholesky': 1.0, 'multigrid': 1.0}, None),
)
CORES = (1, 2, 8, 16, 32, 64)


def fitted_fraction(one, two):
    """Amdahl's s from the best rounds at one and two threads: t2 / t1 = s + (1 - s) / 2."""
    return min(1.0, max(0.0, 2 * min(two) / min(one) - 1))


def modelled_step(stages, cores, bandwidth_cores):
    """The flow step at `cores` threads: per stage its one-thread median times s + (1 - s) / p, p capped where the
    stage can use no more threads, and not below 1 / bandwidth_cores of it where the stage streams memory (the cores
    one socket's memory bandwidth feeds)."""
    total = 0.0
    for t1, s, cap, bound in stages:
        p = min(cores, cap) if cap else cores
        factor = s + (1 - s) / p
        if bound:
            factor = max(factor, 1.0 / bandwidth_cores)
        total += t1 * factor
    return total


def print_model(n, solver, times, exchange, bandwidth_cores):
    """Two models of the flow step (core step and exchange) against cores: Amdahl's serial fractions fitted to the
    best rounds at one and two threads, and those of the code's structure."""
    fitted, structural, names = [], [], []
    for name, where, bound, serial, cap in MODEL_STAGES:
        source = times if where == 'core' else exchange
        if not source:
            continue
        one, two = source[1][name], source[2][name]
        t1, s = statistics.median(one), fitted_fraction(one, two)
        names.append('%s %.2f' % (name, s))
        fitted.append((t1, s, None, bound))
        structural.append((t1, serial[solver], (cap or {}).get(solver), bound))
    for label, stages in (('fitted (%s)' % ', '.join(names), fitted), ('structural', structural)):
        base = modelled_step(stages, 1, bandwidth_cores)
        predicted = ', '.join(
            '%d: %.1f ms (%.2fx)' % (p, t * 1e3, base / t)
            for p, t in ((p, modelled_step(stages, p, bandwidth_cores)) for p in CORES)
        )
        print('model %d %s, %s: %s' % (n, solver, label, predicted), flush=True)


def main(argv):
    if option(argv, 'child', '') == 'exchange':
        exchange_child(int(float(option(argv, 'n', 10000))), int(option(argv, 'rounds', 7)))
        return
    sizes = option_list(argv, 'n', '10000,50000,200000', int)
    solvers = option_list(argv, 'solvers', 'cholesky,multigrid')
    rounds = int(option(argv, 'rounds', 7))
    exchange = int(option(argv, 'exchange', 1))
    bandwidth_cores = float(option(argv, 'bandwidth_cores', 8.0))
    print(ROW % ('N', 'solver', 'stage', '1 thr, ms', 'range', '2 thr, ms', 'range', 'x', 'best'))
    print(ROW % tuple('-' * w for w in (7, 9, 14, 9, 15, 9, 15, 4, 4)))
    measured = []
    for n in sizes:
        cores = {}
        for solver in solvers:
            times, diff = core_rows(n, solver, rounds)
            cores[solver] = times
            for s in STAGES:
                note = '  (1 vs 2 threads: max rel. diff %.1e)' % diff if s == 'Engine.step' else ''
                print_row(n, solver, s, times[1][s], times[2][s], note)
        ex = exchange_rows(n, rounds) if exchange else None
        for s in EXCHANGE if ex else ():
            print_row(n, 'YADE', s, ex[1][s], ex[2][s])
        measured += [(n, solver, times, ex) for solver, times in cores.items()]
    print()
    for n, solver, times, ex in measured:
        print_model(n, solver, times, ex, bandwidth_cores)


if __name__ == '__main__':
    main(sys.argv[1:])
