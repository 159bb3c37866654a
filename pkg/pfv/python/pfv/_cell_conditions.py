"""Conditions on the pore cells of a pfv.FlowEngine, a part of the engine: YADE's point conditions
(imposePressure, imposeFlux: they follow their point through remeshes) and its conditions on single
cells (imposed or set pressures, blocked cells: cleared by a remesh, which renumbers the cells).

A condition takes effect at the next step (a new linear system where the set of unknowns changes);
the cell velocities kept by ``_flow_queries`` are dropped at once.
"""
from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from . import _attributes as attributes
from ._cell_geometry import CellGeometry
from ._flow_queries import FlowQueries


class CellConditions:
    """The point and cell conditions of the engine whose pfv.Engine is `core`, whose cells are `geometry`
    and whose flow queries are `flow`."""

    def __init__(self, core: Any, geometry: CellGeometry, flow: FlowQueries) -> None:
        self._core = core
        self._geometry = geometry
        self._flow = flow

    # -- boundary and point conditions ------------------------------------------------------------
    def updateBCs(self) -> None:
        """Apply changed boundary values and types (PFV applies values at every step anyway)."""
        self._core.request_system_rebuild()

    def imposePressure(self, pos: Sequence[float], p: float) -> int:
        """Impose pressure p in the cell containing pos; returns the condition's index. A point
        outside the pore space is refused (at once once there is a mesh, else at the first step)."""
        return self._core.impose_pressure(
            attributes.as_point("imposePressure position", pos), attributes.as_number("imposePressure pressure", p)
        )

    def setImposedPressure(self, cond: int, p: float) -> None:
        """Change the pressure of the imposed condition number cond."""
        cond = attributes.as_index("setImposedPressure cond", cond)
        self._core.set_imposed_pressure(cond, attributes.as_number("setImposedPressure pressure", p))

    def clearImposedPressure(self) -> None:
        self._core.clear_imposed_pressure()

    def imposeFlux(self, pos: Sequence[float], p: float) -> None:
        """YADE's sign: outflux positive, influx negative. A point outside the pore space is refused."""
        self._core.impose_flux(
            attributes.as_point("imposeFlux position", pos), -attributes.as_number("imposeFlux flux", p)
        )

    def clearImposedFlux(self) -> None:
        self._core.clear_imposed_flux()

    # -- conditions on single cells -------------------------------------------------------------------
    def getCellPImposed(self, id: int) -> bool:
        """Whether the cell's pressure is imposed: set on the cell, or by a pressure wall or an imposed point."""
        return self._core.cell_imposed(self._geometry.cell(id))

    def setCellPImposed(self, id: int, pImposed: bool) -> None:
        """Impose the cell's pressure at the value it holds (setCellPressure), or free it (an unknown even
        where a boundary would impose it). Until the next remesh; rebuilds the linear system at the next step."""
        self._flow.forget_velocities()
        self._core.set_cell_imposed(self._geometry.cell(id), attributes.as_flag("pImposed", pImposed))

    def setCellPressure(self, id: int, pressure: float) -> None:
        """Set the pressure the cell holds: what an imposed cell keeps (a pressure wall or imposed point applies
        its own value at the next step; the next solve overwrites an unknown)."""
        self._flow.forget_velocities()
        cell = self._geometry.cell(id)
        self._core.set_cell_pressure(cell, attributes.as_number("setCellPressure pressure", pressure))

    def blockCell(self, id: int, blockPressure: bool) -> None:
        """Cut the cell out of the flow problem until the next remesh: no flux through its throats, its
        pressure kept as it is, or set to 0 (and reported imposed) with blockPressure. Rebuilds the linear
        system at the next step (YADE: at the next remesh, or at once from blockHook)."""
        self._flow.forget_velocities()
        self._core.block_cell(self._geometry.cell(id), attributes.as_flag("blockPressure", blockPressure))

    def imposePressureFromId(self, id: int, p: float) -> int:
        """imposePressure at the cell's barycentre (which lies inside it): after a remesh the condition holds
        for the new cell there. Returns the condition's index."""
        return self.imposePressure(self._geometry.getCellBarycenter(id), p)

    def resetLinearSystem(self) -> None:
        """Rebuild the linear system at the next step, on the same triangulation."""
        self._core.request_system_rebuild()
