"""The flow solution of a pfv.FlowEngine as YADE's members show it, a part of the engine: pore
pressures, fluxes through cells and boundaries, cell velocities and the fluid forces on the bodies.

Every query waits for a step in progress (the engine's lock) and raises RuntimeError before the
first step. Cells are found through ``_cell_geometry.CellGeometry``; YADE's cell velocities are
computed once per step or cell condition (``forget_velocities``) and kept for the queries between.
"""
from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from yade.minieigenHP import Vector3

from . import _attributes as attributes
from ._cell_geometry import CellGeometry
from ._coupled_bodies import CoupledBodies


class FlowQueries:
    """Pressures, fluxes, velocities and forces of the engine whose pfv.Engine is `core`, whose coupled
    bodies are `bodies` and whose cells are `geometry`."""

    def __init__(self, core: Any, bodies: CoupledBodies, geometry: CellGeometry) -> None:
        self._core = core
        self._bodies = bodies
        self._geometry = geometry
        self._cell_velocities = None  # (mesh key, velocities) of the last velocity query: not saved

    # -- pressures --------------------------------------------------------------------------------
    def getPorePressure(self, pos: Sequence[float]) -> float:
        return self._core.cell_pressure(self._geometry.cell_at(pos))

    def getCellPressure(self, id: int) -> float:
        return self._core.cell_pressure(attributes.as_index("getCellPressure id", id))

    def averagePressure(self) -> float:
        self._bodies.require_mesh()
        return self._core.average_pressure()

    def averageSlicePressure(self, posY: float, axis: int = 1) -> float:
        self._bodies.require_mesh()
        axis = attributes.as_index("averageSlicePressure axis", axis)
        return self._core.average_slice_pressure(axis, attributes.as_number("averageSlicePressure position", posY))

    def absolute_pressure(self, pos: Sequence[float]) -> float:
        """The pore pressure at pos with its hydrostatic part: getPorePressure(pos) + fluid_density g.(pos - top),
        `top` the centre of the wall that faces up (against gravity's largest component). Equals the
        excess pressure without buoyancy (fluid_density = 0)."""
        p = self._core.cell_pressure(self._geometry.cell_at(pos))
        rho = self._core.fluid_density
        if rho == 0:
            return p
        g = np.array(self._core.gravity)
        walls = self._core.walls()
        top = np.array([(walls[0] + walls[1]) / 2, (walls[2] + walls[3]) / 2, (walls[4] + walls[5]) / 2])
        axis = int(np.abs(g).argmax())
        top[axis] = walls[2 * axis + 1] if g[axis] < 0 else walls[2 * axis]
        return p + rho * float(g @ (np.asarray(attributes.as_point("position", pos)) - top))

    # -- fluxes -----------------------------------------------------------------------------------
    def getCellFluxFromId(self, id: int) -> float:
        """Flux leaving the cell through its throats plus its rate of volume change, at the last step (YADE's
        sign: negative where an imposed cell takes fluid in)."""
        return self._core.cell_flux(self._geometry.cell(id))

    def getCellFlux(self, cond: int) -> float:
        """getCellFluxFromId of the cell of imposed pressure number `cond` (imposePressure's index)."""
        self._bodies.require_mesh()
        cell = self._core.imposed_pressure_cell(attributes.as_index("cond", cond))
        if cell < 0:
            raise ValueError(f"imposed pressure {cond} lies in no pore cell of the current mesh")
        return self._core.cell_flux(cell)

    def getBoundaryFlux(self, boundary: int) -> float:
        return self._core.boundary_flux(self._bodies.wall_index(boundary))  # the wallIds of the last step

    def _boundary_throats(self, boundary: Any) -> tuple[np.ndarray, np.ndarray]:
        """The cells touching the wall `boundary` (a body id) and their throats (cell, local) to cells that
        touch no wall, as YADE's boundary queries take them."""
        wall = self._bodies.wall_index(boundary)
        n = self._core.n_spheres()
        cv = self._core.cell_vertices()
        neighbours = self._core.cell_neighbour_array()
        touches = (cv >= n).any(axis=1)
        on_wall = np.nonzero((cv == n + wall).any(axis=1))[0]
        pairs = [
            (c, local)
            for c in on_wall
            for local in range(4)
            if neighbours[c, local] >= 0 and not touches[neighbours[c, local]]
        ]
        cells = np.array([c for c, _ in pairs], dtype=int)
        areas = np.array([self._throat_fluid_area(c, local) for c, local in pairs])
        return cells, areas

    def _throat_fluid_area(self, cell: int, local: int) -> float:
        return self._core.throat_fluid_area(cell, local)

    def getBoundaryFluidArea(self, boundary: int) -> float:
        """Fluid area of the throats from the cells touching the boundary (a body id) to cells that touch no
        wall: where the boundary layer of cells meets the interior."""
        return float(self._boundary_throats(boundary)[1].sum())

    def getBoundaryVel(self, boundary: int) -> list[list[float]]:
        """[vx, vy, vz, area] per throat of getBoundaryFluidArea: the velocity (getCellVelocity) of its cell on
        the boundary and the throat's fluid area."""
        cells, areas = self._boundary_throats(boundary)
        v = self._yade_velocities()
        return [[*v[c].tolist(), float(a)] for c, a in zip(cells, areas)]

    def getBoundaryVolume(self, boundary: int, dt: float) -> float:
        """Fluid volume entering the sample through the boundary in time dt: -getBoundaryFlux(boundary) dt."""
        return -self.getBoundaryFlux(boundary) * attributes.as_number("getBoundaryVolume dt", dt)

    # -- velocities -------------------------------------------------------------------------------
    def getCellVelocity(self, pos: Sequence[float]) -> list[float]:
        """YADE's velocity of the cell at pos: sum over its throats of q (X - P) / V, q the flux leaving through
        the throat, X where the line of the two cells' centres pierces the facet, P the cell's centre, V its
        volume (the mean fluid velocity times the cell's porosity; cell_velocity.hpp). YADE updates it only in
        averageVelocity, avFlVelOnSph and saveVtk (before, it reads 0); PFV at every call."""
        cell = self._geometry.cell_at(pos)
        return self._yade_velocities()[cell].tolist()

    def averageVelocity(self) -> Vector3:
        """Volume mean of the cells' velocities (getCellVelocity) over the sample: the Darcy velocity, flux
        over cross-section along a permeameter."""
        self._bodies.require_mesh()
        volume = self._core.cell_volumes()
        return Vector3(*((self._yade_velocities() * volume[:, None]).sum(axis=0) / volume.sum()))

    def avFlVelOnSph(self, idSph: int) -> list[float]:
        """Volume mean of the velocities of the cells around sphere idSph that touch no wall (nan if none)."""
        vertex = self._bodies.vertex_of(attributes.as_index("idSph", idSph))
        cv = self._core.cell_vertices()
        cells = (cv == vertex).any(axis=1) & ~(cv >= self._core.n_spheres()).any(axis=1)
        volume = self._core.cell_volumes()[cells]
        if not volume.sum() > 0:
            return [math.nan] * 3
        return ((self._yade_velocities()[cells] * volume[:, None]).sum(axis=0) / volume.sum()).tolist()

    def _yade_velocities(self) -> np.ndarray:
        """YADE's cell velocities: sum over the throats of q (x_throat - x_cell) / V (total volume),
        from the core's mean fluid velocities (per fluid volume). Kept until the next step or cell
        condition, so that a script asking cell by cell pays for one evaluation, not one per cell."""
        key = self._geometry.mesh_key()
        if self._cell_velocities is None or self._cell_velocities[0] != key:
            volume = self._core.cell_volumes()
            fluid = self._core.cell_fluid_volumes()
            share = np.divide(fluid, volume, out=np.zeros_like(volume), where=volume > 0)
            velocities = self._core.cell_velocities() * share[:, None]
            velocities.flags.writeable = False  # shared by every query until the key changes
            self._cell_velocities = (key, velocities)
        return self._cell_velocities[1]

    def forget_velocities(self) -> None:
        """A cell condition changed: the velocities kept are stale."""
        self._cell_velocities = None

    # -- forces and the solver ----------------------------------------------------------------------
    def fluidForce(self, idSph: int) -> Vector3:
        return Vector3(*self._core.forces()[self._bodies.vertex_of(idSph)])

    def shearLubForce(self, idSph: int) -> Vector3:
        """The viscous shear part of fluidForce(idSph) (viscousShear; zero while it is off).
        YADE's name: its shearLubForce reports the viscousShear force as well."""
        v = self._bodies.vertex_of(idSph)
        shear = self._core.shear_forces()
        return Vector3(*shear[v]) if len(shear) else Vector3(0, 0, 0)

    def metisUsed(self) -> bool:
        return self._core.metis_used()
