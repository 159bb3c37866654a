"""The flow step's two-thread speed-up against the DEM step's, both measured in one process, interleaved.

    yade-double -j2 -n -x bench/thread_gain.py [--n=2e5] [--motion=drift|compression] [--kinds=pfv,pfv-multigrid]
                [--rounds=6] [--stages] [--json=FILE]

bench/growth.py times one and two threads in separate children; on this virtual machine, whose speed drifts by up
to 2x between processes, the two children's DEM steps do not see the same machine, and a comparison of the flow
step's gain with the DEM step's across them carries that drift. Here one `yade -j2` process runs both: OpenMP's
thread count belongs to the thread that steps the scene, so `pfv.set_num_threads(t)` before O.step() sets it for
YADE's DEM engines (YADE sized its per-thread buffers for -j2: fewer threads are safe), and the flow engine's
ompThreads = t for its own loops.

Scene and engines: those of bench/growth.py (pfv_testing.lattice_scene: the jittered lattice permeameter, its
kinematic motion, YADE's default remesh rule meshUpdateInterval=1000, defTolerance=0). Per engine: three first steps,
then --rounds rounds; a round times one thread and two threads in turn, the order alternating from round to round.
At each thread count: a block of 3 dry steps (the engine taken out, the spheres held still), 8 untimed coupled steps
(the engine's dV/dt history and multigrid's start rebuilt after the gap), 3 coupled steps and 3 more dry ones. The
flow step is the median coupled step minus the mean of the two dry blocks' medians, the DEM step that mean.

Per round, the flow step's gain (one thread over two) and the DEM step's, measured within seconds of each other,
and their ratio; printed: the medians over the rounds and their ranges, and the core's stages (Engine.step_times)
at each thread count. --stages also turns on O.timingEnabled and prints the engine's timing stages (those of YADE's
timing.stats(): the exchange with YADE and the Python around the core included) per coupled step at each count.
The target of doc/scaling.md is a ratio of at least 1: the flow step gains at least what YADE's DEM step gains. No
time is asserted anywhere.
"""
import json
import statistics
import sys

from pfv_testing.cli import option
from pfv_testing.lattice_scene import MOTIONS, build_scene, dry_steps, insert, make_flow, remove_flows
from pfv_testing.timing import yade_step

BLOCK, WARM, FIRST = 3, 8, 3
STAGES = ("volumes", "solve", "forces", "total")


def set_threads(flow, threads):
    import pfv

    pfv.set_num_threads(threads)
    flow.ompThreads = threads


def block(flow, motion, threads):
    """One block at `threads`: (flow step, DEM step) in seconds and the core's stages of the coupled steps."""
    set_threads(flow, threads)
    before = statistics.median(dry_steps(flow, motion, BLOCK))
    for _ in range(WARM):
        yade_step()
    coupled, stages = [], []
    if hasattr(flow, "timingDeltas"):
        flow.timingDeltas.reset()
    for _ in range(BLOCK):
        coupled.append(yade_step())
        if hasattr(flow, "core"):
            stages.append(dict(flow.core.step_times()))
    laps = {}
    if hasattr(flow, "timingDeltas"):
        laps = {label: ns * 1e-9 / BLOCK for label, ns, _ in flow.timingDeltas.data}
    after = statistics.median(dry_steps(flow, motion, BLOCK))
    dem = 0.5 * (before + after)
    return statistics.median(coupled) - dem, dem, stages, laps


def trial(kind, motion, rounds):
    flow = make_flow(kind)
    flow.meshUpdateInterval = 1000
    flow.defTolerance = 0.0
    insert(flow)
    set_threads(flow, 2)
    for _ in range(FIRST):
        yade_step()
    out = {t: dict(flow=[], dem=[], stages=[], laps=[]) for t in (1, 2)}
    for r in range(rounds):
        for threads in (1, 2) if r % 2 == 0 else (2, 1):
            f, d, stages, laps = block(flow, motion, threads)
            out[threads]["flow"].append(f)
            out[threads]["dem"].append(d)
            out[threads]["stages"] += stages
            out[threads]["laps"].append(laps)
    rec = dict(
        kind=kind,
        rounds=[
            dict(flow1=out[1]["flow"][r], flow2=out[2]["flow"][r], dem1=out[1]["dem"][r], dem2=out[2]["dem"][r])
            for r in range(rounds)
        ],
    )
    rec["stages"] = {
        t: {s: statistics.median(st[s] for st in out[t]["stages"]) for s in STAGES} for t in (1, 2) if out[t]["stages"]
    }
    rec["laps"] = {
        t: {k: statistics.median(lp.get(k, 0.0) for lp in out[t]["laps"]) for k in out[t]["laps"][0]}
        for t in (1, 2)
        if out[t]["laps"] and out[t]["laps"][0]
    }
    if hasattr(flow, "core"):
        rec["solver"] = flow.core.solver_choice
        rec["cg_iterations"] = flow.core.cg_iterations
        rec["unscheduled_remeshes"] = flow.core.inversion_remeshes
    del flow
    remove_flows()
    return rec


def report(rec):
    med = statistics.median
    rounds = rec["rounds"]
    flow_gain = [r["flow1"] / r["flow2"] for r in rounds]
    dem_gain = [r["dem1"] / r["dem2"] for r in rounds]
    ratio = [f / d for f, d in zip(flow_gain, dem_gain)]
    print(f"thread_gain: {rec['kind']}" + (f" ({rec['solver']})" if "solver" in rec else ""))
    for name, one, two in (("flow step", "flow1", "flow2"), ("DEM step", "dem1", "dem2")):
        print(
            f"  {name:10s} 1 thread {1e3 * med(r[one] for r in rounds):8.1f} ms, "
            f"2 threads {1e3 * med(r[two] for r in rounds):8.1f} ms"
        )
    for name, xs in (("flow gain", flow_gain), ("DEM gain", dem_gain), ("flow / DEM", ratio)):
        print(f"  {name:10s} median {med(xs):.2f} (rounds {min(xs):.2f}-{max(xs):.2f})")
    for t, st in rec.get("stages", {}).items():
        print(f"  core at {t} thread(s): " + ", ".join(f"{s} {1e3 * v:.1f} ms" for s, v in st.items()))
    for t, laps in rec.get("laps", {}).items():
        print(
            f"  timing stages at {t} thread(s), per step: "
            + ", ".join(f"{k} {1e3 * v:.2f} ms" for k, v in laps.items())
        )


def main(argv):
    from yade import O

    n = int(float(option(argv, "n", "2e5")))
    motion_name = option(argv, "motion", "drift")
    if motion_name not in MOTIONS or motion_name == "static":
        raise SystemExit("thread_gain.py: --motion must be drift or compression")
    if O.numThreads < 2:
        raise SystemExit("thread_gain.py: run it under yade -j2 (O.numThreads is %d)" % O.numThreads)
    kinds = option(argv, "kinds", "pfv,pfv-multigrid").split(",")
    rounds = int(option(argv, "rounds", "6"))
    motion = build_scene(n, motion_name)
    O.timingEnabled = bool(option(argv, "stages", False))
    data = dict(n=n, motion=motion_name, trials=[])
    for kind in kinds:
        rec = trial(kind, motion, rounds)
        data["trials"].append(rec)
        report(rec)
    path = option(argv, "json", "")
    if path:
        with open(path, "w") as f:
            json.dump(data, f, indent=1)


main(sys.argv[1:])
