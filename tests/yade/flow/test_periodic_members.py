"""pfv.PeriodicFlowEngine's members beyond the step: point conditions, cell queries, timing, VTK output, O.save/O.load.

    yade-double -n -x tests/yade/flow/test_periodic_members.py        (exit 0 = pass)

A jittered simple cubic array of 4 x 4 x 4 spheres in a periodic cell. Checked:
* imposePressure: getPorePressure at the point returns the value, in any period; with no gradient and static spheres
  every pore takes it; setImposedPressure moves it; imposeFlux with YADE's sign (outflow positive) lowers the
  pressure where the fluid leaves; clearImposed* undo them;
* getCellPressure is the pressure at each pore's power centre (p~ + gradP . x); averagePressure weighs them by the
  cells' volumes; bad ids raise;
* useSolver 0 (Gauss-Seidel), 1 (conjugate gradients) and solver="multigrid" to a tight tolerance give the Cholesky
  factor's pressures; unknown solvers and a relax outside (0, 2) raise;
* O.timingEnabled: timing.stats() lists the engine's stages (the stages' times are not checked);
* saveVtk: the files read back with VTK give one cell per pore, the engine's pressures and volumes; the pores' volumes
  add up to the cell's, and each sphere is written once, inside the cell;
* O.saveTmp/O.loadTmp and O.save/O.load to a file, with spheres and a sheared cell moving every step, a compressible
  fluid and a remesh in between: the run after the load equals the uninterrupted one bit for bit.
"""
import builtins
import os
import tempfile

import numpy as np

from pfv_testing import checks
from pfv_testing.periodic_scene import build, dem_engines
from yade import O, timing  # noqa: E402
from pfv import PeriodicFlowEngine  # noqa: E402

SIDE = 4


def new_scene(**settings):
    build(SIDE, jitter=1e-4, seed=11)
    flow = PeriodicFlowEngine(label="flow", **settings)
    O.engines = dem_engines(flow)
    return flow


# -- point conditions --------------------------------------------------------------------------------------------
flow = new_scene(viscosity=1.0)
point = (1.3 + SIDE, 0.7, 2.1 - SIDE)  # outside the base cell
index = flow.imposePressure(point, 40.0)
O.step()
pressures = np.array([flow.getCellPressure(c) for c in range(flow.nCells())])
checks.check("imposePressure: no gradient, static spheres: every pore at the imposed value", np.allclose(pressures, 40))
checks.check("imposePressure: getPorePressure at the point", abs(flow.getPorePressure(point) - 40.0) < 1e-12)
flow.setImposedPressure(index, -5.0)
O.step()
checks.check("setImposedPressure moves it", abs(flow.getPorePressure(point) + 5.0) < 1e-12)
flow.gradP = (0.0, 3.0, 0.0)
O.step()
checks.check("with a gradient the imposed point keeps its value", abs(flow.getPorePressure(point) + 5.0) < 1e-9)
shifted = flow.getPorePressure((point[0], point[1] + SIDE, point[2]))
checks.check("one period further along y, gradP_y L higher", abs(shifted - (-5.0 + 3.0 * SIDE)) < 1e-9, f"{shifted}")
flow.gradP = (0.0, 0.0, 0.0)
outlet = (2.5, 2.5, 2.5)
flow.imposeFlux(outlet, 1e-3)  # YADE's sign: positive leaves the pore
O.step()
checks.check(
    "imposeFlux: the fluid leaving lowers the pressure there",
    flow.getPorePressure(outlet) < flow.getPorePressure(point) - 1e-9,
    f"{flow.getPorePressure(outlet)} vs {flow.getPorePressure(point)}",
)
flow.clearImposedFlux()
flow.clearImposedPressure()
O.step()
checks.check(
    "cleared: the reference pore fixes p~ = 0 again",
    max(abs(flow.getCellPressure(c)) for c in range(flow.nCells())) < 1e-12,
)
checks.expect_error(
    "imposePressure at nan", ValueError, "imposePressure", lambda: flow.imposePressure((0, 0, 1e400), 1)
)
checks.expect_error(
    "setImposedPressure of no condition", IndexError, "setImposedPressure", lambda: flow.setImposedPressure(3, 1)
)
checks.expect_error("imposeFlux of a string", TypeError, "imposeFlux", lambda: flow.imposeFlux((1, 1, 1), "x"))

# -- cell queries ---------------------------------------------------------------------------------------------------
flow.gradP = (0.0, 2.0, 0.0)
O.step()
core = flow._core
p = core.pressure()
checks.check(
    "getCellPressure is the pressure of each pore",
    all(flow.getCellPressure(c) == p[c] for c in range(flow.nCells())),
)
volumes = core.cell_volumes()
checks.check(
    "averagePressure weighs the pores by their volumes",
    abs(flow.averagePressure() - np.dot(p, volumes) / volumes.sum()) < 1e-12 * np.abs(p).max(),
)
checks.expect_error("getCellPressure(-1)", IndexError, "getCellPressure", lambda: flow.getCellPressure(-1))
checks.expect_error(
    "getCellPressure(nCells)", IndexError, "getCellPressure", lambda: flow.getCellPressure(flow.nCells())
)

# -- solvers ----------------------------------------------------------------------------------------------------
# Each solver starts from the pressures of another gradient and must reach the factor's pressures of this one.
flow.fluidBulkModulus = 0
flow.gradP = (0.0, 1.0, 3.0)
O.step()
direct = core.pressure().copy()
for code, name in ((0, "gauss_seidel"), (1, "conjugate_gradient"), (None, "multigrid"), (3, "cholesky")):
    flow.gradP = (2.0, 0.0, 0.0)
    O.step()
    if code is None:
        flow.solver = name
    else:
        flow.useSolver = code
    flow.tolerance = 1e-12
    flow.gradP = (0.0, 1.0, 3.0)
    O.step()
    spread = direct.max() - direct.min()
    error = np.abs(core.pressure() - direct).max() / spread
    checks.check(
        f"{name} (useSolver {flow.useSolver}): the factor's pressures", error < 1e-8, f"{error:.2g} of the spread"
    )
checks.expect_error("useSolver = 2", ValueError, "useSolver", lambda: setattr(flow, "useSolver", 2))
checks.expect_error("solver = 'lu'", ValueError, "solver", lambda: setattr(flow, "solver", "lu"))
checks.expect_error("relax = 2", ValueError, "relax", lambda: setattr(flow, "relax", 2.0))
checks.check("the refused settings left the solver as it was", flow.solver == "cholesky" and flow.relax == 1.9)

# -- timing -----------------------------------------------------------------------------------------------------
O.timingEnabled = True
flow.updateTriangulation = True
O.step()
O.step()
labels = [label for label, _, _ in flow.timingDeltas.data]
for stage in ("positions", "remesh: triangulation", "system: factorization", "dV/dt", "solve", "forces"):
    checks.check(f"timing lists the stage '{stage}'", stage in labels, f"{labels}")
counts = dict((label, count) for label, _, count in flow.timingDeltas.data)
checks.check("one remesh in two steps, two solves", counts.get("remesh: triangulation") == 1 and counts["solve"] == 2)
timing.stats()  # YADE's report reads the engine's stages
O.timingEnabled = False

# -- VTK ------------------------------------------------------------------------------------------------------
from vtkmodules.util.numpy_support import vtk_to_numpy  # noqa: E402
from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader  # noqa: E402


def read(path):
    reader = vtkXMLUnstructuredGridReader()
    reader.SetFileName(path)
    reader.Update()
    return reader.GetOutput()


folder = tempfile.mkdtemp(prefix="pfv-periodic-vtk-")
flow.saveVtk(folder)
pores, spheres = read(os.path.join(folder, "out_0.vtu")), read(os.path.join(folder, "spheres_0.vtu"))
checks.check("saveVtk: one VTK cell per pore", pores.GetNumberOfCells() == flow.nCells())
written = vtk_to_numpy(pores.GetCellData().GetArray("Pressure"))
checks.check("saveVtk: the engine's pressures", np.array_equal(written, core.pressure()))
tet_volumes = []
points = vtk_to_numpy(pores.GetPoints().GetData())
for c in range(pores.GetNumberOfCells()):
    ids = [pores.GetCell(c).GetPointId(k) for k in range(4)]
    a, b, d, e = points[ids]
    tet_volumes.append(abs(np.dot(b - a, np.cross(d - a, e - a))) / 6)
checks.check(
    "saveVtk: the written pores fill one period (their volumes add up to the cell's)",
    abs(sum(tet_volumes) - SIDE**3) < 1e-9 * SIDE**3,
    f"{sum(tet_volumes)}",
)
centres = vtk_to_numpy(spheres.GetPoints().GetData())
checks.check(
    "saveVtk: each sphere once, inside the cell",
    spheres.GetNumberOfPoints() == len(O.bodies) and centres.min() >= 0 and centres.max() < SIDE,
)
checks.check("saveVtk: the collection", os.path.exists(os.path.join(folder, "out.pvd")))


# -- O.save / O.load ------------------------------------------------------------------------------------------------
def moving_scene():
    flow = new_scene(viscosity=1.0, gradP=(0.5, 1.0, 0.0), fluidBulkModulus=1e4, meshUpdateInterval=4)
    flow.imposeFlux((1.5, 1.5, 1.5), -1e-4)
    return flow


def move(step):
    """Every sphere along its own direction, the cell sheared: dV/dt in every pore."""
    rng = np.random.default_rng(step)
    for b in O.bodies:
        b.state.pos = b.state.pos + tuple(2e-4 * rng.uniform(-1, 1, 3))
    h = O.cell.hSize
    h[0, 1] += 1e-4
    O.cell.hSize = h


def run(steps, first):
    out = []
    for k in range(steps):
        move(first + k)
        O.step()
        flow = builtins.flow
        out.append(
            np.concatenate([np.ravel([tuple(flow.fluidForce(i)) for i in range(len(O.bodies))]), flow._core.pressure()])
        )
    return out


def same(a, b):
    return len(a) == len(b) and all(x.shape == y.shape and np.array_equal(x, y) for x, y in zip(a, b))


moving_scene()
run(6, 0)
O.saveTmp("mid")
reference = run(6, 6)
O.loadTmp("mid")
restored = builtins.flow
checks.check(
    "after O.loadTmp the label names a PeriodicFlowEngine with the settings",
    type(restored) is PeriodicFlowEngine
    and restored.fluidBulkModulus == 1e4
    and restored.meshUpdateInterval == 4
    and tuple(restored.gradP) == (0.5, 1.0, 0.0)
    and len(restored._core.imposed_fluxes()) == 1,
)
checks.check("O.loadTmp: the run goes on as the uninterrupted one, remesh included", same(run(6, 6), reference))

path = os.path.join(tempfile.mkdtemp(prefix="pfv-periodic-save-"), "scene.yade.gz")
moving_scene()
run(5, 0)
O.save(path)
reference = run(4, 5)
O.load(path)
checks.check("O.load of a file: the run goes on as the uninterrupted one", same(run(4, 5), reference))

checks.report("periodic engine members")
