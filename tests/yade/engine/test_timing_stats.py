"""YADE's timing report shows pfv.FlowEngine's stages, as it shows YADE's FlowEngine checkpoints.

    yade-double -n -x tests/yade/engine/test_timing_stats.py        (exit 0 = pass)
"""
import contextlib
import io

from pfv_testing import robustness as rb
from yade import O, timing  # noqa: E402

flow = rb.fresh(meshUpdateInterval=5)
rb.run(3)
rb.check("nothing recorded while O.timingEnabled is off", flow.timingDeltas.data == [])
O.timingEnabled = True
timing.reset()
remeshes = flow.core.remesh_count
rb.run(20)
remeshes = flow.core.remesh_count - remeshes
data = {label: (ns, count) for label, ns, count in flow.timingDeltas.data}
out = io.StringIO()
with contextlib.redirect_stdout(out):
    timing.stats()
report = out.getvalue()
rb.check(
    "timing.stats() lists the stages under the engine",
    all(
        label in report
        for label in ("solve", "dV/dt", "remesh: triangulation", "system: factorization", "forces to YADE")
    ),
)
rb.check("every step counts once in the per-step stages", data["solve"][1] == 20 and data["forces to YADE"][1] == 20)
rb.check(
    "the remesh stages count the remeshes",
    data["remesh: triangulation"][1] == remeshes == 4,
    f"({data['remesh: triangulation'][1]} vs {remeshes})",
)
total = sum(ns for ns, _ in data.values())
rb.check(
    "the stages add up to no more than the engine's time",
    0 < total <= flow.execTime,
    f"({total / 1e6:.1f} ms of {flow.execTime / 1e6:.1f} ms)",
)
timing.reset()
rb.check("timing.reset() clears them", flow.timingDeltas.data == [])
rb.report("timing")
