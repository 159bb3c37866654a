"""YADE's FlowEngine members that work on single pore cells, as a mixin of ``pfv.FlowEngine``.

Cells are named by the core's cell index, 0 .. nCells() - 1, valid until the next remesh (YADE's
rule): a remesh renumbers the cells and clears what was set on single cells (imposed pressures,
blocked cells). Vertices are named by YADE body id: a sphere by its id, a wall by its entry of
wallIds. Every query waits for a step in progress (the engine's lock) and raises RuntimeError before
the first step; a cell index out of range raises IndexError. Nothing here runs during a step of a
script that does not use it: the step consults a few flags (pressureForce, decoupleForces,
blockHook, the reports) and nothing else.

Also here: the YADE attributes that change what a step does or reports (decoupleForces,
pressureForce, blockHook, debug, getCHOLMODPerfTimings, meanKStat), those read off the mesh
(porosity, epsVolMax), those of the scene scan (mask, convertClumps, wallThickness, idOffset), and
YADE's file outputs (exportMatrix, exportTriplets, printVertices, pressureProfile).
"""
from __future__ import annotations

import math
import numbers
import sys
from collections.abc import Sequence
from typing import Any

import numpy as np

import yade
from yade.minieigenHP import Vector3

from . import _attributes as attributes
from ._locking import exclusive

# Python-side state of the mixin (plain instance attributes, not YADE attributes).
CELL_INTERNAL = frozenset({
    "_ini_void_volumes",     # iniVoidVolumes
    "_decouple_forces",      # decoupleForces
    "_pressure_force",       # pressureForce
    "_block_hook",           # blockHook
    "_debug",                # debug
    "_perf_timings",         # getCHOLMODPerfTimings
    "_mean_k_stat",          # meanKStat
    "_after_step_reports",   # any of the reports above (or a blockHook) is on
    "_permeability_map",     # permeabilityMap
    "_solve_threads",        # numSolveThreads
    "_factorize_threads",    # numFactorizeThreads
    "_boundary_velocity",    # boundaryVelocity
    "_boundary_x_pos",       # boundaryXPos
    "_boundary_pressure",    # boundaryPressure
    "_ids",                  # ids
    "_mask",                 # mask
    "_convert_clumps",       # convertClumps
    "_wall_thickness",       # wallThickness
    "_id_offset",            # idOffset
    "_volume_factor",        # volumeFactor
    "_desired_porosity",     # desiredPorosity
    "_power_volumes",        # (mesh key, volumes) of the last compTessVolumes
    "_cell_velocities",      # (mesh key, velocities) of the last velocity query
})

# Results kept for queries on the same mesh and step: not settings, not saved.
CELL_CACHES = frozenset({"_power_volumes", "_cell_velocities"})

# YADE's boundary normals (setBoundaryNormal), pointing into the sample.
_NORMALS = ((1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1))


def _index(name: str, value: Any) -> int:
    """An integer index (a bool or a float is refused, as YADE's converters refuse them)."""
    if isinstance(value, (bool, float)) or not isinstance(value, numbers.Integral):
        raise TypeError(f"{name} must be an integer, got {value!r}")
    return int(value)


def _flag(name: str, value: Any) -> bool:
    if not isinstance(value, (numbers.Integral, np.bool_)):
        raise TypeError(f"{name} must be a bool, got {value!r}")
    return bool(value)


def _numbers(name: str, value: Any) -> list[float]:
    if isinstance(value, (str, bytes)) or not isinstance(value, Sequence | np.ndarray):
        raise TypeError(f"{name} must be a sequence of numbers, got {value!r}")
    return [attributes.as_number(f"{name}[{i}]", v) for i, v in enumerate(value)]


def _flag_property(slot: str, name: str, doc: str, on_change: str | None = None) -> property:
    """A bool attribute kept in `slot`; `on_change` names a method to call after a change."""
    def get(self) -> bool:
        return getattr(self, slot)

    def set_(self, value: bool) -> None:
        object.__setattr__(self, slot, _flag(name, value))
        if on_change:
            getattr(self, on_change)()
    return property(get, set_, doc=doc)


def _read_only(name: str, getter) -> property:
    def set_(self, value: Any) -> None:
        raise AttributeError(f"{name} is read-only (computed by the engine)")
    return property(getter, set_, doc=getter.__doc__)


class CellInterface:
    """The cell methods of YADE's FlowEngine and the attributes listed in the module docstring
    (mixed into pfv.FlowEngine)."""

    _ini_void_volumes = False
    _decouple_forces = False
    _pressure_force = True
    _block_hook = ""
    _debug = False
    _perf_timings = False
    _mean_k_stat = False
    _after_step_reports = False
    _permeability_map = False
    _solve_threads = 1
    _factorize_threads = 1
    _boundary_velocity = ((0.0, 0.0, 0.0),) * 6
    _boundary_x_pos: tuple[float, ...] = ()
    _boundary_pressure: tuple[float, ...] = ()
    _ids: tuple[int, ...] = ()
    _mask = 0
    _convert_clumps = True
    _wall_thickness = 0.0
    _id_offset = 0
    _volume_factor = 1.0
    _desired_porosity = 0.0
    _power_volumes = None
    _cell_velocities = None

    # -- attributes: what a step does and reports --------------------------------------------
    iniVoidVolumes = _flag_property(
        "_ini_void_volumes", "iniVoidVolumes",
        "getCellInvVoidVolume gives 1 / V_void (else 0 unless fluidBulkModulus > 0), as YADE's iniVoidVolumes.")
    decoupleForces = _flag_property(
        "_decouple_forces", "decoupleForces",
        "The fluid forces are computed (fluidForce) but not applied to the bodies.")
    pressureForce = _flag_property(
        "_pressure_force", "pressureForce",
        "False: the engine computes no flow at all (its step does nothing; the next step after it is on again "
        "has no dV/dt term).")
    debug = _flag_property("_debug", "debug", "Print one line per step: remesh, system, cells, solve.",
                           "_update_reports")
    getCHOLMODPerfTimings = _flag_property(
        "_perf_timings", "getCHOLMODPerfTimings",
        "Print the times to build, analyse and factorise each new linear system.", "_update_reports")
    meanKStat = _flag_property(
        "_mean_k_stat", "meanKStat",
        "Print, at each remesh, how many throat conductances the clamp (clampKValues) changed.", "_update_reports")
    permeabilityMap = _flag_property(
        "_permeability_map", "permeabilityMap",
        "Accepted for YADE's scripts: YADE keeps a per-cell permeability for its VTK output with it; PFV's step "
        "does not change.")
    convertClumps = _flag_property(
        "_convert_clumps", "convertClumps",
        "True (YADE's default): a clump enters the triangulation as the sphere of its members' volume at its "
        "centre of mass and its fluid force goes to the clump; False: its spherical members are coupled as "
        "spheres of their own and the clump is left out (YADE's NewtonIntegrator sums their forces).",
        "_bodies_changed")

    @property
    def blockHook(self) -> str:
        """Python code run in __main__ at each remesh, after the new mesh is built and before its linear
        system: the place for blockCell and other conditions on the new cells (a background remesh, with
        multithread, runs it after the new mesh is adopted: its conditions apply from the next step)."""
        return self._block_hook

    @blockHook.setter
    def blockHook(self, value: str) -> None:
        if not isinstance(value, str):
            raise TypeError(f"blockHook must be a string (Python code), got {value!r}")
        if value.strip():
            compile(value, "blockHook", "exec")  # a syntax error now, not at the next remesh
        object.__setattr__(self, "_block_hook", value)
        self._update_reports()

    def _update_reports(self) -> None:
        object.__setattr__(self, "_after_step_reports",
                           bool(self._debug or self._perf_timings or self._mean_k_stat or self._block_hook))

    @property
    def numSolveThreads(self) -> int:
        """Accepted for YADE's scripts (YADE's OpenBLAS threads of a solve); PFV's threads are ompThreads."""
        return self._solve_threads

    @numSolveThreads.setter
    def numSolveThreads(self, value: int) -> None:
        object.__setattr__(self, "_solve_threads", self._thread_count("numSolveThreads", value))

    @property
    def numFactorizeThreads(self) -> int:
        """Accepted for YADE's scripts (YADE's OpenBLAS threads of a factorisation); PFV's are ompThreads."""
        return self._factorize_threads

    @numFactorizeThreads.setter
    def numFactorizeThreads(self, value: int) -> None:
        object.__setattr__(self, "_factorize_threads", self._thread_count("numFactorizeThreads", value))

    @staticmethod
    def _thread_count(name: str, value: Any) -> int:
        value = _index(name, value)
        if value < 1:
            raise ValueError(f"{name} must be at least 1, got {value}")
        return value

    @property
    def boundaryVelocity(self) -> list[Vector3]:
        """Velocities of the six boundaries, kept for YADE's scripts: YADE's own shear term skips the
        sphere-wall pairs that would read them, and PFV's pairs no sphere with a wall either."""
        return [Vector3(*v) for v in self._boundary_velocity]

    @boundaryVelocity.setter
    def boundaryVelocity(self, value: Sequence[Any]) -> None:
        if isinstance(value, (str, bytes)) or len(value) != 6:
            raise ValueError("boundaryVelocity needs 6 vectors (xmin, xmax, ymin, ymax, zmin, zmax)")
        object.__setattr__(self, "_boundary_velocity",
                           tuple(attributes.as_point(f"boundaryVelocity[{w}]", v) for w, v in enumerate(value)))

    @property
    def boundaryXPos(self) -> list[float]:
        """x of the points of the pressure profile on ymax (see boundaryPressure)."""
        return list(self._boundary_x_pos)

    @boundaryXPos.setter
    def boundaryXPos(self, value: Sequence[float]) -> None:
        object.__setattr__(self, "_boundary_x_pos", tuple(_numbers("boundaryXPos", value)))
        self._push_profile()

    @property
    def boundaryPressure(self) -> list[float]:
        """Pressures along x on the ymax boundary, at boundaryXPos: while both lists have the same length
        (at least 2) the Dirichlet cells of ymax (bndCondIsPressure[ymax]) take the pressure interpolated
        at the x of their power centre, bndCondValue[ymax] beyond the points. Applies at the next step."""
        return list(self._boundary_pressure)

    @boundaryPressure.setter
    def boundaryPressure(self, value: Sequence[float]) -> None:
        object.__setattr__(self, "_boundary_pressure", tuple(_numbers("boundaryPressure", value)))
        self._push_profile()

    def _push_profile(self) -> None:
        xs, ps = list(self._boundary_x_pos), list(self._boundary_pressure)
        consistent = len(xs) == len(ps) and len(xs) >= 2
        with self._lock:
            self._core.pressure_profile = (3, 0, xs, ps) if consistent else (3, 0, [], [])

    @property
    def ids(self) -> list[int]:
        """PartialEngine's body list, kept for YADE's scripts (YADE's FlowEngine does not use it)."""
        return list(self._ids)

    @ids.setter
    def ids(self, value: Sequence[int]) -> None:
        object.__setattr__(self, "_ids", tuple(_index("ids entry", v) for v in value))

    @property
    def mask(self) -> int:
        """> 0: only spheres whose groupMask shares a bit with mask are coupled (at the next scan of the
        bodies, i.e. the next remesh)."""
        return self._mask

    @mask.setter
    def mask(self, value: int) -> None:
        object.__setattr__(self, "_mask", _index("mask", value))
        self._bodies_changed()

    @property
    def wallThickness(self) -> float:
        """> 0: a wall body named in wallIds (without boundaryUseMaxMin) bounds the domain at half this
        thickness from its centre, towards the sample (YADE's rule); 0: at a box wall's inner face."""
        return self._wall_thickness

    @wallThickness.setter
    def wallThickness(self, value: float) -> None:
        value = attributes.as_number("wallThickness", value)
        if value < 0:
            raise ValueError(f"wallThickness must be >= 0, got {value}")
        object.__setattr__(self, "_wall_thickness", value)
        self._bodies_changed()

    @property
    def idOffset(self) -> int:
        """YADE's id offset of the walls. Set < 0: at the next scan of the bodies it becomes len(O.bodies)
        and wallIds becomes idOffset + (0 .. 5), walls that are not bodies (with boundaryUseMaxMin)."""
        return self._id_offset

    @idOffset.setter
    def idOffset(self, value: int) -> None:
        object.__setattr__(self, "_id_offset", _index("idOffset", value))
        if self._id_offset < 0:
            self._bodies_changed()

    def _apply_id_offset(self) -> None:
        """At a scan: a negative idOffset becomes len(O.bodies), and wallIds follow (YADE's rule)."""
        if self._id_offset < 0:
            offset = len(yade.O.bodies)
            object.__setattr__(self, "_id_offset", offset)
            object.__setattr__(self, "_wall_ids", [offset + w for w in range(6)])

    @property
    def volumeFactor(self) -> float:
        """YADE's low-porosity factor for its thermal engine only (out of PFV's scope): kept, no effect."""
        return self._volume_factor

    @volumeFactor.setter
    def volumeFactor(self, value: float) -> None:
        value = attributes.as_number("volumeFactor", value)
        if value <= 0:
            raise ValueError(f"volumeFactor must be positive, got {value}")
        object.__setattr__(self, "_volume_factor", value)

    @property
    def desiredPorosity(self) -> float:
        """0: off. Else at each step volumeCorrection = desiredPorosity / the porosity of the spheres'
        bounding box (YADE's rule), which scales dV/dt of the cells without wall vertices."""
        return self._desired_porosity

    @desiredPorosity.setter
    def desiredPorosity(self, value: float) -> None:
        value = attributes.as_number("desiredPorosity", value)
        if not 0 <= value < 1:
            raise ValueError(f"desiredPorosity must be in [0, 1), got {value}")
        object.__setattr__(self, "_desired_porosity", value)

    def _correct_volumes(self, pos: np.ndarray, radii: np.ndarray) -> None:
        """desiredPorosity: volumeCorrection from the porosity of the spheres' bounding box."""
        low, high = (pos - radii[:, None]).min(axis=0), (pos + radii[:, None]).max(axis=0)
        box = float(np.prod(high - low))
        porosity = (box - 4.0 / 3.0 * math.pi * float(np.sum(radii ** 3))) / box
        if porosity > 0:
            self._core.volume_correction = self._desired_porosity / porosity

    def _scan_options(self) -> dict[str, Any]:
        return dict(mask=self._mask, convert_clumps=self._convert_clumps, wall_thickness=self._wall_thickness)

    def _bodies_changed(self) -> None:
        """The bodies must be scanned again at the next step (which remeshes)."""
        if self._scan is not None:
            self._scan.outdated = True
        self._core.reset_history()

    # -- read-only attributes ----------------------------------------------------------------------
    def _porosity(self) -> float:
        """Porosity of the current mesh away from the walls: sum V_f / sum V over the cells that have no
        wall vertex and no neighbour with one (YADE: over the same region, one remesh late); 0 before
        the first step."""
        with self._lock:
            if not self._core.has_mesh():
                return 0.0
            walls = self._core.cell_vertices() >= self._core.n_spheres()
            neighbours = self._core.cell_neighbour_array()
            touching = walls.any(axis=1)
            near = touching | np.where(neighbours >= 0, touching[np.maximum(neighbours, 0)], False).any(axis=1)
            inner = ~near
            volume = self._core.cell_volumes()[inner].sum()
            return float(self._core.cell_fluid_volumes()[inner].sum() / volume) if volume > 0 else 0.0

    porosity = _read_only("porosity", _porosity)

    def _eps_vol_max(self) -> float:
        """Volumetric strain of the pore space over the last step: sum dV / sum V (YADE computes it only
        with defTolerance > 0, PFV whenever asked); 0 before the first step."""
        with self._lock:
            if not self._core.has_mesh() or self._stepped is None or self._last_step is None:
                return 0.0
            return float(self._core.volume_rate_total() * self._last_step[2] / self._core.cell_volumes().sum())

    epsVolMax = _read_only("epsVolMax", _eps_vol_max)

    # -- helpers ---------------------------------------------------------------------------------
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

    def _wall_index(self, boundary: Any) -> int:
        """The wall (0..5) of a boundary named by body id, as getBoundaryFlux takes it."""
        self._require_mesh()
        wall_ids = self._stepped.wall_ids
        boundary = _index("boundary", boundary)
        if boundary not in wall_ids:
            raise ValueError(f"body {boundary} is not one of the boundaries wallIds = {wall_ids}")
        return wall_ids.index(boundary)

    def _yade_velocities(self) -> np.ndarray:
        """YADE's cell velocities: sum over the throats of q (x_throat - x_cell) / V (total volume),
        from the core's mean fluid velocities (per fluid volume). Kept until the next step or cell
        condition, so that a script asking cell by cell pays for one evaluation, not one per cell."""
        key = self._mesh_key()
        if self._cell_velocities is None or self._cell_velocities[0] != key:
            volume = self._core.cell_volumes()
            fluid = self._core.cell_fluid_volumes()
            share = np.divide(fluid, volume, out=np.zeros_like(volume), where=volume > 0)
            velocities = self._core.cell_velocities() * share[:, None]
            velocities.flags.writeable = False  # shared by every query until the key changes
            object.__setattr__(self, "_cell_velocities", (key, velocities))
        return self._cell_velocities[1]

    def _pressures_changed(self) -> None:
        object.__setattr__(self, "_cell_velocities", None)

    def _mesh_key(self) -> tuple:
        return (self._core.remesh_count, self._last_step)

    # -- the step's extras ---------------------------------------------------------------------------
    def _remesh_for_block_hook(self, pos: np.ndarray, scan: Any, walls: list[float]) -> None:
        """Remesh without a linear system, run blockHook on the new cells, let the step build the system."""
        self._core.remesh(pos, scan.radii, walls)
        self._stepped = scan
        self._run_block_hook()

    def _run_block_hook(self) -> None:
        import __main__
        exec(compile(self._block_hook, "blockHook", "exec"), vars(__main__))

    def _report_step(self, before: tuple[int, int]) -> None:
        """After a step: blockHook for a background remesh, and the reports that are on."""
        core = self._core
        remeshed = core.remesh_count != before[0]
        if remeshed and self._block_hook and core.background_remesh:
            self._run_block_hook()
        if self._perf_timings and core.system_builds != before[1]:
            t = core.system_times()
            print(f"CHOLMOD Time to build linear equations {round(t['assembly'] * 1e6)}\n"
                  f"CHOLMOD Time to analyze {round(t['analysis'] * 1e6)}\n"
                  f"CHOLMOD Time to factorize {round(t['factorization'] * 1e6)}  (microseconds, pfv)")
        if self._mean_k_stat and remeshed:
            k = core.conductances()
            k = k[k > 0]
            if len(k):
                median = float(np.median(k))
                low, high = core.min_k_div_k_mean * median, core.max_k_div_k_mean * median
                print(f"meanKStat (pfv): median k {median:.6g}; {int(np.sum(np.isclose(k, low)))} throats at "
                      f"minKdivKmean x median, {int(np.sum(np.isclose(k, high)))} at maxKdivKmean x median"
                      + ("" if core.clamp_k_values else " (clampKValues off)"))
        if self._debug:
            print(f"pfv.FlowEngine: iter {yade.O.iter}: {'remeshed, ' if remeshed else ''}"
                  f"{'new system, ' if core.system_builds != before[1] else ''}{core.n_cells()} cells, "
                  f"solve {core.step_times()['solve']:.3g} s")

    # -- geometry and topology ---------------------------------------------------------------------
    @exclusive
    def getCellBarycenter(self, id: int) -> Vector3:
        """Mean of the cell's four vertices at the last step's positions. A wall vertex counts as the
        point of the wall nearest the mean of the cell's sphere centres (YADE averages the centres of
        its fictitious wall spheres, far outside the sample)."""
        return Vector3(*self._core.cell_barycenter(self._cell(id)))

    @exclusive
    def getVertices(self, id: int) -> list[int]:
        """The body ids of the cell's four vertices (spheres, and walls as their wallIds entry)."""
        return [self._body_of_vertex(v) for v in self._core.cell_vertex_indices(self._cell(id))]

    @exclusive
    def getNeighbors(self, id: int) -> list[int]:
        """The pore cells sharing a facet with the cell (up to four)."""
        return self._core.cell_neighbours(self._cell(id))

    @exclusive
    def isCellNeighbor(self, cell1_ID: int, cell2_ID: int) -> bool:
        """Whether the two cells share a facet."""
        other = self._cell(cell2_ID)
        return other in self._core.cell_neighbours(self._cell(cell1_ID))

    @exclusive
    def getIncidentCells(self, vertexId: int) -> list[int]:
        """The cells of which the body (a sphere, or a wall by its wallIds entry) is a vertex, by index."""
        vertex = self._vertex_of(_index("vertexId", vertexId))
        return np.nonzero((self._core.cell_vertices() == vertex).any(axis=1))[0].tolist()

    # -- throats -------------------------------------------------------------------------------------
    @exclusive
    def getConductivity(self, cellId: int, throat: int) -> float:
        """Conductance k of the throat opposite local vertex `throat` (0..3, as getNeighbors' order before
        dropping missing cells): 0 towards no cell or through a blocked cell."""
        return self._core.throat_conductance(self._cell(cellId), _index("throat", throat))

    @exclusive
    def getDiffusionCoeff(self, cellId: int, throat: int) -> float:
        """Area of the throat's facet over the distance between the two cells' power centres (0 towards no
        cell): what YADE's method returns (its accessor, named fluidArea, gives the facet's whole area)."""
        return self._core.throat_diffusion(self._cell(cellId), _index("throat", throat))

    @exclusive
    def surfaceSolidThroatInPore(self, cellId: int, throatIndex: int) -> float:
        """Solid surface of the half throat in the cell (between the facet and the cell's power centre): the
        spherical triangles of its spheres, and its area on no-flux walls, at the last step's positions."""
        cell = self._cell(cellId)
        return self._core.throat_solid_area(cell, _index("throatIndex", throatIndex), self._stepped.radii)

    @exclusive
    def getConstrictions(self, all: bool = True) -> list[float]:
        """Inscribed radius of every throat between two cells (throat_constriction): with all, those touching
        a wall too, negative; else only those between spheres."""
        return [r for r, _ in self._constrictions(_flag("all", all))]

    @exclusive
    def getConstrictionsFull(self, all: bool = True) -> list[list[float]]:
        """As getConstrictions, as [cell1, cell2, radius, nx, ny, nz]: n is the throat's area vector, from
        cell2 towards cell1."""
        return [[int(a), int(b), r, *n] for r, (a, b, n) in self._constrictions(_flag("all", all), full=True)]

    def _constrictions(self, all: bool, full: bool = False) -> list:
        self._require_mesh()
        d = self._core.constrictions(self._stepped.radii)
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
    @exclusive
    def getCellInvVoidVolume(self, id: int) -> float:
        """1 / the cell's pore volume, with iniVoidVolumes or fluidBulkModulus > 0 (else 0, as YADE): V_f, at
        least minimumPorosity times V, measured at the remesh or the last initializeVolumes()."""
        cell = self._cell(id)
        if not (self._ini_void_volumes or self._core.fluid_bulk_modulus > 0):
            return 0.0
        volume = float(self._core.void_volumes()[cell])
        return 1.0 / volume if volume > 0 else math.inf

    def _positions_now(self) -> tuple[np.ndarray, list[float]]:
        read = self._stepped.read_positions(self._boundary_use_max_min)
        if read is None:
            raise RuntimeError("bodies were erased since the last step: run a step first")
        return read

    @exclusive
    def initializeVolumes(self) -> None:
        """Measure the cells' pore volumes again at the current positions (getCellInvVoidVolume, the
        compressible storage); the next step has no dV/dt term (YADE's: a zero volume change)."""
        self._require_mesh()
        self._core.initialize_volumes(*self._positions_now())

    @exclusive
    def updateVolumes(self) -> None:
        """Measure the rates of volume change from the last step's positions to the current ones over O.dt
        (getCellFluxFromId, getBoundaryFlux); the current positions become the reference of the next step."""
        self._require_mesh()
        pos, walls = self._positions_now()
        self._core.update_volumes(pos, walls, yade.O.dt)

    @exclusive
    def compTessVolumes(self) -> None:
        """Compute the volumes of the spheres' power (Voronoi) cells at the last step's positions (volume())."""
        self._require_mesh()
        volumes, _ = self._core.power_cell_volumes(self._stepped.radii)
        object.__setattr__(self, "_power_volumes", (self._mesh_key(), volumes))

    @exclusive
    def volume(self, id: int = 0) -> float:
        """Volume of the power (Voronoi) cell of sphere `id`, bounded by the walls (computed by
        compTessVolumes() when needed); 0 for a wall."""
        self._require_mesh()
        vertex = self._vertex_of(_index("id", id))
        if vertex >= len(self._stepped.ids):
            return 0.0
        if self._power_volumes is None or self._power_volumes[0] != self._mesh_key():
            self.compTessVolumes()
        return float(self._power_volumes[1][vertex])

    # -- pressures and conditions on cells ---------------------------------------------------------------
    @exclusive
    def getCellPImposed(self, id: int) -> bool:
        """Whether the cell's pressure is imposed: set on the cell, or by a pressure wall or an imposed point."""
        return self._core.cell_imposed(self._cell(id))

    @exclusive
    def setCellPImposed(self, id: int, pImposed: bool) -> None:
        """Impose the cell's pressure at the value it holds (setCellPressure), or free it (an unknown even
        where a boundary would impose it). Until the next remesh; rebuilds the linear system at the next step."""
        self._pressures_changed()
        self._core.set_cell_imposed(self._cell(id), _flag("pImposed", pImposed))

    @exclusive
    def setCellPressure(self, id: int, pressure: float) -> None:
        """Set the pressure the cell holds: what an imposed cell keeps (a pressure wall or imposed point applies
        its own value at the next step; the next solve overwrites an unknown)."""
        self._pressures_changed()
        self._core.set_cell_pressure(self._cell(id), attributes.as_number("setCellPressure pressure", pressure))

    @exclusive
    def blockCell(self, id: int, blockPressure: bool) -> None:
        """Cut the cell out of the flow problem until the next remesh: no flux through its throats, its
        pressure kept as it is, or set to 0 (and reported imposed) with blockPressure. Rebuilds the linear
        system at the next step (YADE: at the next remesh, or at once from blockHook)."""
        self._pressures_changed()
        self._core.block_cell(self._cell(id), _flag("blockPressure", blockPressure))

    @exclusive
    def imposePressureFromId(self, id: int, p: float) -> int:
        """imposePressure at the cell's barycentre (which lies inside it): after a remesh the condition holds
        for the new cell there. Returns the condition's index."""
        return self.imposePressure(self.getCellBarycenter(id), p)

    @exclusive
    def resetLinearSystem(self) -> None:
        """Rebuild the linear system at the next step, on the same triangulation."""
        self._core.request_system_rebuild()

    # -- fluxes and velocities -----------------------------------------------------------------------------
    @exclusive
    def getCellFluxFromId(self, id: int) -> float:
        """Flux leaving the cell through its throats plus its rate of volume change, at the last step (YADE's
        sign: negative where an imposed cell takes fluid in)."""
        return self._core.cell_flux(self._cell(id))

    @exclusive
    def getCellFlux(self, cond: int) -> float:
        """getCellFluxFromId of the cell of imposed pressure number `cond` (imposePressure's index)."""
        self._require_mesh()
        cell = self._core.imposed_pressure_cell(_index("cond", cond))
        if cell < 0:
            raise ValueError(f"imposed pressure {cond} lies in no pore cell of the current mesh")
        return self._core.cell_flux(cell)

    @exclusive
    def getCellVelocity(self, pos: Sequence[float]) -> list[float]:
        """YADE's velocity of the cell at pos: sum over its throats of q (X - P) / V, q the flux leaving through
        the throat, X where the line of the two cells' centres pierces the facet, P the cell's centre, V its
        volume (the mean fluid velocity times the cell's porosity; cell_velocity.hpp). YADE updates it only in
        averageVelocity, avFlVelOnSph and saveVtk (before, it reads 0); PFV at every call."""
        cell = self._cell_at(pos)
        return self._yade_velocities()[cell].tolist()

    @exclusive
    def averageVelocity(self) -> Vector3:
        """Volume mean of the cells' velocities (getCellVelocity) over the sample: the Darcy velocity, flux
        over cross-section along a permeameter."""
        self._require_mesh()
        volume = self._core.cell_volumes()
        return Vector3(*((self._yade_velocities() * volume[:, None]).sum(axis=0) / volume.sum()))

    @exclusive
    def avFlVelOnSph(self, idSph: int) -> list[float]:
        """Volume mean of the velocities of the cells around sphere idSph that touch no wall (nan if none)."""
        vertex = self._vertex_of(_index("idSph", idSph))
        cv = self._core.cell_vertices()
        cells = (cv == vertex).any(axis=1) & ~(cv >= self._core.n_spheres()).any(axis=1)
        volume = self._core.cell_volumes()[cells]
        if not volume.sum() > 0:
            return [math.nan] * 3
        return ((self._yade_velocities()[cells] * volume[:, None]).sum(axis=0) / volume.sum()).tolist()

    def _boundary_throats(self, boundary: Any) -> tuple[np.ndarray, np.ndarray]:
        """The cells touching the wall `boundary` (a body id) and their throats (cell, local) to cells that
        touch no wall, as YADE's boundary queries take them."""
        wall = self._wall_index(boundary)
        n = self._core.n_spheres()
        cv = self._core.cell_vertices()
        neighbours = self._core.cell_neighbour_array()
        touches = (cv >= n).any(axis=1)
        on_wall = np.nonzero((cv == n + wall).any(axis=1))[0]
        pairs = [(c, local) for c in on_wall for local in range(4)
                 if neighbours[c, local] >= 0 and not touches[neighbours[c, local]]]
        cells = np.array([c for c, _ in pairs], dtype=int)
        areas = np.array([self._throat_fluid_area(c, local) for c, local in pairs])
        return cells, areas

    def _throat_fluid_area(self, cell: int, local: int) -> float:
        return self._core.throat_fluid_area(cell, local)

    @exclusive
    def getBoundaryFluidArea(self, boundary: int) -> float:
        """Fluid area of the throats from the cells touching the boundary (a body id) to cells that touch no
        wall: where the boundary layer of cells meets the interior."""
        return float(self._boundary_throats(boundary)[1].sum())

    @exclusive
    def getBoundaryVel(self, boundary: int) -> list[list[float]]:
        """[vx, vy, vz, area] per throat of getBoundaryFluidArea: the velocity (getCellVelocity) of its cell on
        the boundary and the throat's fluid area."""
        cells, areas = self._boundary_throats(boundary)
        v = self._yade_velocities()
        return [[*v[c].tolist(), float(a)] for c, a in zip(cells, areas)]

    @exclusive
    def getBoundaryVolume(self, boundary: int, dt: float) -> float:
        """Fluid volume entering the sample through the boundary in time dt: -getBoundaryFlux(boundary) dt."""
        return -self.getBoundaryFlux(boundary) * attributes.as_number("getBoundaryVolume dt", dt)

    # -- outputs ----------------------------------------------------------------------------------------
    @exclusive
    def pressureProfile(self, wallUpY: float, wallDownY: float) -> None:
        """Append to the file Pressure_profile the mean pore pressure of 6 levels y = wallDownY + k (wallUpY -
        wallDownY) / 6, k = 0 .. 5, each sampled at 6 points across z at mid x, one line per level. YADE writes
        the running mean over the levels so far (its sums are not reset per level); PFV the level's mean."""
        self._require_mesh()
        up = attributes.as_number("wallUpY", wallUpY)
        down = attributes.as_number("wallDownY", wallDownY)
        walls = self._core.walls()
        inset = 1e-9 * max(walls[1] - walls[0], walls[3] - walls[2], walls[5] - walls[4])
        x = 0.5 * (walls[0] + walls[1])
        lines = []
        for k in range(6):
            y = min(max(down + k * (up - down) / 6, walls[2] + inset), walls[3] - inset)
            pressures = []
            for j in range(6):
                z = min(max(walls[4] + j * (walls[5] - walls[4]) / 5, walls[4] + inset), walls[5] - inset)
                cell = self._core.locate((x, y, z))
                if cell >= 0:
                    pressures.append(self._core.cell_pressure(cell))
            lines.append(f"{np.mean(pressures):g}" if pressures else "nan")
        with open("Pressure_profile", "a") as f:
            f.write("\n".join(lines) + "\n")

    @exclusive
    def printVertices(self) -> None:
        """Write vertices.txt as YADE does ("id x y z r alpha fictious"): the walls first, each as the point of
        its plane at the middle of its face with radius inf (PFV's walls are planes, YADE's large spheres),
        then the spheres at the last step's positions."""
        self._require_mesh()
        walls = self._core.walls()
        centre = [0.5 * (walls[2 * a] + walls[2 * a + 1]) for a in range(3)]
        lines = ["id x y z r alpha fictious"]
        for w, body in enumerate(self._stepped.wall_ids):
            point = list(centre)
            point[w // 2] = walls[w]
            lines.append(f"{body} {point[0]:g} {point[1]:g} {point[2]:g}  inf 0 1")
        for body, x, r in zip(self._stepped.ids, self._core.last_positions(), self._stepped.radii):
            lines.append(f"{body} {x[0]:g} {x[1]:g} {x[2]:g}  {r:g} 0 0")
        with open("vertices.txt", "w") as f:
            f.write("\n".join(lines) + "\n")

    def _lower_triangle(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
        """G's lower triangle by column (rows ascending within a column), as YADE's matrix A: (col, row, value, n)."""
        m = self._core.system_matrix()
        start, row, value = m["col_start"], m["row"], m["value"]
        n = len(start) - 1
        col = np.repeat(np.arange(n), np.diff(start))
        # The upper entry (row r, column c) is the lower entry (row c, column r).
        order = np.lexsort((col, row))
        return row[order], col[order], value[order], n

    @exclusive
    def exportTriplets(self, filename: str = "triplets") -> None:
        """Write G's lower triangle, one "row col value" line per entry by column, as YADE does (rows and
        columns are the unknown cells in cell order; YADE numbers them in the order it meets them)."""
        self._require_mesh()
        lower_col, lower_row, value, _ = self._lower_triangle()
        with open(str(filename), "w") as f:
            f.writelines(f"{r} {c} {v:g}\n" for r, c, v in zip(lower_row, lower_col, value))

    @exclusive
    def exportMatrix(self, filename: str = "matrix") -> None:
        """Write G's lower triangle as YADE does (Eigen's print of a sparse matrix): its entries by column as
        (value,row), the column pointers, then every row in full, zeros included."""
        self._require_mesh()
        lower_col, lower_row, value, n = self._lower_triangle()
        pointers = np.searchsorted(lower_col, np.arange(n))
        text = [f"{v:g}" for v in value]
        with open(str(filename), "w") as f:
            f.write("Nonzero entries:\n")
            f.write("".join(f"({t},{r}) " for t, r in zip(text, lower_row)) + "\n\n")
            f.write("Outer pointers:\n" + "".join(f"{p} " for p in pointers) + " $\n\n")
            by_row = np.lexsort((lower_col, lower_row))
            row_start = np.searchsorted(lower_row[by_row], np.arange(n + 1))
            for r in range(n):
                line = ["0"] * n
                for k in by_row[row_start[r]:row_start[r + 1]]:
                    line[lower_col[k]] = text[k]
                f.write(" ".join(line) + " \n")

    @exclusive
    def cholmodStats(self) -> None:
        """Print CHOLMOD's report on the current factor, then its ordering method and whether METIS ran."""
        self._require_mesh()
        if not self._core.print_cholmod_statistics("PFV Cholmod factorization"):
            print("cholmodStats: the current solver is not CHOLMOD (useSolver=3)", file=sys.stderr)

    # -- boundaries -----------------------------------------------------------------------------------------
    def setBoundaryNormal(self, index: int, v: Sequence[float]) -> None:
        """YADE's normal of boundary `index` (0..5), pointing into the sample. PFV's walls are the six
        axis-aligned planes: only YADE's default normal of each is accepted."""
        index = _index("index", index)
        if not 0 <= index < 6:
            raise IndexError(f"boundary index must be in 0..5, got {index}")
        normal = np.array(attributes.as_point("setBoundaryNormal normal", v))
        if not np.allclose(normal, _NORMALS[index], rtol=0, atol=1e-12):
            raise NotImplementedError(
                f"pfv.FlowEngine: boundary {index} is the axis-aligned plane with normal {_NORMALS[index]}; other "
                "normals are not supported")
