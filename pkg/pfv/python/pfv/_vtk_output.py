"""VTK output of pfv.FlowEngine (``saveVtk``): the engine's state as VTK objects and XML files for ParaView.

Each call writes two VTK XML unstructured grids into the folder and updates a ParaView collection:

* ``out_<N>.vtu``: the pore network, one VTK cell per pore cell, with the cell data Pressure, Velocity (mean fluid
  velocity from the throat fluxes), Pcondition (1: imposed pressure), PressureSource, FluidVolume, Volume,
  fictious (number of wall vertices) and id (the engine's cell index);
* ``spheres_<N>.vtu``: the coupled spheres as vertices with the point data radii, id (YADE body id) and fluidForce,
  and the walls' ids, positions and fluid forces as field data;
* ``out.pvd``: the collection of every snapshot written to the folder by this process, each at its time.

Both grids carry the time as the field data ``TimeValue``. Every float is written as Float64, so that a file read
back gives the engine's values exactly. The files are written by VTK's own XML writer
(``vtkXMLUnstructuredGridWriter``, appended raw binary, optionally zlib-compressed) from numpy arrays copied in
bulk (``numpy_support``); the collection is a small XML index written with ``xml.etree``.

Walls: a pore cell with wall vertices is, in the engine's geometry, the prism swept from its sphere centres to the
walls (``lib/triangulation/pore_geometry.hpp``). It is written as that solid: a cell with one wall vertex as a
wedge (its sphere triangle and the triangle's projection on the wall), with two as a hexahedron (its sphere segment,
the segment's projections on both walls and on their common edge), with three as the box between its sphere centre
and the corner. Projections of the same sphere on the same walls are one point, so neighbouring cells share their
faces and the cells tile the box; the volume of each VTK cell is the cell's Volume. ``withBoundaries=False`` leaves
out every cell with a wall vertex, as YADE does.
"""
from __future__ import annotations

import contextlib
import os
import sys
import threading
import xml.etree.ElementTree as ElementTree
from dataclasses import dataclass
from typing import Any

import numpy as np
from vtkmodules.util.numpy_support import numpy_to_vtk
from vtkmodules.vtkCommonCore import VTK_ID_TYPE, vtkPoints
from vtkmodules.vtkCommonDataModel import (
    VTK_HEXAHEDRON,
    VTK_TETRA,
    VTK_VERTEX,
    VTK_WEDGE,
    vtkCellArray,
    vtkUnstructuredGrid,
)
from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridWriter

__all__ = [
    "FlowState",
    "read_state",
    "pore_grid",
    "sphere_grid",
    "unstructured_grid",
    "vtk_array",
    "write_grid",
    "save",
    "save_grids",
    "COLLECTION",
]

COLLECTION = "out.pvd"  # the collection file of a folder
_WALLS = 6
_MASK = 64  # a projection point's key: sphere * _MASK + the bit mask of the walls it is projected on
_CELL_TYPES = np.array([VTK_TETRA, VTK_WEDGE, VTK_HEXAHEDRON, VTK_HEXAHEDRON], dtype=np.uint8)  # by wall count
_CELL_SIZES = np.array([4, 6, 8, 8], dtype=np.int64)


@dataclass
class FlowState:
    """What the output needs of an engine, copied out under its lock (spheres in the core's order)."""

    time: float
    ids: np.ndarray  # YADE ids of the spheres
    radii: np.ndarray
    positions: np.ndarray  # (n, 3): the sphere centres of the last step
    forces: np.ndarray  # (n + 6, 3): fluid forces on the spheres, then on the six walls
    walls: np.ndarray  # the six wall coordinates (xmin, xmax, ymin, ymax, zmin, zmax)
    wall_ids: np.ndarray  # YADE ids of the walls
    cell_vertices: np.ndarray  # (cells, 4): vertex n + w is wall w
    pressure: np.ndarray
    velocity: np.ndarray  # (cells, 3)
    fluid_volume: np.ndarray
    volume: np.ndarray  # total volume at `positions`
    source: np.ndarray  # wall w, 6 + imposed point k, or -1 (pressure solved for)

    @property
    def n_spheres(self) -> int:
        return len(self.ids)


def read_state(core: Any, ids: np.ndarray, radii: np.ndarray, wall_ids: list[int], time: float) -> FlowState:
    """The output's data from the core `core` (pfv._core.Engine, after a step) for the spheres of YADE ids `ids` and
    radii `radii` (those of the last step) and the walls `wall_ids`. The caller holds the engine's lock."""
    return FlowState(
        time=float(time),
        ids=np.asarray(ids, dtype=np.int64),
        radii=np.asarray(radii, dtype=float),
        positions=core.positions(),
        forces=core.forces(),
        walls=np.array(core.walls(), dtype=float),
        wall_ids=np.asarray(wall_ids, dtype=np.int64),
        cell_vertices=core.cell_vertices(),
        pressure=core.pressure(),
        velocity=core.cell_velocities(),
        fluid_volume=core.cell_fluid_volumes(),
        volume=core.current_cell_volumes(),
        source=core.cell_sources(),
    )


# The VTK arrays are copies: a VTK array sharing a numpy array's memory keeps it alive only through its Python
# wrapper, which VTK may drop while the C++ array lives on in the grid (then pointing to freed memory).
def vtk_array(values: np.ndarray, name: str) -> Any:
    """A named VTK array with a copy of `values` (one memcpy)."""
    array = numpy_to_vtk(np.ascontiguousarray(values), deep=True)
    array.SetName(name)
    return array


def _id_array(values: np.ndarray) -> Any:
    return numpy_to_vtk(np.ascontiguousarray(values, dtype=np.int64), deep=True, array_type=VTK_ID_TYPE)


def unstructured_grid(
    points: np.ndarray, cell_types: np.ndarray, offsets: np.ndarray, connectivity: np.ndarray, time: float
) -> vtkUnstructuredGrid:
    grid = vtkUnstructuredGrid()
    vtk_points = vtkPoints()
    vtk_points.SetData(vtk_array(np.asarray(points, dtype=float), "Points"))
    grid.SetPoints(vtk_points)
    cells = vtkCellArray()
    cells.SetData(_id_array(offsets), _id_array(connectivity))
    grid.SetCells(vtk_array(cell_types, "types"), cells)
    grid.GetFieldData().AddArray(vtk_array(np.array([time]), "TimeValue"))
    return grid


def _projection_points(keys: np.ndarray, positions: np.ndarray, walls: np.ndarray) -> np.ndarray:
    """The points of projection keys (sphere * _MASK + wall mask): the sphere centre with the coordinate of every
    wall of the mask replaced by the wall's."""
    spheres, masks = np.divmod(keys, _MASK)
    points = positions[np.minimum(spheres, len(positions) - 1)]  # a corner (sphere n) takes all three from walls
    for w in range(_WALLS):
        on = (masks >> w) & 1 == 1
        points[on, w // 2] = walls[w]
    return points


def _even(axis1: np.ndarray, axis2: np.ndarray) -> np.ndarray:
    """+1 where (axis1, axis2, the third axis) is an even permutation of (0, 1, 2), else -1."""
    return np.where((axis2 - axis1) % 3 == 1, 1.0, -1.0)


def _pore_cells(state: FlowState, with_boundaries: bool) -> tuple[np.ndarray, ...]:
    """(cells kept, points, cell types, offsets, connectivity) of the pore network, each cell positively oriented
    in VTK's convention. Vectorised over the cells of each wall count."""
    n = state.n_spheres
    pos, walls = state.positions, state.walls
    vertices = np.asarray(state.cell_vertices, dtype=np.int64)
    is_wall = vertices >= n
    wall_count = is_wall.sum(axis=1)
    kept = np.arange(len(vertices)) if with_boundaries else np.flatnonzero(wall_count == 0)
    counts = wall_count[kept]
    v = vertices[kept]
    # Wall cells: spheres first, then walls (as wall indices), as in the engine's cell shapes.
    walled = np.flatnonzero(counts > 0)
    if len(walled):
        order = np.argsort(v[walled] >= n, axis=1, kind="stable")
        sorted_vertices = np.take_along_axis(v[walled], order, axis=1)
        v[walled] = np.where(sorted_vertices >= n, sorted_vertices - n, sorted_vertices)
    sizes = _CELL_SIZES[counts]
    offsets = np.zeros(len(kept) + 1, dtype=np.int64)
    np.cumsum(sizes, out=offsets[1:])
    connectivity = np.empty(offsets[-1], dtype=np.int64)
    blocks, keys = [], []  # per wall count: (rows of `kept`, connectivity with projection keys marked negative)

    rows = np.flatnonzero(counts == 0)
    if len(rows):
        t = v[rows].copy()
        a, b, c, d = (pos[t[:, k]] for k in range(4))
        flip = np.einsum("ij,ij->i", b - a, np.cross(c - a, d - a)) < 0
        t[flip, 2], t[flip, 3] = t[flip, 3], t[flip, 2].copy()
        blocks.append((rows, t))

    def key(sphere: np.ndarray, *wall_sets: np.ndarray) -> np.ndarray:
        mask = np.zeros(len(sphere), dtype=np.int64)
        for w in wall_sets:
            mask |= np.left_shift(1, w)
        corner = len(wall_sets) == 3
        k = (np.full(len(sphere), n, dtype=np.int64) if corner else sphere) * _MASK + mask
        keys.append(k)
        return -1 - k  # marked: replaced by a point index below

    rows = np.flatnonzero(counts == 1)
    if len(rows):
        s, w = v[rows, :3].copy(), v[rows, 3]
        a, b, d = (pos[s[:, k]] for k in range(3))
        axis = w // 2
        normal = np.cross(b - a, d - a)[np.arange(len(rows)), axis]
        # The sphere triangle is the base: its normal points away from the wall, into the box.
        flip = normal * np.where(w % 2 == 0, 1.0, -1.0) < 0
        s[flip, 1], s[flip, 2] = s[flip, 2], s[flip, 1].copy()
        blocks.append((rows, np.column_stack([s, key(s[:, 0], w), key(s[:, 1], w), key(s[:, 2], w)])))

    rows = np.flatnonzero(counts == 2)
    if len(rows):
        s0, s1 = v[rows, 0], v[rows, 1]
        w1, w2 = v[rows, 2].copy(), v[rows, 3].copy()
        a, b = pos[s0], pos[s1]
        i = np.arange(len(rows))
        axis1, axis2 = w1 // 2, w2 // 2
        edge = 3 - axis1 - axis2
        # Base (a, a on w1, a on w1 and w2, a on w2): its normal must point towards b.
        toward = (walls[w1] - a[i, axis1]) * (walls[w2] - a[i, axis2]) * _even(axis1, axis2) * (b[i, edge] - a[i, edge])
        flip = toward < 0
        w1[flip], w2[flip] = w2[flip], w1[flip].copy()
        blocks.append(
            (
                rows,
                np.column_stack(
                    [s0, key(s0, w1), key(s0, w1, w2), key(s0, w2), s1, key(s1, w1), key(s1, w1, w2), key(s1, w2)]
                ),
            )
        )

    rows = np.flatnonzero(counts == 3)
    if len(rows):
        s0 = v[rows, 0]
        w1, w2, w3 = v[rows, 1].copy(), v[rows, 2].copy(), v[rows, 3]
        a = pos[s0]
        i = np.arange(len(rows))
        axis1, axis2, axis3 = w1 // 2, w2 // 2, w3 // 2
        # Base (a, a on w1, a on w1 and w2, a on w2): its normal must point towards w3.
        toward = (walls[w1] - a[i, axis1]) * (walls[w2] - a[i, axis2]) * (walls[w3] - a[i, axis3]) * _even(axis1, axis2)
        flip = toward < 0
        w1[flip], w2[flip] = w2[flip], w1[flip].copy()
        blocks.append(
            (
                rows,
                np.column_stack(
                    [
                        s0,
                        key(s0, w1),
                        key(s0, w1, w2),
                        key(s0, w2),
                        key(s0, w3),
                        key(s0, w1, w3),
                        key(s0, w1, w2, w3),
                        key(s0, w2, w3),
                    ]
                ),
            )
        )

    points = pos
    if keys:
        unique = np.unique(np.concatenate(keys))
        points = np.concatenate([pos, _projection_points(unique, pos, walls)])
    for rows, block in blocks:
        if keys:
            # The marked entries (-1 - key) become n + the key's rank among the unique keys.
            marked = block < 0
            block[marked] = n + np.searchsorted(unique, -1 - block[marked])
        connectivity[offsets[rows][:, None] + np.arange(block.shape[1])] = block
    return kept, points, _CELL_TYPES[counts], offsets, connectivity


def pore_grid(state: FlowState, with_boundaries: bool) -> vtkUnstructuredGrid:
    """The pore network as a VTK unstructured grid (see the module's docstring)."""
    kept, points, types, offsets, connectivity = _pore_cells(state, with_boundaries)
    grid = unstructured_grid(points, types, offsets, connectivity, state.time)
    source = np.asarray(state.source, dtype=np.int32)[kept]
    fictious = (np.asarray(state.cell_vertices) >= state.n_spheres).sum(axis=1).astype(np.int32)[kept]
    data = grid.GetCellData()
    for name, values in (
        ("Pressure", np.asarray(state.pressure, dtype=float)[kept]),
        ("Velocity", np.asarray(state.velocity, dtype=float)[kept]),
        ("Pcondition", (source >= 0).astype(np.int32)),
        ("PressureSource", source),
        ("FluidVolume", np.asarray(state.fluid_volume, dtype=float)[kept]),
        ("Volume", np.asarray(state.volume, dtype=float)[kept]),
        ("fictious", fictious),
        ("id", kept.astype(np.int32)),
    ):
        data.AddArray(vtk_array(values, name))
    data.SetActiveScalars("Pressure")
    return grid


def sphere_grid(state: FlowState) -> vtkUnstructuredGrid:
    """The coupled spheres as VTK vertices with their radii, YADE ids and fluid forces; the walls' ids, positions and
    fluid forces as field data."""
    n = state.n_spheres
    grid = unstructured_grid(
        state.positions,
        np.full(n, VTK_VERTEX, dtype=np.uint8),
        np.arange(n + 1, dtype=np.int64),
        np.arange(n, dtype=np.int64),
        state.time,
    )
    forces = np.asarray(state.forces, dtype=float)
    data = grid.GetPointData()
    data.AddArray(vtk_array(state.radii, "radii"))
    data.AddArray(vtk_array(state.ids, "id"))
    data.AddArray(vtk_array(forces[:n], "fluidForce"))
    data.SetActiveScalars("radii")
    field = grid.GetFieldData()
    field.AddArray(vtk_array(state.wall_ids, "wallIds"))
    field.AddArray(vtk_array(state.walls, "wallPositions"))
    field.AddArray(vtk_array(forces[n : n + _WALLS], "wallFluidForce"))
    return grid


def write_grid(grid: vtkUnstructuredGrid, path: str, compress: bool) -> None:
    """Write `grid` to `path` (.vtu) with VTK's XML writer: appended raw binary, zlib-compressed if `compress`.
    Written to a temporary file first and renamed: a reader never sees a half-written file."""
    writer = vtkXMLUnstructuredGridWriter()
    partial = f"{path}.part{os.getpid()}"
    writer.SetFileName(partial)
    writer.SetInputData(grid)
    writer.SetDataModeToAppended()
    writer.EncodeAppendedDataOff()
    writer.SetHeaderTypeToUInt64()
    if compress:
        # Level 1 rather than VTK's default 5: zlib's fastest level; on float arrays the higher levels
        # gain little size for their time.
        writer.SetCompressorTypeToZLib()
        writer.SetCompressionLevel(1)
    else:
        writer.SetCompressorTypeToNone()
    if writer.Write() != 1:
        with contextlib.suppress(FileNotFoundError):
            os.remove(partial)
        raise OSError(f"pfv.FlowEngine.saveVtk: VTK could not write {path}")
    os.replace(partial, path)


@dataclass
class _Snapshot:
    time: float
    files: tuple[tuple[str, str], ...]  # (name, file relative to the folder) per part


_series: dict[str, list[_Snapshot]] = {}  # real path of a folder -> its snapshots written by this process
_series_lock = threading.Lock()


def _write_collection(folder: str, snapshots: list[_Snapshot]) -> None:
    """The folder's ParaView collection: every snapshot's parts at its time."""
    root = ElementTree.Element(
        "VTKFile",
        type="Collection",
        version="0.1",
        byte_order="LittleEndian" if sys.byteorder == "little" else "BigEndian",
    )
    collection = ElementTree.SubElement(root, "Collection")
    for snapshot in snapshots:
        for part, (name, file) in enumerate(snapshot.files):
            ElementTree.SubElement(
                collection, "DataSet", timestep=repr(snapshot.time), group="", part=str(part), name=name, file=file
            )
    tree = ElementTree.ElementTree(root)
    ElementTree.indent(tree)
    path = os.path.join(folder, COLLECTION)
    partial = f"{path}.part{os.getpid()}"
    tree.write(partial, encoding="utf-8", xml_declaration=True)
    os.replace(partial, path)


def save_grids(
    folder: str, time: float, grids: list[tuple[str, str, vtkUnstructuredGrid]], compress: bool
) -> list[str]:
    """Write the parts `grids` ((name, file prefix, grid) each) of one snapshot at `time` into `folder` (made if
    missing) as <prefix>_<N>.vtu, N the number of snapshots this process wrote there before, and rewrite the folder's
    collection. Returns the paths written."""
    os.makedirs(folder, exist_ok=True)
    key = os.path.realpath(folder)
    with _series_lock:
        snapshots = _series.setdefault(key, [])
        number = len(snapshots)
        files = tuple((name, f"{prefix}_{number}.vtu") for name, prefix, _ in grids)
        for (_, file), (_, _, grid) in zip(files, grids):
            write_grid(grid, os.path.join(folder, file), compress)
        snapshots.append(_Snapshot(time, files))
        _write_collection(folder, snapshots)
    return [os.path.join(folder, f) for _, f in files] + [os.path.join(folder, COLLECTION)]


def save(state: FlowState, folder: str, with_boundaries: bool, compress: bool) -> list[str]:
    """Write the snapshot `state` into `folder` as out_<N>.vtu and spheres_<N>.vtu (save_grids)."""
    grids = [("pores", "out", pore_grid(state, with_boundaries)), ("spheres", "spheres", sphere_grid(state))]
    return save_grids(folder, state.time, grids, compress)
