"""Where a coupled step of pfv.FlowEngine goes in YADE, engine by engine, on bench/growth.py's lattice scene.

    yade-double -j1 -n -x bench/coupled_breakdown.py [--n=1000000]

The scene and the engine of bench/growth.py (build_scene, make_flow: N fixed spheres on the jittered lattice,
aabbWalls, permeameter along y, multigrid):
a dry step before the flow engine is added, the first coupled step (wall time, the core's share, and cProfile's view
of the Python side), then a steady coupled step with every engine's execTime (O.timingEnabled) and the core's
step_times()['total'], and cProfile of one more steady step. The DEM engines' execTime beside the flow engine against
the dry step shows what the coupling costs the DEM itself (the flow's working set evicts the DEM's). No timing is
asserted anywhere.
"""
import cProfile
import io
import pstats
import sys
import time

from pfv_testing.cli import option
from pfv_testing.lattice_scene import build_scene, insert, make_flow


def profile_step(label, rows=12):
    from yade import O

    pr = cProfile.Profile()
    t0 = time.perf_counter()
    pr.enable()
    O.step()
    pr.disable()
    wall = time.perf_counter() - t0
    s = io.StringIO()
    pstats.Stats(pr, stream=s).sort_stats('cumulative').print_stats(rows)
    print('%s: %.3f s of wall time; cProfile, by cumulative time:' % (label, wall))
    print('\n'.join(line for line in s.getvalue().splitlines() if 'pfv' in line or 'ncalls' in line))
    return wall


def main():
    from yade import O

    n = option(sys.argv[1:], 'n', 1000000)
    build_scene(n)
    dry = []
    for _ in range(3):
        t0 = time.perf_counter()
        O.step()
        dry.append(time.perf_counter() - t0)
    print('N = %d: dry steps %s s' % (n, ', '.join('%.3f' % d for d in dry)))
    flow = make_flow('pfv-multigrid')
    insert(flow)
    profile_step('first coupled step')
    print('   of which the core step %.2f s' % flow.core.step_times()['total'])
    for _ in range(2):
        O.step()
    O.timingEnabled = True
    for e in O.engines:
        e.execTime = 0
    t0 = time.perf_counter()
    O.step()
    wall = time.perf_counter() - t0
    print(
        'steady coupled step: %.3f s of wall time, the core step %.3f s; execTime by engine: %s'
        % (
            wall,
            flow.core.step_times()['total'],
            ', '.join('%s %.3f s' % (type(e).__name__, e.execTime * 1e-9) for e in O.engines),
        )
    )
    profile_step('next steady coupled step')
    return 0


if __name__ == '__main__' and 'yade' in sys.modules:
    sys.exit(main())
