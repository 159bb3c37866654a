"""Ordinary edit sequences leave the scene usable: every setting changed after every kind of scene
change, then the simulation runs on with conserved fluxes; a new viscosity applies at once.

    yade-double -n -x tests/yade/robustness/test_robustness_edits.py        (exit 0 = pass)

State derived at the wrong moment (a stability limit computed on a mesh about to be rebuilt, for
spheres it no longer holds) used to make every later step fail after, say, boundaryUseMaxMin or
an erased sphere followed by a viscosity change. The settings are those of
tests/data/settings_invalidation.csv, each with the value given there.
"""
import ast
import math
import warnings

from pfv_testing import robustness as rb
from pfv_testing import settings_table
from yade import O, utils  # noqa: E402

warnings.simplefilter("ignore")  # time-step and hidden-sphere warnings are not what is tested here


def settings():
    for row in settings_table.rows():
        if row["yade"] == "-":
            continue
        text = row["value"] if row["yade_value"] == "=" else row["yade_value"]
        yield row["yade"], ast.literal_eval(text)


def erase_sphere(flow):
    O.bodies.erase(50)


def append_sphere(flow):
    O.bodies.append(utils.sphere((0.5, 0.5, 0.5), 0.004, material="spheres"))
    O.bodies[len(O.bodies) - 1].state.blockedDOFs = "xyzXYZ"


def use_max_min(flow):
    flow.boundaryUseMaxMin = [True] * 6


def change_wall_ids(flow):
    # The same boxes, listed again after a detour through boundaryUseMaxMin on one side.
    flow.boundaryUseMaxMin = [False, False, False, False, True, False]
    flow.wallIds = [0, 1, 2, 3, 5, 5]


def shear_on(flow):
    flow.viscousShear = True


def move_wall(flow):
    wall = O.bodies[3]
    wall.state.pos = (wall.state.pos[0], wall.state.pos[1] + 0.01, wall.state.pos[2])


def change_dt(flow):
    O.dt = 0.5 * O.dt


SCENE_CHANGES = [erase_sphere, append_sphere, use_max_min, change_wall_ids, shear_on, move_wall, change_dt]

combinations = 0
for change in SCENE_CHANGES:
    for name, value in settings():
        flow = rb.fresh()
        try:
            rb.run(2)
            change(flow)
            settings_table.change(flow, name, value)
            rb.run(3)
            # The iterative solvers stop at a residual of 1e-6 relative to the right-hand side,
            # whose couplings to the pressure walls exceed the net flux by orders of magnitude.
            iterative = flow.useSolver != 3
            ok, figures = rb.conserved(flow, tol=1e-3 if iterative else 1e-8)
            if name == "imposePressure" or flow.fluidBulkModulus > 0:
                ok = all(map(math.isfinite, figures))
            if not ok:
                rb.fail(f"{change.__name__} then {name} = {value!r}: fluxes not conserved {figures}")
        except Exception as error:  # noqa: BLE001
            rb.fail(
                f"{change.__name__} then {name} = {value!r}: {type(error).__name__}: " f"{str(error).splitlines()[-1]}"
            )
        combinations += 1
rb.check("scene changes x setting changes run on", not rb.failures, f"({combinations} sequences)")

# A new viscosity applies at the next step, for every solver, without a new triangulation.
for solver in (3, 1, 0):
    flow = rb.fresh(useSolver=solver, tolerance=1e-12)
    rb.run(2)
    q0, meshes = flow.getBoundaryFlux(2), flow.core.remesh_count
    flow.viscosity = 2.0
    rb.run(1)
    ratio = flow.getBoundaryFlux(2) / q0
    rb.check(
        f"useSolver={solver}: doubled viscosity halves the flux at once",
        abs(ratio - 0.5) < 1e-6,
        f"(ratio {ratio:.9f})",
    )
    rb.check(f"useSolver={solver}: no remesh for a viscosity change", flow.core.remesh_count == meshes)

rb.report("edit-sequence")
