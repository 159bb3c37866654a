"""The pore mesh of a pfv.FlowEngine as YADE's members show it, a part of the engine: cells and their
vertices, neighbours and throats, and the volumes of cells and of the spheres' power cells.

Cells are named by the core's cell index, 0 .. nCells() - 1, valid until the next remesh (YADE's
rule): a remesh renumbers the cells. Vertices are named by YADE body id: a sphere by its id, a wall
by its entry of wallIds. Every member raises RuntimeError before the first step; a cell index out of
range raises IndexError. The other cell parts (``_flow_queries``, ``_cell_conditions``) find their
cells through ``cell`` and ``cell_at`` here.
"""
from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

import yade
from yade.minieigenHP import Vector3

from . import _attributes as attributes
from ._coupled_bodies import CoupledBodies
from ._run_history import RunHistory


class CellGeometry:
    """The cells, throats and volumes of the engine whose pfv.Engine is `core`, whose coupled bodies
    are `bodies` and whose step history is `history`."""

    def __init__(self, core: Any, bodies: CoupledBodies, history: RunHistory) -> None:
        self._core = core
        self._bodies = bodies
        self._history = history
        self._ini_void_volumes = False
        self._power_volumes = None  # (mesh key, volumes) of the last compTessVolumes: not saved

    @property
    def iniVoidVolumes(self) -> bool:
        """getCellInvVoidVolume gives 1 / V_void (else 0 unless fluidBulkModulus > 0), as YADE's iniVoidVolumes."""
        return self._ini_void_volumes

    @iniVoidVolumes.setter
    def iniVoidVolumes(self, value: bool) -> None:
        self._ini_void_volumes = attributes.as_flag("iniVoidVolumes", value)

    def saved(self) -> dict[str, Any]:
        return {"ini_void_volumes": self._ini_void_volumes}

    def restore(self, state: dict[str, Any]) -> None:
        self._ini_void_volumes = state["ini_void_volumes"]

    # -- cells by index and by position -------------------------------------------------------------
    def cell(self, id: Any) -> int:
        """A cell index of the current mesh: RuntimeError before the first step, IndexError out of range."""
        self._bodies.require_mesh()
        cell = attributes.as_index("cell id", id)
        n = self._core.n_cells()
        if not 0 <= cell < n:
            raise IndexError(f"no pore cell with id {cell} (the mesh has {n} cells)")
        return cell

    def cell_at(self, pos: Sequence[float]) -> int:
        """The cell containing pos: RuntimeError before the first step, ValueError outside the pore space."""
        self._bodies.require_mesh()
        cell = self._core.locate(attributes.as_point("position", pos))
        if cell < 0:
            raise ValueError(f"point {tuple(pos)} lies in no pore cell (outside the walls or the packing)")
        return cell

    def mesh_key(self) -> tuple:
        """Changes with every remesh and step: what results kept for queries are valid for."""
        return (self._core.mesh_id, self._history.last_step)

    def nCells(self) -> int:
        return self._core.n_cells()

    def getCell(self, X: float, Y: float, Z: float) -> int:
        self._bodies.require_mesh()
        return self._core.locate(attributes.as_point("getCell position", (X, Y, Z)))

    def getCellCenter(self, id: int) -> Vector3:
        return Vector3(*self._core.cell_center(attributes.as_index("getCellCenter id", id)))

    def getCellVolume(self, pos: Sequence[float]) -> float:
        return self._core.cell_volume(self.cell_at(pos))

    # -- read-only attributes ----------------------------------------------------------------------
    @property
    def porosity(self) -> float:
        """Porosity of the current mesh away from the walls: sum V_f / sum V over the cells that have no
        wall vertex and no neighbour with one (YADE: over the same region, one remesh late); 0 before
        the first step."""
        if not self._core.has_mesh():
            return 0.0
        walls = self._core.cell_vertices() >= self._core.n_spheres()
        neighbours = self._core.cell_neighbour_array()
        touching = walls.any(axis=1)
        near = touching | np.where(neighbours >= 0, touching[np.maximum(neighbours, 0)], False).any(axis=1)
        inner = ~near
        volume = self._core.cell_volumes()[inner].sum()
        return float(self._core.cell_fluid_volumes()[inner].sum() / volume) if volume > 0 else 0.0

    @property
    def epsVolMax(self) -> float:
        """Volumetric strain of the pore space over the last step: sum dV / sum V (YADE computes it only
        with defTolerance > 0, PFV whenever asked); 0 before the first step."""
        if not self._bodies.has_mesh() or self._history.last_step is None:
            return 0.0
        return float(self._core.volume_rate_total() * self._history.last_step[2] / self._core.cell_volumes().sum())

    # -- geometry and topology ---------------------------------------------------------------------
    def getCellBarycenter(self, id: int) -> Vector3:
        """Mean of the cell's four vertices at the last step's positions. A wall vertex counts as the
        point of the wall nearest the mean of the cell's sphere centres (YADE averages the centres of
        its fictitious wall spheres, far outside the sample)."""
        return Vector3(*self._core.cell_barycenter(self.cell(id)))

    def getVertices(self, id: int) -> list[int]:
        """The body ids of the cell's four vertices (spheres, and walls as their wallIds entry)."""
        return [self._bodies.body_of_vertex(v) for v in self._core.cell_vertex_indices(self.cell(id))]

    def getNeighbors(self, id: int) -> list[int]:
        """The pore cells sharing a facet with the cell (up to four)."""
        return self._core.cell_neighbours(self.cell(id))

    def isCellNeighbor(self, cell1_ID: int, cell2_ID: int) -> bool:
        """Whether the two cells share a facet."""
        other = self.cell(cell2_ID)
        return other in self._core.cell_neighbours(self.cell(cell1_ID))

    def getIncidentCells(self, vertexId: int) -> list[int]:
        """The cells of which the body (a sphere, or a wall by its wallIds entry) is a vertex, by index."""
        vertex = self._bodies.vertex_of(attributes.as_index("vertexId", vertexId))
        return np.nonzero((self._core.cell_vertices() == vertex).any(axis=1))[0].tolist()

    # -- throats -------------------------------------------------------------------------------------
    def getConductivity(self, cellId: int, throat: int) -> float:
        """Conductance k of the throat opposite local vertex `throat` (0..3, as getNeighbors' order before
        dropping missing cells): 0 towards no cell or through a blocked cell."""
        return self._core.throat_conductance(self.cell(cellId), attributes.as_index("throat", throat))

    def getDiffusionCoeff(self, cellId: int, throat: int) -> float:
        """Area of the throat's facet over the distance between the two cells' power centres (0 towards no
        cell): what YADE's method returns (its accessor, named fluidArea, gives the facet's whole area)."""
        return self._core.throat_diffusion(self.cell(cellId), attributes.as_index("throat", throat))

    def surfaceSolidThroatInPore(self, cellId: int, throatIndex: int) -> float:
        """Solid surface of the half throat in the cell (between the facet and the cell's power centre): the
        spherical triangles of its spheres, and its area on no-flux walls, at the last step's positions."""
        cell = self.cell(cellId)
        throat = attributes.as_index("throatIndex", throatIndex)
        return self._core.throat_solid_area(cell, throat, self._bodies.stepped.radii)

    def getConstrictions(self, all: bool = True) -> list[float]:
        """Inscribed radius of every throat between two cells (throat_constriction): with all, those touching
        a wall too, negative; else only those between spheres."""
        return [r for r, _ in self._constrictions(attributes.as_flag("all", all))]

    def getConstrictionsFull(self, all: bool = True) -> list[list[float]]:
        """As getConstrictions, as [cell1, cell2, radius, nx, ny, nz]: n is the throat's area vector, from
        cell2 towards cell1."""
        found = self._constrictions(attributes.as_flag("all", all), full=True)
        return [[int(a), int(b), r, *n] for r, (a, b, n) in found]

    def _constrictions(self, all: bool, full: bool = False) -> list:
        self._bodies.require_mesh()
        d = self._core.constrictions(self._bodies.stepped.radii)
        radius = np.where(d["wall"].astype(bool), -d["radius"], d["radius"])
        keep = radius != 0 if all else radius > 0
        if full:
            keep &= np.any(d["normal"] != 0, axis=1)
        idx = np.nonzero(keep)[0]
        if not full:
            return [(float(radius[i]), None) for i in idx]
        a, b = d["cells"]
        return [(float(radius[i]), (a[i], b[i], d["normal"][i].tolist())) for i in idx]

    # -- volumes --------------------------------------------------------------------------------------
    def getCellInvVoidVolume(self, id: int) -> float:
        """1 / the cell's pore volume, with iniVoidVolumes or fluidBulkModulus > 0 (else 0, as YADE): V_f, at
        least minimumPorosity times V, measured at the remesh or the last initializeVolumes()."""
        cell = self.cell(id)
        if not (self._ini_void_volumes or self._core.fluid_bulk_modulus > 0):
            return 0.0
        volume = float(self._core.void_volumes()[cell])
        return 1.0 / volume if volume > 0 else math.inf

    def initializeVolumes(self) -> None:
        """Measure the cells' pore volumes again at the current positions (getCellInvVoidVolume, the
        compressible storage); the next step has no dV/dt term (YADE's: a zero volume change)."""
        self._bodies.require_mesh()
        self._core.initialize_volumes(*self._bodies.positions_now())

    def updateVolumes(self) -> None:
        """Measure the rates of volume change from the last step's positions to the current ones over O.dt
        (getCellFluxFromId, getBoundaryFlux); the current positions become the reference of the next step."""
        self._bodies.require_mesh()
        pos, walls = self._bodies.positions_now()
        self._core.update_volumes(pos, walls, yade.O.dt)

    def compTessVolumes(self) -> None:
        """Compute the volumes of the spheres' power (Voronoi) cells at the last step's positions (volume())."""
        self._bodies.require_mesh()
        volumes, _ = self._core.power_cell_volumes(self._bodies.stepped.radii)
        self._power_volumes = (self.mesh_key(), volumes)

    def volume(self, id: int = 0) -> float:
        """Volume of the power (Voronoi) cell of sphere `id`, bounded by the walls (computed by
        compTessVolumes() when needed); 0 for a wall."""
        self._bodies.require_mesh()
        vertex = self._bodies.vertex_of(attributes.as_index("id", id))
        if vertex >= len(self._bodies.stepped.ids):
            return 0.0
        if self._power_volumes is None or self._power_volumes[0] != self.mesh_key():
            self.compTessVolumes()
        return float(self._power_volumes[1][vertex])
