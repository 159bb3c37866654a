"""The multigrid's smoothers side by side in one engine: what a step costs with each, static and moving; or one
smoother in two builds, the children alternating.

    OMP_NUM_THREADS=1 PYTHONPATH=build/python /usr/bin/python3.11 bench/multigrid_smoothers.py [N] [--rounds=3]
        [--smoothers=gauss_seidel,split_gauss_seidel,jacobi] [--builds=OLD_PYTHONPATH,NEW_PYTHONPATH]
        (default N = 200000)

One pfv.Engine (no YADE) on bench/core_steady.py's scene (the jittered lattice of unit spacing, multigrid,
permeameter along y). Each round runs the smoothers, the order rotating from round to round; a smoother's turn sets
multigrid_smoother (which rebuilds the hierarchy on the same mesh), then times five phases from the packing's rest
positions:

* static: the spheres still, so each solve starts from the pressures of the last step, which tend to the exact ones
  (one iteration certifies them once the error left by the last multi-iteration solve has been worked off);
* squeeze: every sphere moved towards the mid-plane y by a strain of 2e-5 per step, a smooth motion;
* jerky squeeze: a strain of 1e-11 k^3 after k steps, whose acceleration changes from step to step;
* random motion: every sphere displaced from its rest position by up to 1e-4 of its radius along each axis, drawn
  afresh at every step, so that no history predicts the next pressures (the solve is as from a cold start);
* drift: every sphere moving at its own constant velocity, 2e-4 spacings per step in a random direction, dt 1e-5
  (the other phases: 1e-4), the motion whose cell volumes are cubic in time.

The first three steps of each phase are not timed: the jump back to the rest positions and the change of rate make
dV/dt jump, and the start of each solve is predicted from the steps before it. After a change of smoother the first
also builds the hierarchy. Per phase the median over its steps of the core's solve stage (step_times()) and of the
whole step, the CG iterations (range and mean), and per round the ratio of each smoother's solve median to the first
smoother's of that round.

--builds: the first smoother alone, each round one child process per build (the order alternating), so that the
two builds see the same machine; the ratio is then the second build's to the first's. No timing is asserted
anywhere.
"""
import json
import os
import statistics
import subprocess
import sys
import time

import numpy as np
import pfv_testing
from pfv_testing.cli import option
from pfv_testing.lattice import lattice_permeameter

SMOOTHERS = ("gauss_seidel", "split_gauss_seidel", "jacobi")
# name, strain of the squeeze after k steps, random displacement per step in radii, drift per step in spacings, dt,
# steps
PHASES = (
    ("static", lambda k: 0.0, 0.0, 0.0, 1e-4, 10),
    ("squeeze", lambda k: 2e-5 * k, 0.0, 0.0, 1e-4, 6),
    ("jerky squeeze", lambda k: 1e-11 * k**3, 0.0, 0.0, 1e-4, 6),
    ("random motion", lambda k: 0.0, 1e-4, 0.0, 1e-4, 6),
    ("drift", lambda k: 0.0, 0.0, 2e-4, 1e-5, 9),
)
SHARED = os.path.dirname(os.path.dirname(os.path.abspath(pfv_testing.__file__)))


def moved(pos, rad, mid, k, phase, rng, velocity):
    _, strain, shake, drift, _, _ = phase
    out = pos.copy()
    out[:, 1] = mid + (pos[:, 1] - mid) * (1 - strain(k))
    if shake > 0:
        out += rng.uniform(-shake, shake, size=pos.shape) * rad[:, None]
    if drift > 0:
        out += k * drift * velocity
    return out


def turn(engine, pos, rad, walls, smoother):
    """Phases of one smoother: {phase: (solve times, step times, iterations)}."""
    engine.multigrid_smoother = smoother
    mid = 0.5 * (walls[2] + walls[3])
    rng = np.random.default_rng(7)  # the same motions for every smoother
    velocity = rng.normal(size=pos.shape)
    velocity /= np.linalg.norm(velocity, axis=1)[:, None]
    out = {}
    for phase in PHASES:
        name, dt, steps = phase[0], phase[4], phase[5]
        solves, totals, iterations = [], [], []
        for k in range(steps + 3):
            t0 = time.perf_counter()
            engine.step(moved(pos, rad, mid, k, phase, rng, velocity), rad, walls, dt)
            if k < 3:
                continue  # the jump to this phase's start and what it leaves in the predicted starts
            totals.append(time.perf_counter() - t0)
            solves.append(engine.step_times()["solve"])
            iterations.append(engine.cg_iterations)
        out[name] = (solves, totals, iterations)
    return out


def run_rounds(n, rounds, smoothers):
    """{smoother: [phases of each round]} from one engine."""
    e, pos, rad, walls = lattice_permeameter(n)
    e.step(pos, rad, walls, PHASES[0][4])
    results = {s: [] for s in smoothers}
    for r in range(rounds):
        k = r % len(smoothers)
        for s in smoothers[k:] + smoothers[:k]:
            results[s].append(turn(e, pos, rad, walls, s))
    return results, e.n_cells()


def run_builds(n, rounds, smoother, builds):
    """{build: [phases of each round]}, each round one child per build, the order alternating."""
    results = {b: [] for b in builds}
    cells = 0
    for r in range(rounds):
        for b in builds if r % 2 == 0 else builds[::-1]:
            env = dict(os.environ, PYTHONPATH=os.pathsep.join([b, SHARED]))
            args = [sys.executable, os.path.abspath(__file__), str(n), "--child", f"--smoothers={smoother}"]
            out = subprocess.run(args, env=env, check=True, capture_output=True, text=True).stdout
            line = next(x for x in out.splitlines() if x.startswith("RESULT "))
            data = json.loads(line[len("RESULT ") :])
            results[b].append(data["phases"])
            cells = data["cells"]
    return results, cells


def iterations_text(its):
    low, high = min(its), max(its)
    span = str(low) if low == high else f"{low}–{high}"
    return f"{span} ({statistics.mean(its):.1f})"


def print_table(results, label, cells, command):
    names = list(results)
    print(f"{cells:,} cells (`{command}`)\n")
    print(
        f"| phase | {label} | solve [ms], median per round | step [ms], median | CG iterations (mean) | "
        f"solve / {names[0]}'s, per round |"
    )
    print("|---|---|---|---|---|---|")
    for name, *_ in PHASES:
        for s in names:
            ratio = [
                statistics.median(t[name][0]) / statistics.median(g[name][0])
                for t, g in zip(results[s], results[names[0]])
            ]
            solve = [1e3 * statistics.median(t[name][0]) for t in results[s]]
            step = 1e3 * statistics.median([x for t in results[s] for x in t[name][1]])
            its = [i for t in results[s] for i in t[name][2]]
            ratio_text = ", ".join(f"{x:.2f}" for x in ratio) if s != names[0] else ""
            print(
                f"| {name} | {s} | {', '.join(f'{x:.0f}' for x in solve)} | {step:.0f} | {iterations_text(its)} | "
                f"{ratio_text} |"
            )
    print(flush=True)


def main(argv):
    sizes = [int(float(a)) for a in argv if not a.startswith("--")] or [200000]
    rounds = option(argv, "rounds", 3)
    smoothers = tuple(option(argv, "smoothers", ",".join(SMOOTHERS)).split(","))
    builds = [b for b in option(argv, "builds", "").split(",") if b]
    if option(argv, "child", False):
        results, cells = run_rounds(sizes[0], 1, smoothers)
        print("RESULT " + json.dumps(dict(phases=results[smoothers[0]][0], cells=cells)), flush=True)
        return 0
    for n in sizes:
        command = " ".join(["multigrid_smoothers.py", str(n)] + [a for a in argv if a.startswith("--")])
        print(f"N = {n:,} spheres, {rounds} rounds")
        if builds:
            results, cells = run_builds(n, rounds, smoothers[0], builds)
            print_table(results, "build", cells, command)
        else:
            results, cells = run_rounds(n, rounds, smoothers)
            print_table(results, "smoother", cells, command)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
