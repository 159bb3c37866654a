"""YADE's FlowEngine members that work on single pore cells, as a mixin of ``pfv.FlowEngine``.

Cells are named by the core's cell index, 0 .. nCells() - 1, valid until the next remesh (YADE's
rule): a remesh renumbers the cells and clears what was set on single cells (imposed pressures,
blocked cells). Vertices are named by YADE body id: a sphere by its id, a wall by its entry of
wallIds. Every query waits for a step in progress (the engine's lock) and raises RuntimeError before
the first step; a cell index out of range raises IndexError. Nothing here runs during a step.
"""
from __future__ import annotations

import functools
import math
import numbers
from typing import Any

from yade.minieigenHP import Vector3

from . import _attributes as attributes

# Python-side state of the mixin (plain instance attributes, not YADE attributes).
CELL_INTERNAL = frozenset({
    "_ini_void_volumes",  # iniVoidVolumes
})


def _locked(method):
    """Run `method` under the engine's lock (as flow_engine._exclusive)."""
    @functools.wraps(method)
    def locked(self, *args, **kwargs):
        with self._lock:
            return method(self, *args, **kwargs)
    return locked


def _index(name: str, value: Any) -> int:
    """An integer index (a bool or a float is refused, as YADE's converters refuse them)."""
    if isinstance(value, (bool, float)) or not isinstance(value, numbers.Integral):
        raise TypeError(f"{name} must be an integer, got {value!r}")
    return int(value)


class CellInterface:
    """The cell methods of YADE's FlowEngine (mixed into pfv.FlowEngine)."""

    _ini_void_volumes = False

    # -- attributes ------------------------------------------------------------------------
    @property
    def iniVoidVolumes(self) -> bool:
        """YADE's iniVoidVolumes: getCellInvVoidVolume gives 1 / V_void (else 0 unless fluidBulkModulus > 0)."""
        return self._ini_void_volumes

    @iniVoidVolumes.setter
    def iniVoidVolumes(self, value: bool) -> None:
        if not isinstance(value, numbers.Integral):
            raise TypeError(f"iniVoidVolumes must be a bool, got {value!r}")
        object.__setattr__(self, "_ini_void_volumes", bool(value))

    # -- helpers ---------------------------------------------------------------------------
    def _cell(self, id: Any) -> int:
        """A cell index of the current mesh: RuntimeError before the first step, IndexError out of range."""
        self._require_mesh()
        cell = _index("cell id", id)
        n = self._core.n_cells()
        if not 0 <= cell < n:
            raise IndexError(f"no pore cell with id {cell} (the mesh has {n} cells)")
        return cell

    def _body_of_vertex(self, vertex: int) -> int:
        """YADE body id of a core vertex: a sphere's id, or wallIds[w] for wall w."""
        ids = self._stepped.ids
        return int(ids[vertex]) if vertex < len(ids) else int(self._stepped.wall_ids[vertex - len(ids)])

    # -- geometry and topology ---------------------------------------------------------------
    @_locked
    def getCellBarycenter(self, id: int) -> Vector3:
        """Mean of the cell's four vertices at the last step's positions. A wall vertex counts as the
        point of the wall nearest the mean of the cell's sphere centres (YADE averages the centres
        of its fictitious wall spheres, far outside the sample)."""
        return Vector3(*self._core.cell_barycenter(self._cell(id)))

    @_locked
    def getVertices(self, id: int) -> list[int]:
        """The body ids of the cell's four vertices (spheres, and walls as their wallIds entry)."""
        return [self._body_of_vertex(v) for v in self._core.cell_vertex_indices(self._cell(id))]

    @_locked
    def getNeighbors(self, id: int) -> list[int]:
        """The pore cells sharing a facet with the cell (up to four)."""
        return self._core.cell_neighbours(self._cell(id))

    @_locked
    def isCellNeighbor(self, cell1_ID: int, cell2_ID: int) -> bool:
        """Whether the two cells share a facet."""
        other = self._cell(cell2_ID)
        return other in self._core.cell_neighbours(self._cell(cell1_ID))

    # -- volumes -------------------------------------------------------------------------------
    @_locked
    def getCellInvVoidVolume(self, id: int) -> float:
        """1 / the cell's pore volume, with iniVoidVolumes or fluidBulkModulus > 0 (else 0, as YADE):
        V_f, at least minimumPorosity times V, measured at the remesh or the last initializeVolumes()."""
        cell = self._cell(id)
        if not (self._ini_void_volumes or self._core.fluid_bulk_modulus > 0):
            return 0.0
        volume = float(self._core.void_volumes()[cell])
        return 1.0 / volume if volume > 0 else math.inf

    # -- pressures and conditions on cells -------------------------------------------------------
    @_locked
    def getCellPImposed(self, id: int) -> bool:
        """Whether the cell's pressure is imposed: set on the cell, or by a pressure wall or an
        imposed point."""
        return self._core.cell_imposed(self._cell(id))

    @_locked
    def setCellPImposed(self, id: int, pImposed: bool) -> None:
        """Impose the cell's pressure at the value it holds (setCellPressure), or free it (an unknown
        even where a boundary would impose it). Until the next remesh; rebuilds the linear system
        at the next step."""
        if not isinstance(pImposed, numbers.Integral):
            raise TypeError(f"pImposed must be a bool, got {pImposed!r}")
        self._core.set_cell_imposed(self._cell(id), bool(pImposed))

    @_locked
    def setCellPressure(self, id: int, pressure: float) -> None:
        """Set the pressure the cell holds: what an imposed cell keeps (a pressure wall or imposed
        point applies its own value at the next step; the next solve overwrites an unknown)."""
        self._core.set_cell_pressure(self._cell(id), attributes.as_number("setCellPressure pressure", pressure))

    @_locked
    def getCellFluxFromId(self, id: int) -> float:
        """Flux leaving the cell through its throats plus its rate of volume change, at the last step
        (YADE's sign: negative where an imposed cell takes fluid in)."""
        return self._core.cell_flux(self._cell(id))

    @_locked
    def blockCell(self, id: int, blockPressure: bool) -> None:
        """Cut the cell out of the flow problem until the next remesh: no flux through its throats,
        its pressure kept as it is, or set to 0 (and reported imposed) with blockPressure. Rebuilds
        the linear system at the next step (YADE: at the next remesh, or at once from blockHook)."""
        if not isinstance(blockPressure, numbers.Integral):
            raise TypeError(f"blockPressure must be a bool, got {blockPressure!r}")
        self._core.block_cell(self._cell(id), bool(blockPressure))
