"""FlowEngine.saveVtk: every file read back with VTK's XML readers gives the engine's values exactly.

    yade-double -n -x tests/yade/engine/test_save_vtk.py        (exit 0 = pass, 1 = fail)

Scene: the shipped 1000-sphere permeameter (frozen spheres, pressure drop along y) with one imposed pressure point.

Checks
1. saveVtk before the first step raises RuntimeError ("not run yet"); bad arguments raise TypeError.
2. Two calls at two iterations into one folder write out_0.vtu, spheres_0.vtu, out_1.vtu, spheres_1.vtu and out.pvd;
   the collection lists both snapshots (pores and spheres) at the O.time of each call, and every file it names
   carries that time as TimeValue.
3. Pore files: Pressure, Velocity, FluidVolume, Volume, Pcondition, PressureSource, fictious and id equal the
   engine's arrays (pressure(), cell_velocities(), cell_fluid_volumes(), current_cell_volumes(), cell_sources(),
   the wall count of cell_vertices()) bit for bit, floats as Float64; getCellPressure agrees; each cell's points are
   its sphere centres (the bodies' positions) and, for wall cells, their projections on its walls.
4. withBoundaries=False holds exactly the cells without a wall vertex, withBoundaries=True every cell, one VTK cell
   each (tetrahedron, wedge, hexahedron); VTK's own cell volumes (vtkCellSizeFilter) equal Volume to 1e-12 and are
   positive, and with boundaries they add up to the box (the cells tile it) and no point is written twice;
   Pcondition marks the cells of the two pressure walls and of the imposed point.
5. Sphere files: points, radii, id, fluidForce equal the bodies' positions and radii, the YADE ids and
   fluidForce(id); the walls' ids, positions and fluid forces are in the field data.
6. compress=True writes zlib-compressed files (smaller) whose arrays equal the uncompressed ones.
"""
import math
import os
import shutil
import tempfile
import xml.etree.ElementTree as ElementTree

import numpy as np  # noqa: E402
from pfv_testing import checks, scenes
from yade import O  # noqa: E402
from vtkmodules.util.numpy_support import vtk_to_numpy  # noqa: E402
from vtkmodules.vtkCommonDataModel import VTK_HEXAHEDRON, VTK_TETRA, VTK_VERTEX, VTK_WEDGE  # noqa: E402
from vtkmodules.vtkFiltersVerdict import vtkCellSizeFilter  # noqa: E402
from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader  # noqa: E402
from pfv import FlowEngine  # noqa: E402


def read(path):
    reader = vtkXMLUnstructuredGridReader()
    reader.SetFileName(path)
    reader.Update()
    if reader.GetErrorCode() != 0 or reader.GetOutput().GetNumberOfPoints() == 0:
        raise RuntimeError(f"VTK could not read {path}")
    return reader.GetOutput()


def arrays(data):
    """{name: (numpy array, VTK type name)} of a vtkFieldData (point, cell or field data)."""
    out = {}
    for k in range(data.GetNumberOfArrays()):
        a = data.GetAbstractArray(k)
        out[a.GetName()] = (vtk_to_numpy(a), a.GetDataTypeAsString())
    return out


def cells(grid):
    """(types, list of point-id arrays) of every cell."""
    types = vtk_to_numpy(grid.GetCellTypesArray())
    offsets = vtk_to_numpy(grid.GetCells().GetOffsetsArray())
    connectivity = vtk_to_numpy(grid.GetCells().GetConnectivityArray())
    return types, [connectivity[offsets[k] : offsets[k + 1]] for k in range(len(types))]


def engine_state(flow):
    """The engine's values that a snapshot taken now must hold."""
    core = flow.core
    scan = flow._bodies.stepped
    ids = scan.ids
    return dict(
        time=O.time,
        pressure=core.pressure(),
        velocity=core.cell_velocities(),
        fluid_volume=core.cell_fluid_volumes(),
        volume=core.current_cell_volumes(),
        source=core.cell_sources(),
        vertices=core.cell_vertices(),
        positions=core.positions(),
        walls=np.array(core.walls()),
        forces=core.forces(),
        ids=ids.copy(),
        radii=scan.radii.copy(),
        bodies=np.array([tuple(O.bodies[int(i)].state.pos) for i in ids]),
        body_radii=np.array([O.bodies[int(i)].shape.radius for i in ids]),
        fluid_force=np.array([tuple(flow.fluidForce(int(i))) for i in ids]),
        wall_force=np.array([tuple(flow.fluidForce(w)) for w in range(6)]),
        cell_pressure=np.array([flow.getCellPressure(c) for c in range(0, flow.nCells(), 97)]),
        n_cells=flow.nCells(),
    )


def same(a, b):
    a, b = np.asarray(a), np.asarray(b)
    return a.shape == b.shape and np.array_equal(a, b)


def expected_points(state, vertices):
    """For one cell: its sphere centres and, per wall vertex set, the projections expected among its points."""
    n = len(state["ids"])
    spheres = [v for v in vertices if v < n]
    walls = [v - n for v in vertices if v >= n]
    points = [state["positions"][s] for s in spheres]
    for s in spheres:  # every projection of every sphere centre on every non-empty subset of the cell's walls
        for mask in range(1, 1 << len(walls)):
            p = state["positions"][s].copy()
            for j, w in enumerate(walls):
                if mask >> j & 1:
                    p[w // 2] = state["walls"][w]
            points.append(p)
    return np.unique(np.array(points), axis=0)


def check_pores(path, state, with_boundaries, label):
    grid = read(path)
    data = arrays(grid.GetCellData())
    n = len(state["ids"])
    wall_count = (state["vertices"] >= n).sum(axis=1)
    kept = np.arange(state["n_cells"]) if with_boundaries else np.flatnonzero(wall_count == 0)
    checks.check(
        f"{label}: {grid.GetNumberOfCells()} cells = {len(kept)} "
        f"({'every cell' if with_boundaries else 'cells without a wall vertex'} of {state['n_cells']})",
        grid.GetNumberOfCells() == len(kept),
    )
    expected = dict(
        Pressure=(state["pressure"][kept], "double"),
        Velocity=(state["velocity"][kept], "double"),
        FluidVolume=(state["fluid_volume"][kept], "double"),
        Volume=(state["volume"][kept], "double"),
        Pcondition=((state["source"][kept] >= 0).astype(np.int32), "int"),
        PressureSource=(state["source"][kept], "int"),
        fictious=(wall_count[kept], "int"),
        id=(kept, "int"),
    )
    for name, (values, kind) in expected.items():
        got = data.get(name)
        checks.check(
            f"{label}: {name} ({kind}) equals the engine's", got is not None and got[1] == kind and same(got[0], values)
        )
    checks.check(
        f"{label}: Pressure agrees with getCellPressure",
        same(data["Pressure"][0][np.searchsorted(kept, np.arange(0, state["n_cells"], 97))], state["cell_pressure"])
        if with_boundaries
        else True,
    )
    points = vtk_to_numpy(grid.GetPoints().GetData())
    checks.check(
        f"{label}: points 0..n-1 are the sphere centres (Float64)",
        grid.GetPoints().GetData().GetDataTypeAsString() == "double"
        and same(points[:n], state["positions"])
        and same(points[:n], state["bodies"]),
    )
    field = arrays(grid.GetFieldData())
    checks.check(f"{label}: TimeValue = O.time of the call", same(field["TimeValue"][0], [state["time"]]))
    types, members = cells(grid)
    type_of = np.array([VTK_TETRA, VTK_WEDGE, VTK_HEXAHEDRON, VTK_HEXAHEDRON])
    checks.check(
        f"{label}: tetrahedra, wedges (1 wall), hexahedra (2, 3 walls)", same(types, type_of[wall_count[kept]])
    )
    bad = [
        c
        for c, m in zip(kept, members)
        if not same(np.unique(points[m], axis=0), expected_points(state, state["vertices"][c]))
    ]
    checks.check(
        f"{label}: each cell's points are its sphere centres and their wall projections ({len(bad)} not)", not bad
    )
    sizes = vtkCellSizeFilter()
    sizes.SetInputData(grid)
    sizes.Update()
    vtk_volume = vtk_to_numpy(sizes.GetOutput().GetCellData().GetArray("Volume"))
    volume = state["volume"][kept]
    error = np.max(np.abs(vtk_volume - volume) / volume)
    checks.check(
        f"{label}: VTK's cell volumes are positive and equal Volume (largest relative difference {error:.1e})",
        vtk_volume.min() > 0 and error < 1e-12,
    )
    if with_boundaries:
        walls = state["walls"]
        box = (walls[1] - walls[0]) * (walls[3] - walls[2]) * (walls[5] - walls[4])
        checks.check(
            f"{label}: the cells tile the box (sum of VTK volumes {vtk_volume.sum():.15g}, box {box:.15g})",
            math.isclose(vtk_volume.sum(), box, rel_tol=1e-12),
        )
        checks.check(
            f"{label}: no point twice ({len(points)} points): neighbouring cells share their wall points",
            len(np.unique(points, axis=0)) == len(points),
        )
        imposed = data["PressureSource"][0]
        checks.check(
            f"{label}: imposed pressure in the cells of walls 2, 3 and of the imposed point "
            f"({[(int(v), int((imposed == v).sum())) for v in np.unique(imposed)]})",
            (imposed == 2).sum() > 0
            and (imposed == 3).sum() > 0
            and (imposed == 6).sum() == 1
            and set(np.unique(imposed)) == {-1, 2, 3, 6},
        )
    return grid


def check_spheres(path, state, label):
    grid = read(path)
    n = len(state["ids"])
    data = arrays(grid.GetPointData())
    points = vtk_to_numpy(grid.GetPoints().GetData())
    checks.check(
        f"{label}: points are the sphere centres", grid.GetNumberOfPoints() == n and same(points, state["bodies"])
    )
    types, members = cells(grid)
    checks.check(
        f"{label}: one vertex cell per sphere",
        same(types, np.full(n, VTK_VERTEX)) and same(np.concatenate(members), np.arange(n)),
    )
    checks.check(f"{label}: radii", data["radii"][1] == "double" and same(data["radii"][0], state["body_radii"]))
    checks.check(f"{label}: id = YADE ids", same(data["id"][0], state["ids"]))
    checks.check(
        f"{label}: fluidForce = fluidForce(id)",
        data["fluidForce"][1] == "double"
        and same(data["fluidForce"][0], state["fluid_force"])
        and same(data["fluidForce"][0], state["forces"][:n]),
    )
    field = arrays(grid.GetFieldData())
    checks.check(
        f"{label}: walls' ids, positions, fluid forces",
        same(field["wallIds"][0], np.arange(6))
        and same(field["wallPositions"][0], state["walls"])
        and same(field["wallFluidForce"][0], state["wall_force"]),
    )
    checks.check(f"{label}: TimeValue = O.time of the call", same(field["TimeValue"][0], [state["time"]]))
    return grid


def same_grids(a, b):
    """Whether two grids hold the same points, cells and arrays."""
    if not same(vtk_to_numpy(a.GetPoints().GetData()), vtk_to_numpy(b.GetPoints().GetData())):
        return False
    if not same(vtk_to_numpy(a.GetCellTypesArray()), vtk_to_numpy(b.GetCellTypesArray())):
        return False
    if not same(vtk_to_numpy(a.GetCells().GetConnectivityArray()), vtk_to_numpy(b.GetCells().GetConnectivityArray())):
        return False
    for get in ("GetCellData", "GetPointData", "GetFieldData"):
        x, y = arrays(getattr(a, get)()), arrays(getattr(b, get)())
        if x.keys() != y.keys() or any(not same(x[k][0], y[k][0]) or x[k][1] != y[k][1] for k in x):
            return False
    return True


root = tempfile.mkdtemp(prefix="pfv-vtk-")
try:
    scenes.build_permeameter(num=1000)
    flow = FlowEngine(label="flow")
    scenes.configure_flow(flow, axis=1, dp=1.0)
    scenes.insert_flow(flow)
    flow.imposePressure((0.5, 0.5, 0.5), 0.25)
    plain, boundaries, compressed = (os.path.join(root, d) for d in ("plain", "boundaries", "compressed"))

    # 1. Before the first step, and bad arguments.
    checks.expect_error(
        "saveVtk before the first step", RuntimeError, "not run yet", lambda: flow.saveVtk(plain), ignore_case=False
    )
    checks.check("nothing written before the first step", not os.path.exists(plain))
    O.run(2, True)
    checks.expect_error("saveVtk(folder=3)", TypeError, "folder", lambda: flow.saveVtk(3), ignore_case=False)
    checks.expect_error(
        "saveVtk(withBoundaries='yes')",
        TypeError,
        "withBoundaries",
        lambda: flow.saveVtk(plain, "yes"),
        ignore_case=False,
    )
    checks.expect_error(
        "saveVtk(compress=None)", TypeError, "compress", lambda: flow.saveVtk(plain, compress=None), ignore_case=False
    )

    # 2. Two snapshots at two iterations; the same states with boundaries, compressed and not.
    states = []
    for k in range(2):
        if k:
            O.run(1, True)
        states.append(engine_state(flow))
        flow.saveVtk(plain)
        flow.saveVtk(boundaries, True)
        flow.saveVtk(compressed, withBoundaries=True, compress=True)
    checks.check(
        f"two snapshots at O.time {states[0]['time']} and {states[1]['time']}", states[1]["time"] > states[0]["time"]
    )
    names = sorted(os.listdir(plain))
    checks.check(f"files: {names}", names == ["out.pvd", "out_0.vtu", "out_1.vtu", "spheres_0.vtu", "spheres_1.vtu"])

    tree = ElementTree.parse(os.path.join(plain, "out.pvd")).getroot()
    entries = [d.attrib for d in tree.iter("DataSet")]
    listed = [(float(e["timestep"]), e["part"], e["name"], e["file"]) for e in entries]
    wanted = [
        (s["time"], part, name, f"{prefix}_{k}.vtu")
        for k, s in enumerate(states)
        for part, name, prefix in (("0", "pores", "out"), ("1", "spheres", "spheres"))
    ]
    checks.check(
        f"out.pvd lists both snapshots at their times: {listed}", tree.get("type") == "Collection" and listed == wanted
    )
    for e in entries:
        grid = read(os.path.join(plain, e["file"]))
        checks.check(
            f"{e['file']} read through out.pvd: TimeValue = its timestep",
            same(arrays(grid.GetFieldData())["TimeValue"][0], [float(e["timestep"])]),
        )

    # 3-5. Every file against the engine's values at its call.
    for k, state in enumerate(states):
        check_pores(os.path.join(plain, f"out_{k}.vtu"), state, False, f"out_{k}.vtu")
        pores = check_pores(os.path.join(boundaries, f"out_{k}.vtu"), state, True, f"withBoundaries out_{k}.vtu")
        spheres = check_spheres(os.path.join(plain, f"spheres_{k}.vtu"), state, f"spheres_{k}.vtu")
        # 6. Compressed files hold the same data.
        for name, grid in ((f"out_{k}.vtu", pores), (f"spheres_{k}.vtu", spheres)):
            packed = os.path.join(compressed, name)
            with open(packed, "rb") as f:
                header = f.read(400)
            smaller = os.path.getsize(packed) < os.path.getsize(os.path.join(boundaries, name))
            checks.check(
                f"compressed {name}: zlib, smaller, same data",
                b'compressor="vtkZLibDataCompressor"' in header and smaller and same_grids(read(packed), grid),
            )
finally:
    shutil.rmtree(root, ignore_errors=True)

checks.report("saveVtk")
