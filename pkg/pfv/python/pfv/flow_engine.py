"""YADE adapter: ``pfv.FlowEngine``, a drop-in replacement for YADE's FlowEngine.

The object is a PyRunner placed in ``O.engines`` like YADE's engine (after the
InteractionLoop, before NewtonIntegrator). Each step it reads the sphere positions in bulk,
runs the C++ pipeline (remesh when due, dV/dt, solve, forces) and adds the fluid forces to
the spheres and to the six wall bodies. Attribute names and sign conventions are YADE's.

An attribute YADE's FlowEngine has but PFV does not support may only be set to YADE's
default value; any other value raises NotImplementedError naming it. Misspelt names raise
AttributeError. Nothing is silently ignored.
"""
import ast
import re
import time
import warnings
import weakref

import numpy as np

import yade
from yade.wrapper import PyRunner, Sphere, Box
from yade.minieigenHP import Vector3
from yade._packSpheres import SpherePack

from ._core import (Engine, YadeForceBridge, gather_axis, gather_sphere_pack, set_num_threads,
                    sphere_pack_size)
from ._yade_api import ATTRIBUTES as _YADE_ATTRIBUTES, METHODS as _YADE_METHODS

__all__ = ["FlowEngine", "TimeStepWarning"]


class TimeStepWarning(UserWarning):
    """O.dt exceeds the coupled stability limit (thesis 4.20-4.22)."""


_engines = weakref.WeakValueDictionary()  # PyRunner commands find their engine here
_coordinates = yade._utils.coordsAndDisplacements


def _run(key):
    engine = _engines.get(key)
    # After O.load the running PyRunner is a restored copy, not this engine (which may still be
    # alive in this process): driving the old object would be silently wrong.
    if engine is None or not any(e is engine for e in yade.O.engines):
        raise RuntimeError(
            "this pfv.FlowEngine must be re-created: after O.save/O.load YADE restores it as a "
            "plain PyRunner, which cannot drive the flow; create a new pfv.FlowEngine and put it "
            "back into O.engines")
    engine._step()


def _as_bool6(name, value):
    value = list(value)
    if len(value) != 6:
        raise ValueError(f"{name} needs 6 values (xmin, xmax, ymin, ymax, zmin, zmax)")
    return [bool(v) for v in value]


def _as_float6(name, value):
    value = [float(v) for v in value]
    if len(value) != 6:
        raise ValueError(f"{name} needs 6 values (xmin, xmax, ymin, ymax, zmin, zmax)")
    return value


# Python-side state attributes (not YADE attributes).
_INTERNAL = frozenset({
    "_core", "_key", "_ids", "_rows", "_radii", "_wall_rows", "_wall_half", "_n_bodies",
    "_boundary_use_max_min", "_wall_ids", "_warned", "_vertex_of_id", "_threads",
    "_mass_per_diameter", "_dt_dem", "_masses", "_dt_collective", "_collective_viscosity",
    "_collective_mesh", "_collective_mode", "_collective_history", "_dt_unsafe", "_force_bridge",
    "_n_listed", "_pack", "_pack_index", "_pack_size", "_use_sphere_pack", "_positions",
    "time_step_safety", "strict_time_step", "collective_iterations", "collective_iterations_warm",
})
# YADE attributes PFV implements through a core attribute of another name (the others are
# properties of FlowEngine below).
_SUPPORTED = {
    "viscosity": "viscosity",
    "permeabilityFactor": "permeability_factor",
    "clampKValues": "clamp_k_values",
    "minKdivKmean": "min_k_div_k_mean",
    "maxKdivKmean": "max_k_div_k_mean",
    "slipBoundary": "slip_boundary",
    "tolerance": "tolerance",
    "relax": "relax",
    "forceMetis": "force_metis",
    "meshUpdateInterval": "mesh_update_interval",
    "defTolerance": "def_tolerance",
    "pZero": "p_zero",
    "multithread": "background_remesh",
    "fluidBulkModulus": "fluid_bulk_modulus",
    "viscousShear": "viscous_shear",
    # PFV extensions (PEP 8 names: YADE has no equivalent).
    "mixed_precision": "mixed_precision",
    "mixed_precision_min_entries": "mixed_precision_min_entries",
    "refinement_tolerance": "refinement_tolerance",
}


_SOLVER_OF_USE_SOLVER = {0: "gauss_seidel", 1: "conjugate_gradient", 3: "cholesky"}
_USE_SOLVER_OF = {v: k for k, v in _SOLVER_OF_USE_SOLVER.items()}


class FlowEngine(PyRunner):
    """PFV's DEM-PFV flow engine with the interface of YADE's FlowEngine."""

    xmin, xmax, ymin, ymax, zmin, zmax = range(6)

    def __init__(self, **kwargs):
        PyRunner.__init__(self)
        object.__setattr__(self, "_core", Engine())
        object.__setattr__(self, "_key", id(self))
        object.__setattr__(self, "_boundary_use_max_min", [True] * 6)
        object.__setattr__(self, "_wall_ids", list(range(6)))
        object.__setattr__(self, "_warned", set())
        object.__setattr__(self, "_ids", None)
        object.__setattr__(self, "_force_bridge", None)
        object.__setattr__(self, "_pack", None)  # a SpherePack whose array this build reads, or None
        object.__setattr__(self, "_use_sphere_pack", True)  # False: always the coordinate lists
        object.__setattr__(self, "_positions", None)  # the centres array _read_positions fills
        object.__setattr__(self, "_threads", None)  # None: follow YADE's -j
        object.__setattr__(self, "_mass_per_diameter", float("inf"))
        object.__setattr__(self, "_dt_dem", float("inf"))
        object.__setattr__(self, "_masses", None)
        # Collective viscous limit: computed on every new mesh (remesh_count changes) and when
        # the viscosity changes; a remesh's power iteration starts from the previous mesh's mode.
        object.__setattr__(self, "_dt_collective", None)
        object.__setattr__(self, "_collective_viscosity", None)
        object.__setattr__(self, "_collective_mesh", None)  # core.remesh_count it was computed on
        object.__setattr__(self, "_collective_mode", None)
        object.__setattr__(self, "_collective_history", [])
        object.__setattr__(self, "collective_iterations", 40)       # cold start (first mesh)
        object.__setattr__(self, "collective_iterations_warm", 10)  # warm start (later meshes)
        # O.dt must stay below time_step_safety * min(dt_MV, collective limit, DEM limit) (zeta of
        # thesis 4.22); beyond it the engine warns when the step becomes unsafe (the first time, and
        # again after it was safe in between), or raises if strict_time_step.
        object.__setattr__(self, "_dt_unsafe", False)
        object.__setattr__(self, "time_step_safety", 0.8)
        object.__setattr__(self, "strict_time_step", False)
        _engines[self._key] = self
        self.command = f"__import__('pfv.flow_engine').flow_engine._run({self._key})"
        self.iterPeriod = 1
        self.initRun = True
        for name, value in kwargs.items():
            setattr(self, name, value)

    # -- attribute surface -------------------------------------------------------------
    def __setattr__(self, name, value):
        if name in _SUPPORTED:
            setattr(self._core, _SUPPORTED[name], value)
        elif name in _INTERNAL or name in _PYRUNNER_ATTRIBUTES:
            object.__setattr__(self, name, value)
        elif name in _YADE_ATTRIBUTES:
            _check_default(name, value)
        else:
            raise AttributeError(f"pfv.FlowEngine has no attribute '{name}' (and neither has YADE's FlowEngine)")

    def __getattr__(self, name):  # only called when normal lookup fails
        if name in _SUPPORTED:
            return getattr(self._core, _SUPPORTED[name])
        if name in _YADE_METHODS:
            raise NotImplementedError(f"pfv.FlowEngine does not support YADE FlowEngine method '{name}' yet")
        if name in _YADE_ATTRIBUTES:
            return _default(name)
        raise AttributeError(f"pfv.FlowEngine has no attribute '{name}'")

    @property
    def bndCondIsPressure(self):
        return list(self._core.bnd_is_pressure)

    @bndCondIsPressure.setter
    def bndCondIsPressure(self, value):
        self._core.bnd_is_pressure = _as_bool6("bndCondIsPressure", value)

    @property
    def bndCondValue(self):
        return list(self._core.bnd_value)

    @bndCondValue.setter
    def bndCondValue(self, value):
        self._core.bnd_value = _as_float6("bndCondValue", value)

    @property
    def boundaryUseMaxMin(self):
        return list(self._boundary_use_max_min)

    @boundaryUseMaxMin.setter
    def boundaryUseMaxMin(self, value):
        value = _as_bool6("boundaryUseMaxMin", value)
        if value != self._boundary_use_max_min:
            object.__setattr__(self, "_boundary_use_max_min", value)
            self._core.request_remesh()
            self._core.reset_history()

    @property
    def wallIds(self):
        return list(self._wall_ids)

    @wallIds.setter
    def wallIds(self, value):
        value = [int(v) for v in value]
        if len(value) != 6:
            raise ValueError("wallIds needs 6 body ids (xmin, xmax, ymin, ymax, zmin, zmax)")
        if value != self._wall_ids:
            object.__setattr__(self, "_wall_ids", value)
            object.__setattr__(self, "_ids", None)
            self._core.reset_history()

    @property
    def useSolver(self):
        """YADE's solver number: 0 Gauss-Seidel, 1 conjugate gradients (PFV), 3 CHOLMOD."""
        return _USE_SOLVER_OF[self._core.solver]

    @useSolver.setter
    def useSolver(self, value):
        if value not in _SOLVER_OF_USE_SOLVER:
            raise ValueError("useSolver must be 0 (Gauss-Seidel), 1 (preconditioned CG, PFV) or 3 (CHOLMOD)")
        self._core.solver = _SOLVER_OF_USE_SOLVER[value]

    @property
    def updateTriangulation(self):
        return self._core.remesh_due()

    @updateTriangulation.setter
    def updateTriangulation(self, value):
        if value:
            self._core.request_remesh()

    @property
    def ompThreads(self):
        """Threads of the engine's parallel loops; -1 follows YADE's thread count (yade -jN)."""
        return -1 if self._threads is None else self._threads

    @ompThreads.setter
    def ompThreads(self, value):
        object.__setattr__(self, "_threads", int(value) if int(value) > 0 else None)

    # -- the step ---------------------------------------------------------------------------
    def _scan_bodies(self):
        """Sphere ids and radii, wall bodies; done at each remesh (bodies may change)."""
        O = yade.O
        if O.periodic:
            raise NotImplementedError("pfv.FlowEngine does not support periodic scenes yet")
        ids, radii, rows, masses, others, clumps = [], [], [], [], 0, 0
        pack_index, pack_size = [], 0  # SpherePack.fromSimulation() lists every sphere body in id order
        mass_per_diameter = float("inf")  # min m/d over the dynamic coupled spheres
        row_of = {}
        wall_set = set(self._wall_ids)
        # Each attribute read through Boost.Python makes a new wrapper: read each once per body
        # (the scan runs at every remesh: 15 -> 10 ms for 10 006 bodies, scratch timing of both loops;
        # 0.22-0.33 s before for 50 006 in the benchmark's restored scene).
        for row, b in enumerate(O.bodies):
            bid = b.id
            row_of[bid] = row
            shape = b.shape
            is_clump = b.isClump
            is_sphere = isinstance(shape, Sphere) and not is_clump
            pack_size += is_sphere
            if bid in wall_set:
                continue
            if is_clump or b.isClumpMember:
                clumps += 1
            elif is_sphere:
                radius = shape.radius
                pack_index.append(pack_size - 1)
                ids.append(bid)
                radii.append(radius)
                rows.append(row)
                state = b.state
                mass = state.mass
                moving = b.dynamic and mass > 0 and state.blockedDOFs != "xyzXYZ"
                masses.append(mass if moving else 0.0)
                if moving:
                    mass_per_diameter = min(mass_per_diameter, mass / (2 * radius))
            else:
                others += 1
        if clumps:
            raise NotImplementedError(
                f"pfv.FlowEngine does not support clumps yet ({clumps} clump bodies or members in the scene)")
        if others and "others" not in self._warned:
            self._warned.add("others")
            warnings.warn(f"pfv.FlowEngine: {others} bodies that are neither spheres nor the six walls "
                          "are left out of the flow", stacklevel=2)
        wall_rows, wall_half = [], []
        for w, bid in enumerate(self._wall_ids):
            if bid not in row_of:
                if not self._boundary_use_max_min[w]:
                    raise ValueError(f"wallIds[{w}] = {bid} is not a body of the scene")
                wall_rows.append(-1)
                wall_half.append(0.0)
                continue
            b = O.bodies[bid]
            wall_rows.append(row_of[bid])
            # A box wall bounds the domain with its inner face.
            half = b.shape.extents[w // 2] if isinstance(b.shape, Box) else 0.0
            wall_half.append(-half if w % 2 else half)
        vertex_of_id = {bid: k for k, bid in enumerate(ids)}
        for w, bid in enumerate(self._wall_ids):
            vertex_of_id.setdefault(bid, len(ids) + w)
        object.__setattr__(self, "_ids", np.array(ids, dtype=np.int64))
        object.__setattr__(self, "_rows", np.array(rows, dtype=np.int64))
        object.__setattr__(self, "_radii", np.array(radii, dtype=float))
        object.__setattr__(self, "_wall_rows", wall_rows)
        object.__setattr__(self, "_wall_half", wall_half)
        object.__setattr__(self, "_n_bodies", len(O.bodies))
        object.__setattr__(self, "_n_listed", len(row_of))
        object.__setattr__(self, "_vertex_of_id", vertex_of_id)
        object.__setattr__(self, "_mass_per_diameter", mass_per_diameter)
        object.__setattr__(self, "_masses", np.array(masses, dtype=float))
        # Spheres get force rows 0..n-1, the walls present rows n + w.
        bridge_ids = ids + [bid for w, bid in enumerate(self._wall_ids) if wall_rows[w] >= 0]
        bridge_rows = list(range(len(ids))) + [len(ids) + w for w in range(6) if wall_rows[w] >= 0]
        key = (bridge_ids, bridge_rows)
        if self._force_bridge is None or self._force_bridge[0] != key:  # its Vector3s are made once
            bridge = YadeForceBridge(Vector3, np.array(bridge_ids, dtype=np.int64), np.array(bridge_rows, dtype=np.int64))
            object.__setattr__(self, "_force_bridge", (key, bridge))
        dem = yade.utils.PWaveTimeStep() if ids else float("inf")
        object.__setattr__(self, "_dt_dem", dem if dem > 0 else float("inf"))
        self._choose_position_reader(np.array(pack_index, dtype=np.int64), pack_size)

    def _choose_position_reader(self, pack_index, pack_size):
        """Read the centres from a SpherePack (yade_sphere_pack.hpp) if this YADE's pack gives,
        for every sphere, the centre and radius YADE's Python interface gives, bit for bit."""
        object.__setattr__(self, "_pack", None)
        if not self._use_sphere_pack:
            return
        pack = SpherePack()
        pack.fromSimulation()
        centres, radii = np.empty((len(pack_index), 3)), np.empty(len(pack_index))
        if sphere_pack_size(pack) < 0 or not gather_sphere_pack(pack, pack_index, centres, radii, pack_size):
            return
        listed = self._read_positions()
        if listed is not None and np.array_equal(centres, listed[0]) and np.array_equal(radii, self._radii):
            object.__setattr__(self, "_pack_index", pack_index)
            object.__setattr__(self, "_pack_size", pack_size)
            object.__setattr__(self, "_pack", pack)

    @property
    def position_source(self):
        """Where the sphere centres come from each step: "SpherePack" (YADE's C++ copy of the
        bodies' centres, read in place) or "coordinate lists" (yade._utils.coordsAndDisplacements,
        one Python list per axis; used when the pack's layout does not check out)."""
        return "SpherePack" if self._pack is not None else "coordinate lists"

    def _read_positions(self):
        """Sphere centres (n, 3) and the six boundary coordinates, or None if bodies were erased
        since the last scan."""
        pos = self._positions
        if pos is None or len(pos) != len(self._rows):  # one array per scan, not per step (core.step copies it)
            pos = np.empty((len(self._rows), 3))
            object.__setattr__(self, "_positions", pos)
        walls = [0.0] * 6
        if self._pack is not None:
            pack = self._pack
            pack.fromSimulation()
            if not gather_sphere_pack(pack, self._pack_index, pos, None, self._pack_size):
                return None
            bodies = yade.O.bodies
            for w in range(6):
                if not self._boundary_use_max_min[w]:
                    wall = bodies[self._wall_ids[w]]
                    if wall is None:
                        return None
                    walls[w] = wall.state.pos[w // 2] + self._wall_half[w]
        else:
            for axis in range(3):
                coords = _coordinates(axis)[0]
                if len(coords) != self._n_listed:
                    return None
                gather_axis(coords, self._rows, pos, axis)
                for w in (2 * axis, 2 * axis + 1):
                    if not self._boundary_use_max_min[w]:
                        walls[w] = coords[self._wall_rows[w]] + self._wall_half[w]
                del coords  # one list alive at a time
        for w in range(6):
            if self._boundary_use_max_min[w]:
                axis = w // 2
                walls[w] = float((pos[:, axis] + self._radii).max() if w % 2 else (pos[:, axis] - self._radii).min())
        return pos, walls

    def _step(self):
        O = yade.O
        core = self._core
        bodies_changed = self._ids is None or len(O.bodies) != self._n_bodies
        if bodies_changed or core.remesh_due():
            self._scan_bodies()  # radii and masses may have changed too
            if bodies_changed:
                core.request_remesh()
        read = self._read_positions()
        if read is None:  # bodies erased (which leaves len(O.bodies) as it was)
            self._scan_bodies()
            core.request_remesh()
            read = self._read_positions()
        pos, walls = read
        set_num_threads(self._threads or O.numThreads)
        self._check_time_step(O.dt)
        remeshing = core.remesh_due()
        try:
            core.step(pos, self._radii, walls, O.dt)
        except ValueError as error:  # name bodies by their YADE id, not by sphere index
            ids = self._ids
            message = re.sub(r"sphere (\d+)", lambda m: f"sphere #{ids[int(m.group(1))]}", str(error))
            raise ValueError(f"pfv.FlowEngine: {message}") from None
        if self._collective_mesh != core.remesh_count:
            # A new mesh (the first, or a remesh adopted by this step): its collective limit may be
            # lower (a compacting sample), check again.
            self._check_time_step(O.dt)
        if remeshing:
            hidden = core.hidden_spheres()
            if hidden:
                warnings.warn(f"pfv.FlowEngine: {len(hidden)} spheres are hidden by larger neighbours in the "
                              f"regular triangulation and get no fluid force (ids {self._ids[hidden][:10].tolist()}...)",
                              stacklevel=2)
        # The engine's force array is read in C++, without a numpy copy.
        self._force_bridge[1].apply(O.forces.addF, core)

    @property
    def viscous_time_step(self):
        """dt_MV = pi rho d^2 / (1200 mu) at the smallest rho d^2 of the coupled dynamic spheres (thesis 4.20)."""
        if self._ids is None:
            self._scan_bodies()
        # pi rho d^2 / (1200 mu) with rho = 6 m / (pi d^3) is m / (200 mu d).
        return self._mass_per_diameter / (200.0 * self._core.viscosity)

    @property
    def collective_viscous_time_step(self):
        """2 / lambda_max(M^-1 V) of the current mesh: the viscous limit of the explicit coupling
        for collective motions (groups of spheres squeezing shared pores), which the thesis'
        single-particle dt_MV overestimates (0.3-0.5 dt_MV measured on dense packings).
        Computed on every new mesh and when the viscosity changes: on the first mesh by Arnoldi
        from a fixed start (at most collective_iterations = 40 operator applications, stopping
        once the estimate settles to 1e-6), afterwards by power iteration started from the
        previous mesh's mode (at most collective_iterations_warm = 10). Each operator application
        costs one back-substitution and one force evaluation; see collective_viscous_history
        ("iterations" there is the count made, "max_iterations" the cap, "seconds" the cost)."""
        core = self._core
        if not core.has_mesh():
            return float("inf")
        # The shear term adds damping to the operator, so switching it recomputes the limit too
        # (switched on, its pairs arrive with a remesh, which recomputes again).
        key = (core.viscosity, core.viscous_shear)
        if self._collective_mesh != core.remesh_count or self._collective_viscosity != key:
            mode = self._collective_mode
            warm = mode is not None and len(mode) == len(self._masses) and self._dt_collective is not None
            iterations = self.collective_iterations_warm if warm else self.collective_iterations
            t0 = time.perf_counter()
            limit, mode, applied = core.viscous_stability_mode(self._masses, iterations, mode if warm else None)
            seconds = time.perf_counter() - t0
            object.__setattr__(self, "_dt_collective", limit)
            object.__setattr__(self, "_collective_mode", mode if len(mode) else None)
            object.__setattr__(self, "_collective_viscosity", key)
            object.__setattr__(self, "_collective_mesh", core.remesh_count)
            self._collective_history.append(dict(
                iter=yade.O.iter, remesh_count=core.remesh_count, limit=limit, iterations=applied,
                max_iterations=iterations,
                warm=warm, seconds=seconds))
        return self._dt_collective

    @property
    def collective_viscous_history(self):
        """One dict per computation of the collective limit: iter, remesh_count, limit [s],
        iterations (operator applications made, each a solve and a force evaluation), max_iterations (the cap),
        warm (power iteration from the previous mode; cold: Arnoldi), seconds (wall time)."""
        return list(self._collective_history)

    @property
    def critical_time_step(self):
        """min(dt_MV, collective viscous limit, DEM P-wave limit): O.dt should not exceed
        time_step_safety times this."""
        if self._ids is None:
            self._scan_bodies()
        return min(self.viscous_time_step, self.collective_viscous_time_step, self._dt_dem)

    def _check_time_step(self, dt):
        dt_mv = self.viscous_time_step
        dt_collective = self.collective_viscous_time_step
        limit = self.time_step_safety * min(dt_mv, dt_collective, self._dt_dem)
        if dt <= limit:
            object.__setattr__(self, "_dt_unsafe", False)
            return
        message = (f"pfv.FlowEngine: O.dt = {dt:.4g} exceeds the coupled stability limit "
                   f"{self.time_step_safety:g} x min(dt_MV = {dt_mv:.4g}, collective viscous limit = "
                   f"{dt_collective:.4g}, dt_DEM = {self._dt_dem:.4g}) = {limit:.4g}; "
                   f"the explicit coupling may blow up (thesis 4.20-4.22)")
        if self.strict_time_step:
            raise ValueError(message)
        if not self._dt_unsafe:  # warn on becoming unsafe, not at every step while it stays so
            object.__setattr__(self, "_dt_unsafe", True)
            warnings.warn(message, TimeStepWarning, stacklevel=2)

    def emulateAction(self):
        """Run one flow step outside the time-stepping loop, as YADE's method does."""
        self._step()

    # -- boundary conditions --------------------------------------------------------------
    def updateBCs(self):
        """Apply changed boundary values and types (PFV applies values at every step anyway)."""
        self._core.request_system_rebuild()

    def imposePressure(self, pos, p):
        return self._core.impose_pressure(tuple(pos), float(p))

    def setImposedPressure(self, cond, p):
        self._core.set_imposed_pressure(int(cond), float(p))

    def clearImposedPressure(self):
        self._core.clear_imposed_pressure()

    def imposeFlux(self, pos, p):
        """YADE's sign: outflux positive, influx negative."""
        self._core.impose_flux(tuple(pos), -float(p))

    def clearImposedFlux(self):
        self._core.clear_imposed_flux()

    # -- queries ----------------------------------------------------------------------------
    def _require_mesh(self):
        if not self._core.has_mesh():
            raise RuntimeError("the flow engine has not run yet: no pore mesh (run at least one step)")

    def _cell_at(self, pos):
        self._require_mesh()
        cell = self._core.locate(tuple(float(x) for x in pos))
        if cell < 0:
            raise ValueError(f"point {tuple(pos)} lies in no pore cell (outside the walls or the packing)")
        return cell

    def getPorePressure(self, pos):
        return self._core.cell_pressure(self._cell_at(pos))

    def getCell(self, X, Y, Z):
        self._require_mesh()
        return self._core.locate((float(X), float(Y), float(Z)))

    def getCellPressure(self, id):
        return self._core.cell_pressure(int(id))

    def getCellCenter(self, id):
        return Vector3(*self._core.cell_center(int(id)))

    def getCellVolume(self, pos):
        return self._core.cell_volume(self._cell_at(pos))

    def getBoundaryFlux(self, boundary):
        self._require_mesh()
        if boundary not in self._wall_ids:
            raise ValueError(f"body {boundary} is not one of the boundaries wallIds = {self._wall_ids}")
        return self._core.boundary_flux(self._wall_ids.index(boundary))

    def fluidForce(self, idSph):
        self._require_mesh()
        v = self._vertex_of_id.get(int(idSph))
        if v is None:
            raise ValueError(f"body {idSph} is not coupled with the fluid (not a sphere nor a wall)")
        return Vector3(*self._core.forces()[v])

    def shearLubForce(self, idSph):
        """The viscous shear part of fluidForce(idSph) (viscousShear; zero while it is off).
        YADE's name: its shearLubForce reports the viscousShear force as well."""
        self._require_mesh()
        v = self._vertex_of_id.get(int(idSph))
        if v is None:
            raise ValueError(f"body {idSph} is not coupled with the fluid (not a sphere nor a wall)")
        shear = self._core.shear_forces()
        return Vector3(*shear[v]) if len(shear) else Vector3(0, 0, 0)

    def nCells(self):
        return self._core.n_cells()

    def averagePressure(self):
        self._require_mesh()
        return self._core.average_pressure()

    def averageSlicePressure(self, posY, axis=1):
        self._require_mesh()
        return self._core.average_slice_pressure(int(axis), float(posY))

    def metisUsed(self):
        return self._core.metis_used()

    # -- PFV extras -------------------------------------------------------------------------
    @property
    def core(self):
        """The C++ engine (pfv.Engine): geometry, timings and diagnostics."""
        return self._core


_PYRUNNER_ATTRIBUTES = frozenset(a for a in dir(PyRunner) if not a.startswith("__")) | {
    name for name, v in vars(FlowEngine).items() if isinstance(v, property)}


def _default(name):
    text = _YADE_ATTRIBUTES[name]
    try:
        return ast.literal_eval(text)
    except (ValueError, SyntaxError):
        return text


def _check_default(name, value):
    default = _default(name)
    try:
        same = value == default or (isinstance(default, float) and float(value) == default)
    except (TypeError, ValueError):
        same = False
    if not same:
        raise NotImplementedError(
            f"pfv.FlowEngine does not support YADE FlowEngine attribute '{name}' yet "
            f"(only its default value {default!r} is accepted)")
