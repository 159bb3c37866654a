"""pfv.PeriodicFlowEngine in a YADE scene: one line switches from YADE's engine, and bad input fails loudly.

    yade-double -n -x tests/yade/flow/test_periodic_engine.py        (exit 0 = pass)

A simple cubic array of 4 x 4 x 4 spheres (radius 0.4995, jittered by 1e-4) in a periodic cell, gradP along y,
the engine written as YADE's: after two O.step() the forces YADE holds are the engine's, and both equal those of
the C++ step (pfv._core.PeriodicFlow) on the same positions; averageVelocity is its Darcy velocity; the pressure
at a point one period further along y is higher by gradP_y times the period. Then the errors: a periodic engine
in a walled scene, pfv.FlowEngine in a periodic one, a non-finite gradP, a wall member, a cell thinner than two
diameters, an unknown attribute; each names the problem and the scene runs on once it is put right.
"""
import numpy as np

from pfv_testing import checks
from pfv_testing.periodic_scene import RADIUS, build, cell_matrix, dem_engines
from yade import O  # noqa: E402
from yade.minieigenHP import Vector3  # noqa: E402
import pfv._core as core  # noqa: E402
from pfv import FlowEngine, PeriodicFlowEngine  # noqa: E402

SIDE = 4
GRADIENT = (0.0, 2.0, 0.0)


def scene(periodic=True, side=SIDE):
    build(side, jitter=1e-4, seed=7, periodic=periodic)


def engines(flow):
    O.engines = dem_engines(flow)


# The drop-in: YADE's script with the engine's import changed.
scene()
flow = PeriodicFlowEngine(gradP=Vector3(*GRADIENT), viscosity=1.0, useSolver=3, label="flow")
engines(flow)
O.step()
O.step()
n = len(O.bodies)
centres = np.array([tuple(O.bodies[i].state.pos) for i in range(n)])
h = cell_matrix()
direct = core.PeriodicFlow()
direct.set_settings(viscosity=1.0, permeability_factor=1.0, gradient=GRADIENT, bulk_modulus=0.0)
direct.step(centres, np.full(n, RADIUS), h, O.dt)
held = np.array([tuple(O.forces.f(i)) for i in range(n)])
reported = np.array([tuple(flow.fluidForce(i)) for i in range(n)])
scale = np.abs(direct.forces()).max()
checks.check("O.forces holds the engine's forces", np.abs(held - reported).max() <= 1e-12 * scale)
checks.check("the engine's forces are the C++ step's", np.abs(reported - direct.forces()).max() <= 1e-12 * scale)
velocity = np.array(tuple(flow.averageVelocity()))
checks.check(
    "averageVelocity is the Darcy velocity of the C++ step",
    np.abs(velocity - direct.mean_velocity()).max() <= 1e-12 * np.abs(velocity).max(),
    f"{velocity}",
)
checks.check("the flow goes down the gradient", velocity[1] < 0, f"{velocity}")
x = (1.3, 0.7, 2.1)
rise = flow.getPorePressure((x[0], x[1] + SIDE, x[2])) - flow.getPorePressure(x)
checks.check("one period further along y the pressure is gradP_y L higher", abs(rise - 2.0 * SIDE) < 1e-9, f"{rise}")
checks.check("no remesh between the two steps", direct.remesh_count == 1 and flow.nCells() == direct.n_cells)
checks.check("the centres come from YADE's SpherePack (checked against its Python interface)", flow._pack is not None)

# Errors.
checks.expect_error("gradP = (nan, 0, 0)", ValueError, "gradP", lambda: setattr(flow, "gradP", (float("nan"), 0, 0)))
checks.expect_error("viscosity = 0", ValueError, "viscosity", lambda: setattr(flow, "viscosity", 0))
checks.expect_error("wallIds", AttributeError, "wallIds", lambda: setattr(flow, "wallIds", [0, 1, 2, 3, 4, 5]))
checks.expect_error("bndCondIsPressure read", AttributeError, "bndCondIsPressure", lambda: flow.bndCondIsPressure)
checks.expect_error("an unknown attribute", AttributeError, "gradp", lambda: setattr(flow, "gradp", (0, 1, 0)))
checks.expect_error("useSolver = 2", ValueError, "useSolver", lambda: setattr(flow, "useSolver", 2))
checks.check("the rejected settings left gradP as it was", tuple(flow.gradP) == GRADIENT, f"{flow.gradP}")
O.step()
checks.check(
    "the engine steps on after the refusals",
    np.abs(np.array(tuple(flow.averageVelocity())) - velocity).max() <= 1e-12 * np.abs(velocity).max(),
)

# Undrained: a compressible fluid, the cell compressed between two steps (hSize and the spheres moved together):
# the pressure rises by K dV / V_f (volume-weighted, V_f the pores' fluid volume). After a gap in the iterations
# (the engine dead meanwhile) the motion is unknown, and the step after it adds none.
flow.gradP = (0, 0, 0)
flow.fluidBulkModulus = 1e5
O.step()
before = flow._core.periodic_pressure()
fluid = flow._core.fluid_volumes()
strain = 1e-5
old_h = cell_matrix()
O.cell.hSize = O.cell.hSize * (1 - strain)
for i in range(n):
    if O.bodies[i] is not None:
        O.bodies[i].state.pos = O.bodies[i].state.pos * (1 - strain)
O.step()
rise = float(np.dot(fluid, flow._core.periodic_pressure() - before) / fluid.sum())
expected = -1e5 * (np.linalg.det(old_h) * ((1 - strain) ** 3 - 1)) / fluid.sum()
checks.check(
    "undrained compression: the pressure rises by K dV / V_f", abs(rise / expected - 1) < 1e-6, f"{rise} vs {expected}"
)
flow.dead = True
O.step()
O.cell.hSize = O.cell.hSize * (1 - strain)  # compressed again while the engine does not run
for i in range(n):
    O.bodies[i].state.pos = O.bodies[i].state.pos * (1 - strain)
O.step()
flow.dead = False
held = float(np.dot(fluid, flow._core.periodic_pressure()) / fluid.sum())
O.step()
change = float(np.dot(fluid, flow._core.periodic_pressure()) / fluid.sum()) - held
checks.check(
    "after a gap the step counts no motion it did not see (the mean pressure stays)",
    abs(change) <= 1e-9 * abs(expected),
    f"{change} (counting it would add about {expected})",
)

# An erased sphere (len(O.bodies) unchanged): the engine rescans and remeshes without it.
flow.fluidBulkModulus = 0
flow.gradP = GRADIENT
centres = np.array([tuple(O.bodies[i].state.pos) for i in range(n)])
h = cell_matrix()
O.step()
cells = flow.nCells()
O.bodies.erase(5)
O.step()
rest = [i for i in range(n) if i != 5]
again = core.PeriodicFlow()
again.set_settings(viscosity=1.0, permeability_factor=1.0, gradient=GRADIENT, bulk_modulus=0.0)
again.step(centres[rest], np.full(n - 1, RADIUS), h, O.dt)
checks.check("after erasing a sphere: its pores are gone", flow.nCells() == again.n_cells and flow.nCells() != cells)
checks.check(
    "after erasing a sphere: the forces of a fresh step without it",
    np.abs(np.array([tuple(flow.fluidForce(i)) for i in rest]) - again.forces()).max() <= 1e-12 * scale,
)
checks.expect_error("fluidForce of the erased sphere", IndexError, "5", lambda: flow.fluidForce(5))

scene(periodic=False)
engines(PeriodicFlowEngine(gradP=Vector3(*GRADIENT)))
checks.expect_error("PeriodicFlowEngine in a walled scene", Exception, "O.periodic", O.step)

scene()
walled = FlowEngine()
engines(walled)
checks.expect_error("pfv.FlowEngine in a periodic scene", Exception, "PeriodicFlowEngine", O.step)

scene(side=1)
engines(PeriodicFlowEngine(gradP=Vector3(*GRADIENT)))
checks.expect_error("a cell one sphere thick", Exception, "diameters", O.step)
checks.report("periodic_engine")
