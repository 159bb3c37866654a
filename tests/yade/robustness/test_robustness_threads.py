"""Queries while O.run steps on YADE's own thread never crash, and engines leave no memory behind.

    yade-double -n -x tests/yade/robustness/test_robustness_threads.py        (exit 0 = pass)

O.run() without waiting runs the iterations on a thread of YADE's; a script's queries then come
from the main thread while a step may be rebuilding the mesh (which used to segfault in the
point location). Each query must wait for the step in progress and answer for a whole step.
"""
import gc
import math
import warnings

from pfv_testing import robustness as rb
from yade import O  # noqa: E402
from pfv import FlowEngine  # noqa: E402
from pfv._time_step import HISTORY_LENGTH  # noqa: E402

warnings.simplefilter("ignore")


def resident_kb():
    """The process's resident size now (VmRSS, kB): the peak would also count passing spikes."""
    with open("/proc/self/status") as f:
        return next(int(line.split()[1]) for line in f if line.startswith("VmRSS:"))


# 1. Queries from the main thread during O.run(300), remeshing every 5 steps.
flow = rb.fresh(meshUpdateInterval=5)
rb.run(1)
queries, errors = 0, []
O.run(300)
while O.running or queries == 0:
    try:
        p = flow.getPorePressure((0.5, 0.5, 0.5))
        v = flow.getCellVolume((0.3, 0.6, 0.4))
        s = flow.averageSlicePressure(0.5)
        dt = flow.critical_time_step
        f = flow.fluidForce(100)
        q = flow.getBoundaryFlux(2)
        queries += 1
        if not all(math.isfinite(x) for x in (p, v, s, q, f[0])) or not dt > 0:
            errors.append(f"non-finite answer p={p} v={v} slice={s} q={q} dt={dt}")
    except Exception as error:  # noqa: BLE001
        errors.append(f"{type(error).__name__}: {error}")
O.wait()
rb.check(
    "queries during O.run answered",
    not errors and queries > 10,
    f"({queries} rounds of 6 queries, {flow.core.remesh_count} remeshes; errors: {errors[:3]})",
)
p_mid = flow.getPorePressure((0.5, 0.5, 0.5))
rb.check("pressure after the run is the linear profile's", 0.3 < p_mid < 0.7, f"(p = {p_mid:.4f})")

# 2. An engine taken out of O.engines leaves no memory behind, O.engines swapped 300 times. YADE
# keeps a reference to every engine ever put into O.engines (a plain PyRunner too), so the Python
# objects stay; their meshes and factors must not.
base = [e for e in O.engines if not isinstance(e, FlowEngine)]
engines = []
for k in range(300):
    engine = FlowEngine()
    rb.scenes.configure_flow(engine, axis=1, dp=1.0)
    O.engines = base[:-1] + [engine] + base[-1:]
    rb.run(1)  # a mesh and a factor, freed once the engine is out of use
    O.engines = base
    engines.append(engine)
    if k == 20:
        gc.collect()
        rss_20 = resident_kb()
gc.collect()
holding = sum(e.core.has_mesh() for e in engines)
rb.check(
    "engines out of O.engines hold no mesh once another steps", holding <= 1, f"({holding} of {len(engines)} hold one)"
)
rss_300 = resident_kb()
# Each engine's mesh and factor take about 8 MB here (kept, 280 swaps would grow by 2 GB); the Python
# objects YADE keeps are a few kB each.
rb.check(
    "memory flat over 280 engine swaps",
    rss_300 - rss_20 < 50 * 1024,
    f"({(rss_300 - rss_20) / 1024:.1f} MB growth of the resident size)",
)
del engines

# 3. The record of the collective limit stays bounded over a long run of remeshes.
flow = rb.fresh(meshUpdateInterval=1)
rb.run(HISTORY_LENGTH + 50)
history = flow.collective_viscous_history
rb.check(
    "collective-limit history bounded",
    len(history) == HISTORY_LENGTH,
    f"({len(history)} entries after {flow.core.remesh_count} remeshes)",
)
rb.check("history holds the latest computations", history[-1]["remesh_count"] == flow.core.remesh_count)

rb.report("thread and memory")
