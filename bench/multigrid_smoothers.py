"""The multigrid's smoothers side by side in one engine: what a step costs with each, static and deforming.

    OMP_NUM_THREADS=1 PYTHONPATH=build/python /usr/bin/python3 bench/multigrid_smoothers.py [N] [--rounds=3]
        (default N = 200000)

One pfv.Engine (no YADE) on bench/core_steady.py's scene (the jittered lattice, multigrid, permeameter along y).
Each round runs the three smoothers (symmetric Gauss-Seidel, split Gauss-Seidel, Jacobi), the order rotating from round
to round; a smoother's turn sets
multigrid_smoother (which rebuilds the hierarchy on the same mesh), then times four phases from the packing's rest
positions:

* static: the spheres still, so each solve starts from the pressures of the last step, which tend to the exact ones
  (one iteration certifies them once the error left by the last multi-iteration solve has been worked off);
* squeeze: every sphere moved towards the mid-plane y by a strain of 2e-5 per step, a smooth motion whose pressures
  the start extrapolated from the last two steps nearly predicts;
* jerky squeeze: a strain of 1e-11 k^3 after k steps, whose changing acceleration the linear extrapolation misses
  by a little (a few iterations);
* random motion: every sphere displaced from its rest position by up to 1e-4 of its radius along each axis, drawn
  afresh at every step, so that the start predicts nothing (the solve is as from a cold start).

The first three steps of each phase are not timed: the jump back to the rest positions and the change of rate make
dV/dt jump, and the start of each solve is extrapolated from the two steps before it. After a change of smoother the
first also builds the hierarchy. Per phase the
median over its steps of the core's solve stage (step_times()) and of the whole step, the CG iterations, and per
round the ratio of each smoother's solve median to the symmetric Gauss-Seidel's of that round. No timing is asserted
anywhere.
"""
import statistics
import sys
import time

import numpy as np

from pfv_testing.lattice import lattice_permeameter

SMOOTHERS = ("gauss_seidel", "split_gauss_seidel", "jacobi")
# name, strain of the squeeze after k steps, random displacement per step in radii, steps
PHASES = (
    ("static", lambda k: 0.0, 0.0, 10),
    ("squeeze", lambda k: 2e-5 * k, 0.0, 6),
    ("jerky squeeze", lambda k: 1e-11 * k**3, 0.0, 6),
    ("random motion", lambda k: 0.0, 1e-4, 6),
)
DT = 1e-4


def moved(pos, rad, mid, strain, shake, rng):
    out = pos.copy()
    out[:, 1] = mid + (pos[:, 1] - mid) * (1 - strain)
    if shake > 0:
        out += rng.uniform(-shake, shake, size=pos.shape) * rad[:, None]
    return out


def turn(engine, pos, rad, walls, smoother):
    """Phases of one smoother: {phase: (solve times, step times, iterations)}."""
    engine.multigrid_smoother = smoother
    mid = 0.5 * (walls[2] + walls[3])
    rng = np.random.default_rng(7)  # the same motions for both smoothers
    out = {}
    for name, strain, shake, steps in PHASES:
        solves, totals, iterations = [], [], []
        for k in range(steps + 3):
            t0 = time.perf_counter()
            engine.step(moved(pos, rad, mid, strain(k), shake, rng), rad, walls, DT)
            if k < 3:
                continue  # the jump to this phase's start and what it leaves in the extrapolated starts
            totals.append(time.perf_counter() - t0)
            solves.append(engine.step_times()["solve"])
            iterations.append(engine.cg_iterations)
        out[name] = (solves, totals, iterations)
    return out


def main(argv):
    sizes = [int(float(a)) for a in argv if not a.startswith("--")] or [200000]
    rounds = next((int(a.split("=")[1]) for a in argv if a.startswith("--rounds=")), 3)
    for n in sizes:
        e, pos, rad, walls = lattice_permeameter(n)
        e.step(pos, rad, walls, DT)
        results = {s: [] for s in SMOOTHERS}
        for r in range(rounds):
            k = r % len(SMOOTHERS)
            for s in SMOOTHERS[k:] + SMOOTHERS[:k]:
                results[s].append(turn(e, pos, rad, walls, s))
        print(
            f"N = {n:,} spheres, {e.n_cells():,} cells, {rounds} rounds (`multigrid_smoothers.py {n} "
            f"--rounds={rounds}`)\n"
        )
        print(
            "| phase | smoother | solve [ms], median per round | step [ms], median | CG iterations | "
            "solve / Gauss-Seidel's, per round |"
        )
        print("|---|---|---|---|---|---|")
        for name, *_ in PHASES:
            for s in SMOOTHERS:
                ratio = [
                    statistics.median(t[name][0]) / statistics.median(g[name][0])
                    for t, g in zip(results[s], results["gauss_seidel"])
                ]
                solve = [1e3 * statistics.median(t[name][0]) for t in results[s]]
                step = 1e3 * statistics.median([x for t in results[s] for x in t[name][1]])
                its = sorted({i for t in results[s] for i in t[name][2]})
                its_text = str(its[0]) if len(its) == 1 else f"{its[0]}–{its[-1]}"
                ratio_text = ", ".join(f"{x:.2f}" for x in ratio) if s != "gauss_seidel" else ""
                print(
                    f"| {name} | {s} | {', '.join(f'{x:.0f}' for x in solve)} | {step:.0f} | {its_text} | "
                    f"{ratio_text} |"
                )
        print(flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
