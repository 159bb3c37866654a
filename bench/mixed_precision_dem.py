"""Mixed precision inside the DEM loop: solve time, refinement passes and the pressure difference to the double
factor, on the permeameter scene of bench/flow_benchmark.py (cached packing, dynamic spheres, settled).

    yade-double -j1 -n -x bench/mixed_precision_dem.py [--size=10000] [--steps=20] [--tolerances=1e-10,1e-8]

From the same saved state it runs S steps with the double factor (`mixed_precision=False`), then S steps with the
32-bit factor (`mixed_precision=True`, `mixed_precision_min_entries=0` so that it applies at every size) for each
refinement tolerance, and prints per run the median solve stage
(`core.step_times()['solve']`), how many steps took 1, 2, ... refinement passes, the contraction estimate, the median
step-to-step change of the pressures, and the largest |p_mixed - p_double| / max|p_double| over the steps (the DEM is
deterministic at -j1, so both runs see the same positions up to the feedback of that difference). Unlike
bench/solver_stages.py the factor is evicted from the cache by the DEM between two solves, as in a real run.
"""
import sys

import numpy as np

from pfv_testing.cli import option
from pfv_testing.flow_bench import scene as fb  # packing cache, scene, engine set-up

from yade import O  # noqa: E402


def run(steps, mixed, tolerance=None):
    O.loadTmp('bench')
    flow = fb.make_engine('pfv')
    flow.mixed_precision = mixed
    if mixed:
        flow.mixed_precision_min_entries = 0  # the 32-bit factor at every size (the default keeps small ones double)
    if tolerance is not None:
        flow.refinement_tolerance = tolerance
    fb.insert_engine(flow)
    for _ in range(5):  # first mesh, factor and the refinement's contraction estimate
        O.step()
    core = flow.core
    solve, passes, change, history = [], [], [], []
    previous = np.array(core.pressure())
    for _ in range(steps):
        O.step()
        p = np.array(core.pressure())
        solve.append(core.step_times()['solve'])
        passes.append(core.refinement_passes)
        change.append(np.abs(p - previous).max() / np.abs(p).max())
        history.append(p)
        previous = p
    result = dict(
        solve=float(np.median(solve)),
        passes=np.bincount(passes).tolist(),
        contraction=core.refinement_contraction(),
        change=float(np.median(change)),
        history=history,
    )
    O.engines = O.engines[:1]
    return result


def main():
    n = option(sys.argv[1:], 'size', 10000)
    steps = option(sys.argv[1:], 'steps', 20)
    tolerances = [float(t) for t in option(sys.argv[1:], 'tolerances', '1e-10,1e-8').split(',')]
    fb.build_scene(n)
    O.saveTmp('bench')
    reference = run(steps, False)
    print('N = %d, %d steps, %d thread(s)' % (n, steps, O.numThreads))
    print(
        'double factor: solve %.2f ms (median), pressure change per step %.2g of max|p|'
        % (1e3 * reference['solve'], reference['change'])
    )
    for tol in tolerances:
        r = run(steps, True, tol)
        diff = max(np.abs(a - b).max() / np.abs(b).max() for a, b in zip(r['history'], reference['history']))
        print(
            'mixed, refinement_tolerance %.0e: solve %.2f ms, steps with 0/1/2/... passes %s, contraction %.2g, '
            'max |p - p_double| / max|p| %.1e' % (tol, 1e3 * r['solve'], r['passes'], r['contraction'], diff)
        )


main()
