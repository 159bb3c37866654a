"""The engine's ompThreads is its own: the engines after it in the step keep the caller's thread count.

    yade-double -n -x tests/yade/engine/test_thread_count.py        (exit 0 = pass)

OpenMP's thread count is a setting of the calling thread, and PFV's engine runs on the thread that runs YADE's
engines (the script's, under O.step(); YADE's own, under O.run()). An engine that set ompThreads and left it so
would change the threads of the DEM engines after it, and of every later step: a script at `yade -j4` whose flow
engine asked for one thread would run its whole DEM on one, and one at `yade -j1` whose flow engine asked for two
would run YADE's DEM on more threads than YADE sized its per-thread buffers for (which crashes: a DEM step at two
threads in a `-j1` process segfaults). Two PyRunners, one on either side of the flow engine, read the count each
step; they must agree, also when the engine's step fails. The test runs at `-j1` (ctest), so the engine asks for
more threads than the caller.
"""
from pfv_testing import checks, robustness as rb
from yade import O  # noqa: E402
from yade.wrapper import PyRunner  # noqa: E402
import pfv  # noqa: E402

seen = {"before": [], "after": []}


def record(where):
    seen[where].append(pfv.get_max_threads())


def around_flow(flow):
    engines = list(O.engines)
    i = engines.index(flow)
    O.engines = (
        engines[:i]
        + [PyRunner(command="record('before')", iterPeriod=1, initRun=True)]
        + [flow]
        + [PyRunner(command="record('after')", iterPeriod=1, initRun=True)]
        + engines[i + 1 :]
    )


caller = 1
for asked in (2, 3):
    flow = rb.fresh()
    around_flow(flow)
    flow.ompThreads = asked
    pfv.set_num_threads(caller)
    for k in range(3):
        seen = {"before": [], "after": []}
        if k < 2:
            O.step()  # on this thread
        else:
            O.run(1, True)  # on YADE's thread, which has its own count
        checks.check(
            f"caller at {caller}, ompThreads = {asked}, {'O.step' if k < 2 else 'O.run'}: the engines after the flow "
            "engine run at the caller's thread count",
            seen["before"] == seen["after"] and len(seen["after"]) == 1,
            f"before {seen['before']}, after {seen['after']}",
        )
    checks.check(
        f"caller at {caller}: this thread keeps its count across the steps",
        pfv.get_max_threads() == 1,
        f"{pfv.get_max_threads()}",
    )

# A step that fails (a sphere's centre made non-finite) gives back the caller's count too.
flow = rb.fresh()
flow.ompThreads = 2
pfv.set_num_threads(1)
O.step()
O.bodies[10].state.pos = (float("nan"), 0.5, 0.5)
try:
    O.step()
    checks.check("a step with a NaN centre fails", False)
except Exception:
    pass
checks.check(
    "after a failed step the caller's thread count is back", pfv.get_max_threads() == 1, f"{pfv.get_max_threads()}"
)
checks.report("thread_count")
