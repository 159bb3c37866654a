"""Two builds of pfv side by side: the first step, the steady flow step and a forced remesh. For a change that
must not alter speed (a refactoring), or one meant to change it, run the build before and the
build after; the children alternate between the builds round after round, so that drift of the
machine falls on both.

    PYTHONPATH=build/python python3 bench/compare_builds.py --builds=OLD_PYTHONPATH,NEW_PYTHONPATH
        [--size=10000] [--rounds=3] [--steady=20] [--remeshes=2] [--threads=1]
        [--scene=permeameter|lattice] [--solver=auto]

--scene=permeameter (default): the benchmark permeameter in YADE (the cached dense packing of
bench/flow_benchmark.py, dynamic spheres, CHOLMOD, settled), times as the engine's execTime in
the DEM loop. --scene=lattice: the C++ engine alone (pfv.Engine, no YADE) on bench/growth.py's
jittered lattice with fixed spheres (pfv_testing.lattice), with --solver (auto, cholesky,
multigrid); times are the step's wall time, and the solve's is reported beside it.

Each PYTHONPATH holds a `pfv` package (e.g. build/python); the children find pfv_testing where the
driver did. Prints per build the median over rounds of the per-round medians, and the ratio of
the second build to the first. No timing is asserted anywhere.
"""
import json
import os
import statistics
import subprocess
import sys

import pfv_testing
from pfv_testing.cli import option

SHARED = os.path.dirname(os.path.dirname(os.path.abspath(pfv_testing.__file__)))


def lattice_child(argv):
    from pfv_testing.lattice import lattice_permeameter
    from pfv_testing.timing import wall

    e, pos, rad, walls = lattice_permeameter(int(float(option(argv, "size", "10000"))))
    e.solver = option(argv, "solver", "auto")

    def timed_step():
        return wall(lambda: e.step(pos, rad, walls, 1e-4))

    first = timed_step()
    for _ in range(3):  # settling steps
        timed_step()
    steady, solve = [], []
    for _ in range(int(option(argv, "steady", "20"))):
        steady.append(timed_step())
        solve.append(e.step_times()["solve"])
    remesh = []
    for _ in range(int(option(argv, "remeshes", "2"))):
        e.request_remesh()
        remesh.append(timed_step())
        for _ in range(2):
            timed_step()
    print(
        "RESULT "
        + json.dumps(
            dict(
                first=first,
                steady=statistics.median(steady),
                solve=statistics.median(solve),
                remesh=statistics.median(remesh),
                cells=e.n_cells(),
                package=__import__("pfv").__file__,
            )
        )
    )


def child(argv):
    if option(argv, "scene", "permeameter") == "lattice":
        return lattice_child(argv)
    from pfv_testing.flow_bench import scene as fb
    from yade import O

    n = int(option(argv, "size", "10000"))
    if not os.path.exists(fb.packing_path(n)):
        fb.generate_packing(n)
    fb.build_scene(n)
    flow = fb.make_engine("pfv")
    fb.insert_engine(flow)
    O.timingEnabled = True

    def timed_step():
        e0 = flow.execTime
        O.step()
        return (flow.execTime - e0) * 1e-9

    first = timed_step()
    for _ in range(2):
        timed_step()
    steady = [timed_step() for _ in range(int(option(argv, "steady", "20")))]
    remesh = []
    for _ in range(int(option(argv, "remeshes", "2"))):
        flow.updateTriangulation = True
        remesh.append(timed_step())
        for _ in range(2):
            timed_step()
    print(
        "RESULT "
        + json.dumps(
            dict(
                first=first,
                steady=statistics.median(steady),
                remesh=statistics.median(remesh),
                cells=flow.nCells(),
                package=__import__("pfv").__file__,
            )
        )
    )


def driver(argv):
    builds = option(argv, "builds", "").split(",")
    if len(builds) != 2:
        sys.exit("--builds=OLD,NEW: two PYTHONPATHs")
    rounds = int(option(argv, "rounds", "3"))
    threads = option(argv, "threads", "1")
    passed = [a for a in argv if not a.startswith(("--builds=", "--rounds=", "--threads="))]
    if option(argv, "scene", "permeameter") == "lattice":
        launcher = ["/usr/bin/python3"]
    else:
        launcher = ["yade-double", "-j" + threads, "-n", "-x"]
    results = {b: [] for b in builds}
    for r in range(rounds):
        for b in builds if r % 2 == 0 else builds[::-1]:
            # The build's pfv first; pfv_testing from where this driver found it (an old build may lack it).
            env = dict(
                os.environ, PYTHONPATH=b + os.pathsep + SHARED, OMP_NUM_THREADS=threads, OPENBLAS_NUM_THREADS=threads
            )
            out = subprocess.run(
                launcher + [os.path.abspath(__file__), "--child"] + passed, env=env, capture_output=True, text=True
            )
            line = [x for x in out.stdout.splitlines() if x.startswith("RESULT ")]
            if out.returncode != 0 or not line:
                sys.exit(f"child failed for {b}:\n{out.stdout[-2000:]}\n{out.stderr[-2000:]}")
            res = json.loads(line[-1][len("RESULT ") :])
            results[b].append(res)
            solve = f" (solve {res['solve'] * 1e3:.2f} ms)" if "solve" in res else ""
            print(
                f"round {r + 1} {b}: first {res.get('first', float('nan')):.3f} s, steady {res['steady'] * 1e3:.2f} ms"
                f"{solve}, remesh {res['remesh']:.3f} s "
                f"({res['cells']} cells, {res['package']})",
                flush=True,
            )
    keys = [k for k in ("first", "steady", "solve", "remesh") if k in results[builds[0]][0]]
    med = {b: {k: statistics.median(x[k] for x in results[b]) for k in keys} for b in builds}
    for b in builds:
        print(f"{b}: " + ", ".join(f"{k} {med[b][k]:.4f} s" for k in keys))
    old, new = builds
    for k in keys:  # per round too: the rounds' spread shows how far the machine drifted
        per_round = ", ".join(f"{y[k] / x[k]:.2f}" for x, y in zip(results[old], results[new]))
        print(f"ratio second/first, {k}: {med[new][k] / med[old][k]:.3f} (per round {per_round})")


if "--child" in sys.argv:
    child(sys.argv)
else:
    driver(sys.argv[1:])
