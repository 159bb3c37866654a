"""VTK output of pfv.PeriodicFlowEngine (``saveVtk``): one period of the pore network and the spheres, for ParaView.

Each call writes, as pfv.FlowEngine's output does (``_vtk_output``, the same collection ``out.pvd``):

* ``out_<N>.vtu``: every pore of one period once, as the tetrahedron the engine stores for it, at the last step's
  positions. A pore that crosses a face of the cell is drawn whole, on the images of its spheres outside the cell:
  the points of the grid are the images the stored pores use (the periodic images a viewer needs), so the pores
  tile one period of space without gaps or overlaps, though not the box of the cell itself. Cell data: Pressure
  (p~ + gradP . x at the power centre), PeriodicPressure (p~), Pcondition (1: imposed pressure), FluidVolume and
  Volume (at the remesh; at the last step), id (the engine's cell index, as getCellPressure takes it);
* ``spheres_<N>.vtu``: each sphere once, its centre wrapped into the cell, with the point data radii, id (YADE body
  id) and fluidForce; the cell's vectors (columns of O.cell.hSize) as the field data ``cellVectors`` and the imposed
  gradient as ``gradP``.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from vtkmodules.vtkCommonDataModel import VTK_TETRA, VTK_VERTEX

from . import _vtk_output as output


@dataclass
class PeriodicState:
    """What the output needs of a periodic engine after a step (spheres in the core's order)."""

    time: float
    ids: np.ndarray
    radii: np.ndarray
    centres: np.ndarray  # (n, 3), wrapped into the cell
    forces: np.ndarray  # (n, 3)
    cell: np.ndarray  # (3, 3), columns the cell's vectors
    gradient: np.ndarray
    cell_vertices: np.ndarray  # (cells, 4) image indices
    images: np.ndarray  # (images, 3)
    pressure: np.ndarray
    periodic_pressure: np.ndarray
    imposed: np.ndarray  # per cell, 1 where the pressure is imposed
    fluid_volume: np.ndarray
    volume: np.ndarray


def read_state(engine: Any) -> PeriodicState:
    """The output's data from a pfv.PeriodicFlowEngine after a step."""
    import yade

    core = engine._core
    cell = core.step_cell()
    images, image_spheres = core.image_positions(), core.image_spheres()
    _, first_image = np.unique(image_spheres, return_index=True)  # one image per sphere, in sphere order
    imposed = core.imposed_cells()
    return PeriodicState(
        time=float(yade.O.time),
        ids=np.asarray(engine._spheres[0], dtype=np.int64),
        radii=np.asarray(engine._spheres[1], dtype=float),
        centres=wrapped(images[first_image], cell),
        forces=core.forces(),
        cell=cell,
        gradient=np.array(tuple(engine.gradP), dtype=float),
        cell_vertices=core.cell_vertices(),
        images=images,
        pressure=core.pressure(),
        periodic_pressure=core.periodic_pressure(),
        imposed=imposed if len(imposed) else np.zeros(core.n_cells, dtype=int),
        fluid_volume=core.fluid_volumes(),
        volume=core.current_cell_volumes(),
    )


def wrapped(centres: np.ndarray, cell: np.ndarray) -> np.ndarray:
    """The centres moved by whole periods into the cell [0, 1)^3 of cell coordinates."""
    fractions = np.linalg.solve(cell, centres.T).T
    return centres - np.floor(fractions) @ cell.T


def pore_grid(state: PeriodicState) -> Any:
    used, connectivity = np.unique(state.cell_vertices.ravel(), return_inverse=True)
    n = len(state.cell_vertices)
    grid = output.unstructured_grid(
        state.images[used],
        np.full(n, VTK_TETRA, dtype=np.uint8),
        np.arange(0, 4 * n + 1, 4, dtype=np.int64),
        connectivity.astype(np.int64),
        state.time,
    )
    data = grid.GetCellData()
    for name, values in (
        ("Pressure", state.pressure),
        ("PeriodicPressure", state.periodic_pressure),
        ("Pcondition", state.imposed.astype(np.int32)),
        ("FluidVolume", state.fluid_volume),
        ("Volume", state.volume),
        ("id", np.arange(n, dtype=np.int32)),
    ):
        data.AddArray(output.vtk_array(np.asarray(values), name))
    data.SetActiveScalars("Pressure")
    return grid


def sphere_grid(state: PeriodicState) -> Any:
    n = len(state.ids)
    grid = output.unstructured_grid(
        state.centres,
        np.full(n, VTK_VERTEX, dtype=np.uint8),
        np.arange(n + 1, dtype=np.int64),
        np.arange(n, dtype=np.int64),
        state.time,
    )
    data = grid.GetPointData()
    data.AddArray(output.vtk_array(state.radii, "radii"))
    data.AddArray(output.vtk_array(state.ids, "id"))
    data.AddArray(output.vtk_array(state.forces, "fluidForce"))
    data.SetActiveScalars("radii")
    field = grid.GetFieldData()
    field.AddArray(output.vtk_array(state.cell.T.ravel(), "cellVectors"))  # the first vector, then the second, ...
    field.AddArray(output.vtk_array(state.gradient, "gradP"))
    return grid


def save(state: PeriodicState, folder: str, compress: bool) -> list[str]:
    grids = [("pores", "out", pore_grid(state)), ("spheres", "spheres", sphere_grid(state))]
    return output.save_grids(folder, state.time, grids, compress)
