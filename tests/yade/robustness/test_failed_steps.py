"""A step that fails, wherever it fails, leaves the engine as the last successful step left it, and the
engine runs on once the cause is gone (doc/yade.md, "After an exception").

    yade-double -n -x tests/yade/robustness/test_failed_steps.py        (exit 0 = pass)

Every way a step can fail (FAILURES: before the core, in its remesh, in the mesh hook, in the linear
system, in the boundary load, in the solve's results, in the time-step guard after a new mesh, in the
forces handed to YADE) in every kind of step (STEPS: a step on the current mesh, a remesh because a
body was erased, one the schedule asked for, one a setting asked for), with the remesh in the
foreground and in the background (multithread). After the failed step the queries must answer what
they answered before it; after the cause is removed, the engine must step and give what an engine
that never failed gives on the same scene (frozen spheres: the same mesh, the same pressures).

On an engine that kept a failed step's remesh, the queries answered 0 and every later step raised
"the stability limit needs a mesh".
"""
import math
import warnings

from pfv import FlowEngine
from pfv_testing import scenes
from pfv_testing.robustness import check, finish_iteration, report, run
from yade import O

warnings.simplefilter("ignore")  # time-step and hidden-sphere warnings are not what is tested here

PROBES = scenes.probe_points(n=2)
WATCHED_BODIES = (6, 40, 200)  # spheres (walls are 0..5); 7 is the one the "erased" steps erase
ERASED = 7
INTERVAL = 3  # meshUpdateInterval: the 4th step is a scheduled remesh (adopted a step or more later in the background)
ATTEMPTS = 4  # steps armed until one fails: a background remesh fails when a later step adopts it


class Arm:
    """A failure that strikes when armed, once."""

    def __init__(self):
        self.armed = False

    def strike(self):
        if self.armed:
            self.armed = False
            raise RuntimeError("injected failure")


arm = Arm()


def block_hook():  # blockHook: the failure inside the mesh hook, on every new mesh
    arm.strike()


def boundary_load(x, y, z, t):  # the outlet's pressure (0, as bndCondValue), evaluated in the core's step
    arm.strike()
    return 0.0


# -- the failures: (name, arm(flow), disarm(flow), steps it applies to) -------------------------
def nan_position(flow, on):
    b = O.bodies[60]
    if on:
        nan_position.saved = b.state.pos
        b.state.pos = (math.nan, 0.5, 0.5)
    else:
        b.state.pos = nan_position.saved


def onto_neighbour(flow, on):  # a centre inside another sphere: refused by the remesh
    b = O.bodies[60]
    if on:
        onto_neighbour.saved = b.state.pos
        b.state.pos = O.bodies[61].state.pos
    else:
        b.state.pos = onto_neighbour.saved


def hook_raises(flow, on):
    arm.armed = on


def load_raises(flow, on):
    # The load (0, as bndCondValue[3]: the results do not change) is set for this failure alone.
    if on:
        flow.set_boundary_pressure(3, boundary_load)
    arm.armed = on


def singular_system(flow, on):  # no pressure boundary: refused when the system is built
    flow.bndCondIsPressure = [False] * 6 if on else [False, False, True, True, False, False]


def non_finite_force(flow, on):  # buoyancy of an absurd density: refused before the commit
    flow.fluid_density = 1e308 if on else 0.0


def time_step_refused(flow, on):  # strict guard: refused on the new mesh, after the core's step
    flow.strict_time_step = on
    O.dt = 1e3 if on else 1e-5


def forces_refused(flow, on):  # the caller's part after the core's step: the forces to YADE
    if on:

        def refuse(*args):
            raise RuntimeError("injected failure handing the forces to YADE")

        flow.__dict__["_apply_forces"] = refuse  # past the engine's check of attribute names
    else:
        del flow.__dict__["_apply_forces"]


ALL_STEPS = ("same mesh", "erased body", "scheduled remesh", "requested remesh")
REMESHING = ALL_STEPS[1:]
FAILURES = (
    ("NaN position", nan_position, ALL_STEPS),
    ("centre inside a neighbour", onto_neighbour, REMESHING),
    ("blockHook raises", hook_raises, REMESHING),
    ("boundary load raises", load_raises, ALL_STEPS),
    ("singular system", singular_system, ALL_STEPS),
    ("non-finite force", non_finite_force, ALL_STEPS),
    ("time step refused on the new mesh", time_step_refused, REMESHING),
    ("forces to YADE refused", forces_refused, ALL_STEPS),
)


def prepare_step(flow, kind):
    """What makes the next step the kind asked for."""
    if kind == "erased body":
        O.bodies.erase(ERASED)
    elif kind == "requested remesh":
        flow.updateTriangulation = True


def engine(background):
    scenes.build_permeameter(num=300, frozen=True)
    O.engines[-1].gravity = (0, 0, -9.81)  # NewtonIntegrator: buoyancy has a weight to act on
    flow = FlowEngine(label="flow", multithread=background, meshUpdateInterval=INTERVAL)
    scenes.configure_flow(flow, axis=1, dp=1.0)
    flow.blockHook = "block_hook()"  # run in __main__: this script
    scenes.insert_flow(flow)
    return flow


def state(flow):
    """What the queries answer: probe pressures, the outflow, forces, the mesh's size and counts."""
    forces = []
    for b in WATCHED_BODIES:
        forces.extend(flow.fluidForce(b))
    return dict(
        pressures=[flow.getPorePressure(p) for p in PROBES],
        flux=flow.getBoundaryFlux(3),
        forces=forces,
        cells=flow.nCells(),
        remeshes=flow.core.remesh_count,
    )


def same(a, b, rtol):
    def close(x, y):
        scale = max(abs(x), abs(y), 1e-30)
        return abs(x - y) <= rtol * scale or abs(x - y) < 1e-14

    for key in a:
        x, y = a[key], b[key]
        if isinstance(x, list):
            if len(x) != len(y) or not all(close(u, v) for u, v in zip(x, y)):
                return False, key
        elif not close(x, y):
            return False, key
    return True, ""


def reference(kind, background):
    """The state after the steps of a case, on an engine that never failed."""
    flow = engine(background)
    run(3)
    prepare_step(flow, kind)
    run(1)
    run(2)
    return state(flow)


def case(name, fault, kind, background, expected):
    label = f"{name}, {kind}, {'background' if background else 'serial'}"
    flow = engine(background)
    run(3)
    prepare_step(flow, kind)
    fault(flow, True)
    failed = False
    for attempt in range(ATTEMPTS):
        flow.core.wait_for_remesh()  # a background remesh in flight is adopted by the next step
        before = state(flow)
        try:
            O.run(1, True)
        except Exception:  # noqa: BLE001 (whatever the failure, the engine must be whole)
            failed = True
            break
    finish_iteration()  # YADE finishes the interrupted iteration (without the engine)
    fault(flow, False)
    arm.armed = False
    if not check(f"{label}: the step fails", failed):
        return
    ok, key = same(state(flow), before, 0.0)
    check(f"{label}: the queries answer the last successful step's results", ok, key)
    try:
        run(2)
        stepped = True
    except Exception as error:  # noqa: BLE001
        stepped = False
        check(f"{label}: the engine runs on", False, repr(error)[:200])
    if stepped:
        now = state(flow)
        now["remeshes"] = expected["remeshes"]  # when a background remesh is adopted depends on its thread's pace
        ok, key = same(now, expected, 1e-9)
        check(f"{label}: then gives what an engine that never failed gives", ok, key)


def main():
    cases = 0
    for background in (False, True):
        for kind in ALL_STEPS:
            expected = reference(kind, background)
            for name, fault, kinds in FAILURES:
                if kind in kinds:
                    case(name, fault, kind, background, expected)
                    cases += 1
    print(f"{cases} cases")
    report("failed-step")


main()
