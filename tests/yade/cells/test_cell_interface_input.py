"""The cell members of pfv.FlowEngine (pfv/_cell_geometry.py, _flow_queries.py, _cell_conditions.py) on
their own: errors before the first step and for bad arguments, the attributes YADE's scripts set
(accepted, validated, read back), the per-step reports, the outputs that only print,
convertClumps=False against the same packing without clumps, and what a remesh does to the
conditions set on cells.

    yade-double -n -x tests/yade/cells/test_cell_interface_input.py      (exit 0 = pass)
"""
import contextlib
import io
import os
import tempfile

import numpy as np  # noqa: E402
from pfv_testing import checks, scenes
from yade import O  # noqa: E402
import pfv  # noqa: E402


def raises(kind, call):
    try:
        call()
    except kind:
        return True
    except Exception as error:  # the wrong kind
        print(f"  {type(error).__name__}: {error}")
        return False
    return False


def engine(**extra):
    scenes.build_permeameter(num=1000)
    flow = pfv.FlowEngine(label="flow")
    scenes.configure_flow(flow, axis=1, dp=1.0, slipBoundary=False, **extra)
    scenes.insert_flow(flow)
    return flow


def before_first_step():
    flow = engine()
    calls = {
        "getCellBarycenter": lambda: flow.getCellBarycenter(0),
        "getVertices": lambda: flow.getVertices(0),
        "getNeighbors": lambda: flow.getNeighbors(0),
        "getCellPImposed": lambda: flow.getCellPImposed(0),
        "setCellPImposed": lambda: flow.setCellPImposed(0, True),
        "blockCell": lambda: flow.blockCell(0, True),
        "getCellFluxFromId": lambda: flow.getCellFluxFromId(0),
        "averageVelocity": flow.averageVelocity,
        "getConstrictions": flow.getConstrictions,
        "volume": lambda: flow.volume(6),
        "exportMatrix": flow.exportMatrix,
        "getIncidentCells": lambda: flow.getIncidentCells(6),
        "initializeVolumes": flow.initializeVolumes,
        "getBoundaryFluidArea": lambda: flow.getBoundaryFluidArea(3),
        "cholmodStats": flow.cholmodStats,
    }
    bad = [name for name, call in calls.items() if not raises(RuntimeError, call)]
    checks.check("before the first step every cell member raises RuntimeError", not bad, ", ".join(bad))
    checks.check("porosity and epsVolMax read 0 before the first step", flow.porosity == 0 and flow.epsVolMax == 0)


def bad_arguments():
    flow = engine()
    O.run(1, True)
    n = flow.nCells()
    cases = [
        (IndexError, lambda: flow.getCellBarycenter(n)),
        (IndexError, lambda: flow.getVertices(-1)),
        (IndexError, lambda: flow.setCellPressure(n + 5, 0.0)),
        (IndexError, lambda: flow.getConductivity(0, 4)),
        (IndexError, lambda: flow.surfaceSolidThroatInPore(0, -1)),
        (IndexError, lambda: flow.setBoundaryNormal(6, (0, 1, 0))),
        (IndexError, lambda: flow.getCellFlux(3)),
        (TypeError, lambda: flow.getCellBarycenter(1.0)),
        (TypeError, lambda: flow.setCellPImposed(0, "yes")),
        (TypeError, lambda: flow.setCellPressure(0, "1")),
        (ValueError, lambda: flow.setCellPressure(0, float("nan"))),
        (ValueError, lambda: flow.getBoundaryFluidArea(17)),
        (ValueError, lambda: flow.volume(10**6)),
        (ValueError, lambda: flow.getCellVelocity((5, 5, 5))),
        (NotImplementedError, lambda: flow.setBoundaryNormal(2, (0, -1, 0))),
        (ValueError, lambda: setattr(flow, "minimumPorosity", 1.0)),
        (ValueError, lambda: setattr(flow, "wallThickness", -1)),
        (ValueError, lambda: setattr(flow, "numSolveThreads", 0)),
        (TypeError, lambda: setattr(flow, "blockHook", 3)),
        (SyntaxError, lambda: setattr(flow, "blockHook", "flow.blockCell(")),
        (ValueError, lambda: setattr(flow, "boundaryXPos", [0.0, float("inf")])),
        (ValueError, lambda: setattr(flow, "flatThreshold", float("nan"))),
        (AttributeError, lambda: setattr(flow, "porosity", 0.3)),
        (AttributeError, lambda: setattr(flow, "epsVolMax", 0)),
        (ValueError, lambda: setattr(flow, "boundaryVelocity", [(0, 0, 0)] * 5)),
    ]
    bad = [i for i, (kind, call) in enumerate(cases) if not raises(kind, call)]
    checks.check("bad arguments raise the error that names them", not bad, f"cases {bad}")
    before = flow.getBoundaryFlux(3)
    O.run(1, True)
    checks.check(
        "the engine still runs, unchanged, after the refused calls",
        abs(flow.getBoundaryFlux(3) - before) <= 1e-12 * abs(before),
    )


def attributes_and_reports():
    flow = engine()
    values = dict(
        numSolveThreads=2,
        numFactorizeThreads=3,
        permeabilityMap=True,
        ids=[6, 7],
        volumeFactor=2.0,
        boundaryVelocity=[(0, 0, 0)] * 5 + [(1, 0, 0)],
        meanK_opt=False,
        doInterpolate=True,
        minimumPorosity=0.1,
        flatThreshold=-1.0,
        idOffset=0,
        debug=True,
        getCHOLMODPerfTimings=True,
        meanKStat=True,
        iniVoidVolumes=True,
    )
    for name, value in values.items():
        setattr(flow, name, value)
    back = {name: getattr(flow, name) for name in values}
    back["boundaryVelocity"] = [tuple(v) for v in back["boundaryVelocity"]]
    values["boundaryVelocity"] = [tuple(float(x) for x in v) for v in values["boundaryVelocity"]]
    wrong = [name for name in values if back[name] != values[name]]
    checks.check("YADE's attributes are accepted and read back", not wrong, ", ".join(wrong))
    checks.check("meanK_opt is clampKValues", flow.clampKValues is False)
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        O.run(2, True)
    text = out.getvalue()
    checks.check(
        "debug, getCHOLMODPerfTimings and meanKStat report",
        "pfv.FlowEngine: iter" in text and "CHOLMOD Time to factorize" in text and "meanKStat (pfv)" in text,
        text[:200].replace("\n", " | "),
    )
    flow.debug = flow.getCHOLMODPerfTimings = flow.meanKStat = False
    # Printing outputs: they run (their YADE formats are compared in test_cell_interface_vs_yade.py).
    flow.cholmodStats()
    flow.compTessVolumes()
    flow.setBoundaryNormal(3, (0, -1, 0))
    q = flow.getBoundaryFlux(3)
    flow.resetLinearSystem()
    builds = flow.core.system_builds
    O.run(1, True)
    checks.check(
        "resetLinearSystem rebuilds the system, results unchanged",
        flow.core.system_builds == builds + 1 and abs(flow.getBoundaryFlux(3) - q) <= 1e-12 * abs(q),
    )
    flow.updateVolumes()
    flow.initializeVolumes()
    O.run(1, True)
    checks.check(
        "updateVolumes/initializeVolumes on a frozen packing change nothing",
        abs(flow.getBoundaryFlux(3) - q) <= 1e-12 * abs(q) and flow.epsVolMax == 0,
    )


def conditions_and_remesh():
    flow = engine()
    O.run(1, True)
    c = flow.getCell(0.5, 0.5, 0.5)
    flow.setCellPImposed(c, True)
    flow.blockCell(flow.getCell(0.3, 0.3, 0.3), False)
    O.run(1, True)
    held = flow.getCellPImposed(c)
    flow.updateTriangulation = True
    O.run(1, True)
    checks.check(
        "conditions set on cells hold until the next remesh",
        held
        and not flow.getCellPImposed(flow.getCell(0.5, 0.5, 0.5))
        and not flow.core.cell_blocked(flow.getCell(0.3, 0.3, 0.3)),
    )
    # doInterpolate carries blocked cells over a remesh (as YADE's interpolation does).
    flow.doInterpolate = True
    b = flow.getCell(0.3, 0.3, 0.3)
    flow.blockCell(b, True)
    O.run(1, True)
    flow.updateTriangulation = True
    O.run(1, True)
    b = flow.getCell(0.3, 0.3, 0.3)
    checks.check(
        "doInterpolate: a blocked cell stays blocked across a remesh",
        flow.core.cell_blocked(b) and flow.getCellPressure(b) == 0,
    )
    # pressureForce=False: no step at all; the next step after has no dV/dt term.
    flow.pressureForce = False
    remeshes = flow.core.remesh_count
    O.run(2, True)
    flow.pressureForce = True
    O.run(1, True)
    checks.check("pressureForce=False runs no flow step", flow.core.remesh_count == remeshes)


def velocities_follow_the_pressures():
    """getCellVelocity is evaluated once per step for all cells (a script asks cell by cell), and
    again after anything that changes the pressures between steps."""
    flow = engine()
    O.run(1, True)
    point = (0.5, 0.5, 0.5)
    first = flow.getCellVelocity(point)
    checks.check("a second query on the same step gives the same velocity", flow.getCellVelocity(point) == first)
    c = flow.getCell(*point)
    flow.setCellPressure(flow.getNeighbors(c)[0], 5.0)  # a neighbour's pressure drives the cell's flow
    changed = flow.getCellVelocity(point)
    checks.check(
        "setCellPressure between steps changes the velocity at once", changed != first, f"{first} -> {changed}"
    )
    flow.setCellPImposed(flow.getNeighbors(c)[0], True)
    O.run(1, True)
    stepped = flow.getCellVelocity(point)
    checks.check("the next step's velocity is the new pressures'", stepped != changed and stepped != first)
    lengths = [len(flow.getCellVelocity(flow.getCellBarycenter(k))) for k in range(flow.nCells())]
    checks.check("every cell answers from the shared evaluation", set(lengths) == {3})


def clumps():
    spheres = scenes.packing(1000)
    # Two touching neighbours become a clump: with convertClumps=False PFV couples them as spheres.
    flow = engine(convertClumps=False)
    a, b = 6 + 10, None
    pa = np.array(spheres[10][:3])
    for k, s in enumerate(spheres):
        if k != 10 and np.linalg.norm(np.array(s[:3]) - pa) < s[3] + spheres[10][3] + 1e-3:
            b = 6 + k
            break
    O.bodies.clump([a, b])
    O.run(1, True)
    q_clump, cells = flow.getBoundaryFlux(3), flow.nCells()
    plain = engine()
    O.run(1, True)
    checks.check(
        "convertClumps=False: clump members coupled as spheres",
        cells == plain.nCells() and abs(q_clump - plain.getBoundaryFlux(3)) <= 1e-9 * abs(q_clump),
        f"{cells} {plain.nCells()}",
    )
    members = len(plain._bodies.stepped.ids)  # read before the next scene: its end frees plain's mesh
    flow = engine()
    O.bodies.clump([a, b])
    O.run(1, True)
    checks.check(
        "convertClumps=True: the clump is one vertex fewer than its members",
        flow.nCells() > 0 and len(flow._bodies.stepped.ids) == members - 1,
    )


def main():
    os.chdir(tempfile.mkdtemp(prefix="pfv-cell-input-"))
    before_first_step()
    bad_arguments()
    attributes_and_reports()
    conditions_and_remesh()
    velocities_follow_the_pressures()
    clumps()


main()
checks.report("cell interface input")
