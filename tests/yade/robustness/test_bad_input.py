"""Bad input to pfv.FlowEngine fails loudly, names the problem and leaves the scene usable.

    yade-double -n -x tests/yade/robustness/test_bad_input.py        (exit 0 = pass)
"""
import math

from pfv_testing import scenes
from pfv_testing.robustness import expect_error, fail, fresh, report
from yade import O  # noqa: E402
from pfv import FlowEngine  # noqa: E402

# Attribute surface.
flow = fresh()
expect_error("unknown attribute", AttributeError, "viscosityy", lambda: setattr(flow, "viscosityy", 1.0))
expect_error("unknown constructor keyword", AttributeError, "pressureeForce", lambda: FlowEngine(pressureeForce=True))
expect_error(
    "YADE attribute not supported",
    NotImplementedError,
    "normalLubrication",
    lambda: setattr(flow, "normalLubrication", True),
)
flow.normalLubrication = False  # YADE's default is accepted
expect_error("YADE method out of scope", NotImplementedError, "getCavityFlux", lambda: flow.getCavityFlux())
expect_error("non-positive viscosity", ValueError, "viscosity", lambda: setattr(flow, "viscosity", -1.0))
expect_error("NaN viscosity", ValueError, "viscosity", lambda: setattr(flow, "viscosity", float("nan")))
expect_error("query before any step", RuntimeError, "not run yet", lambda: flow.getBoundaryFlux(2))
expect_error("unknown ordering", ValueError, "geometric", lambda: setattr(flow.core, "ordering", "geometrical"))

# A good step, to compare against after each recovered failure.
O.run(1, True)
q_ref = flow.getBoundaryFlux(2)
p_ref = flow.getPorePressure((0.5, 0.5, 0.5))

probe = scenes.build_permeameter  # noqa: F841  (scene already built)
sphere = O.bodies[50]
good = tuple(sphere.state.pos)  # a copy: state.pos is live


def run_step():
    flow.updateTriangulation = True
    try:
        O.run(1, True)
    finally:
        # An exception inside an engine leaves YADE's iteration half-done (O.subStep >= 0);
        # YADE's next run finishes it without re-running the failed engine. Finish it here so
        # that each check starts on a whole iteration.
        if O.subStep >= 0:
            O.run(1, True)


sphere.state.pos = (float("nan"), good[1], good[2])
expect_error("NaN position", RuntimeError, "non-finite position", run_step)
sphere.state.pos = (good[0], math.inf, good[2])
expect_error("infinite position", RuntimeError, "non-finite position", run_step)
sphere.state.pos = O.bodies[51].state.pos
expect_error("coincident centres", RuntimeError, "coincident centres", run_step)
other = O.bodies[51]
sphere.state.pos = tuple(other.state.pos + (0.3 * other.shape.radius, 0, 0))
expect_error("centre inside another sphere", RuntimeError, "inside the other sphere", run_step)
use_max_min = flow.boundaryUseMaxMin
flow.boundaryUseMaxMin = [False] * 6
sphere.state.pos = (good[0], 1.2, good[2])
expect_error("centre outside the walls", RuntimeError, "#50", run_step)
sphere.state.pos = good
flow.boundaryUseMaxMin = use_max_min

# The scene is still usable and gives the same answer as before the failures.
run_step()
if (
    abs(flow.getBoundaryFlux(2) - q_ref) > 1e-12 * abs(q_ref)
    or abs(flow.getPorePressure((0.5, 0.5, 0.5)) - p_ref) > 1e-12
):
    fail(
        f"results changed after recovering from bad input: Qin {flow.getBoundaryFlux(2)} vs {q_ref}, "
        f"p {flow.getPorePressure((0.5, 0.5, 0.5))} vs {p_ref}"
    )
else:
    print("ok   scene usable after failures, results unchanged")

# Boundary conditions that make the system singular, and a wall id that is no body.
flow.bndCondIsPressure = [False] * 6
expect_error("no pressure boundary", RuntimeError, "no boundary has an imposed pressure", run_step)
flow.bndCondIsPressure = [False, False, True, True, False, False]
flow.wallIds = [0, 1, 2, 3, 4, 99999]
flow.boundaryUseMaxMin = [False] * 6
expect_error("wall id that is not a body", RuntimeError, "99999", run_step)
flow.wallIds = list(range(6))
run_step()
print("ok   recovered after wall id fix, Qin =", flow.getBoundaryFlux(2))
expect_error("query outside the mesh", ValueError, "no pore cell", lambda: flow.getPorePressure((5, 5, 5)))
expect_error("fluidForce of a body that is not coupled", ValueError, "not coupled", lambda: flow.fluidForce(123456))

# Save/load: a restored runner whose scene carries no saved state (saved by YADE alone) says the
# engine must be re-created (with the state, tests/yade/engine/test_save_load.py, it goes on).
import yade  # noqa: E402

O.save("/tmp/pfv-bad-input.yade.gz")
yade.wrapper.Omega.load.__wrapped__(O, "/tmp/pfv-bad-input.yade.gz")  # YADE's own load
for key in O.tags.keys():
    if key.startswith("pfv.saved."):
        O.tags[key] = ""
del flow
import gc  # noqa: E402

gc.collect()
expect_error("engine after a load without saved state", RuntimeError, "re-create", lambda: O.run(1, True))
if O.subStep >= 0:
    O.engines = [e for e in O.engines if not type(e).__name__ == "PyRunner"]
    O.run(1, True)

# Periodic scenes are not supported yet.
flow = fresh()
O.engines = [flow]  # YADE's own collider asserts on these walls in a periodic cell
O.periodic = True
O.cell.setBox(1, 1, 1)
expect_error("periodic scene", RuntimeError, "periodic", run_step)

report("bad-input")
