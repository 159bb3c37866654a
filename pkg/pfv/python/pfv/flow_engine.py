"""YADE adapter: ``pfv.FlowEngine``, a drop-in replacement for YADE's FlowEngine.

The object is a PyRunner placed in ``O.engines`` like YADE's engine (after the
InteractionLoop, before NewtonIntegrator). Each step it reads the sphere positions in bulk,
runs the C++ pipeline (remesh when due, dV/dt, solve, forces) and adds the fluid forces to
the spheres and to the six wall bodies. Attribute names and sign conventions are YADE's.

An attribute YADE's FlowEngine has but PFV does not support may only be set to YADE's
default value; any other value raises NotImplementedError naming it. Misspelt names raise
AttributeError. Nothing is silently ignored.

This module holds the engine class, which composes five parts: the attribute surface
(``_attributes``), the scan of YADE's bodies (``_scene_scan.SceneScan``), the time-step
guard (``_time_step.TimeStepGuard``), the members on single cells (``_cell_interface``, a mixin)
and the time-dependent boundary pressures (``_boundary_pressure``, a mixin; ``pfv.waves``).
"""
from __future__ import annotations

import contextlib
import numbers
import os
import re
import threading
import uuid
import warnings
import weakref
from collections.abc import Sequence
from typing import Any

import numpy as np

import yade
from yade.wrapper import NewtonIntegrator, PyRunner
from yade.minieigenHP import Vector3

from . import _attributes as attributes
from . import _persistence
from ._boundary_pressure import FIELD_INTERNAL, BoundaryPressure
from ._locking import exclusive as _exclusive
from ._cell_interface import CELL_CACHES, CELL_INTERNAL, CellInterface
from ._core import Engine, set_num_threads
from ._scene_scan import SceneScan
from ._timing import StageTimings, StepClock
from ._time_step import TimeStepGuard, TimeStepWarning, viscous_time_step

__all__ = ["FlowEngine", "TimeStepWarning"]

_engines = weakref.WeakValueDictionary()  # PyRunner commands find their engine here
# Keys of the engines that hold a mesh. YADE keeps a reference to every engine ever put into
# O.engines, so an engine taken out is never freed: the step of an engine in use frees the mesh
# of those no longer in their scene (_release_unused).
_holding: set[int] = set()
_MAX_THREADS = 1024  # ompThreads beyond this is a typo, not a machine
_SCENE_TAG = "pfv.FlowEngine"  # key in O.tags of the token that tells this scene from a new one


_COMMAND = "__import__('pfv.flow_engine').flow_engine._run({})"


def _run(key: int) -> None:
    engine = _engines.get(key)
    # After a load the running PyRunner is a restored copy, not this engine (which may still be
    # alive in this process): driving the old object would be silently wrong. A scene loaded
    # by O.load is adopted at the load; one loaded otherwise (yade file.yade.gz) is adopted here.
    if engine is None or not any(e is engine for e in yade.O.engines):
        engine = _persistence.adopt_runner(_COMMAND.format(key))
        if engine is None:
            raise RuntimeError(
                "this pfv.FlowEngine must be re-created: YADE restored it as a plain PyRunner and the "
                "scene carries no saved state for it (saved before PFV could add it?); create a new "
                "pfv.FlowEngine and put it back into O.engines")
    engine._step()


def _as_tuples(value: Any) -> Any:
    """JSON gives lists where the engine keeps tuples."""
    return tuple(_as_tuples(v) for v in value) if isinstance(value, list) else value


def _gravity(scene: Any) -> tuple[float, float, float]:
    """The gravity of the scene's NewtonIntegrator (zero without one)."""
    for engine in scene.engines:
        if isinstance(engine, NewtonIntegrator):
            return tuple(engine.gravity)
    return (0.0, 0.0, 0.0)


def _release_unused(current: FlowEngine) -> None:
    """Free the meshes of the engines that ran in the current scene but are no longer in O.engines."""
    others = [key for key in _holding if key != current._key]
    if not others:
        return
    engines = yade.O.engines
    for key in others:
        engine = _engines.get(key)
        if engine is None:
            _holding.discard(key)
        elif engine._in_scene(yade.O) and not any(e is engine for e in engines):
            engine._release()


# The core's settings saved with a scene: every one a user may set (YADE's names map onto most).
# The upper clamp first: restoring must never meet a lower bound above the default upper one.
_SAVED_CORE_SETTINGS = ("max_k_div_k_mean",) + tuple(sorted(
    (set(attributes.CORE_NAME.values()) | {"solver", "ordering", "max_iterations", "reuse_ordering",
                                           "cholmod_openmp_teams"}) - {"max_k_div_k_mean"}))
_SAVED_GUARD_SETTINGS = ("safety", "strict", "iterations", "iterations_warm")


# Python-side state of a FlowEngine (not YADE attributes), set as plain instance attributes.
_INTERNAL = frozenset({
    "_core",                  # the C++ engine
    "_key",                   # its key in _engines
    "_lock",                  # held by a step and by every query (O.run steps on YADE's own thread)
    "_scan",                  # the last SceneScan, None before the first step
    "_stepped",               # the SceneScan of the last successful step: the current mesh's spheres
    "_scene_tag",             # the value this engine left in O.tags: a new scene lacks it
    "_last_step",             # (O.iter, O.time, dt) of the last successful step, None: no history
    "_guard",                 # the TimeStepGuard
    "_timings",               # the StageTimings shown by timing.stats()
    "_boundary_use_max_min",  # boundaryUseMaxMin
    "_wall_ids",              # wallIds
    "_warned",                # the one-time warnings given
    "_choice_builds",         # core.system_builds when the solver choice was last looked at
    "_threads",               # ompThreads, None: follow YADE's -j
    "_use_sphere_pack",       # False: always read the coordinate lists
}) | CELL_INTERNAL | FIELD_INTERNAL


def _guard_setting(name: str, doc: str) -> property:
    """A FlowEngine property that reads and writes the TimeStepGuard's attribute `name`."""
    return property(lambda self: getattr(self._guard, name), lambda self, value: setattr(self._guard, name, value),
                    doc=doc)


class FlowEngine(BoundaryPressure, CellInterface, PyRunner):
    """PFV's DEM-PFV flow engine with the interface of YADE's FlowEngine."""

    xmin, xmax, ymin, ymax, zmin, zmax = range(6)

    def __init__(self, **kwargs: Any) -> None:
        PyRunner.__init__(self)
        self._core = Engine()
        self._key = id(self)
        self._lock = threading.RLock()
        self._timings = StageTimings()
        self._stepped = None
        self._scene_tag = None
        self._last_step = None
        self._boundary_use_max_min = [True] * 6
        self._wall_ids = list(range(6))
        self._warned = set()
        self._choice_builds = 0
        self._scan = None
        self._use_sphere_pack = True
        self._threads = None
        self._guard = TimeStepGuard()
        _engines[self._key] = self
        self.command = _COMMAND.format(self._key)
        self.iterPeriod = 1
        self.initRun = True
        for name, value in kwargs.items():
            setattr(self, name, value)

    # -- attribute surface -------------------------------------------------------------
    def __setattr__(self, name: str, value: Any) -> None:
        if name in attributes.CORE_NAME:
            core_name = attributes.CORE_NAME[name]
            value = attributes.as_setting(name, value, getattr(self._core, core_name))
            with self._lock:
                try:
                    setattr(self._core, core_name, value)
                except ValueError as error:
                    raise ValueError(f"pfv.FlowEngine.{name}: {error}") from None
        elif name in _INTERNAL or name in _OWN_ATTRIBUTES:
            object.__setattr__(self, name, value)
        elif attributes.is_yade_attribute(name):
            attributes.check_default(name, value)
        else:
            raise attributes.unknown_attribute(name, setting=True)

    def __getattr__(self, name: str) -> Any:  # only called when normal lookup fails
        if name in attributes.CORE_NAME:
            return getattr(self._core, attributes.CORE_NAME[name])
        if attributes.is_yade_method(name):
            raise attributes.unsupported_method(name)
        if attributes.is_yade_attribute(name):
            return attributes.default(name)
        raise attributes.unknown_attribute(name, setting=False)

    @property
    def bndCondIsPressure(self) -> list[bool]:
        return list(self._core.bnd_is_pressure)

    @bndCondIsPressure.setter
    def bndCondIsPressure(self, value: Sequence[bool]) -> None:
        self._core.bnd_is_pressure = attributes.as_bool6("bndCondIsPressure", value)

    @property
    def bndCondValue(self) -> list[float]:
        return list(self._core.bnd_value)

    @bndCondValue.setter
    def bndCondValue(self, value: Sequence[float]) -> None:
        self._core.bnd_value = attributes.as_float6("bndCondValue", value)

    @property
    def boundaryUseMaxMin(self) -> list[bool]:
        return list(self._boundary_use_max_min)

    @boundaryUseMaxMin.setter
    def boundaryUseMaxMin(self, value: Sequence[bool]) -> None:
        value = attributes.as_bool6("boundaryUseMaxMin", value)
        if value != self._boundary_use_max_min:
            self._boundary_use_max_min = value
            self._core.request_remesh()
            self._core.reset_history()

    @property
    def wallIds(self) -> list[int]:
        return list(self._wall_ids)

    @wallIds.setter
    def wallIds(self, value: Sequence[int]) -> None:
        value = attributes.as_wall_ids(value)
        if value != self._wall_ids:
            self._wall_ids = value
            if self._scan is not None:
                self._scan.outdated = True
            self._core.reset_history()

    @property
    def useSolver(self) -> int:
        """YADE's solver number: 0 Gauss-Seidel, 1 conjugate gradients (PFV), 3 CHOLMOD (also for
        solver='auto'), -1 for solver='multigrid', which YADE lacks."""
        return attributes.use_solver_of(self._core.solver)

    @useSolver.setter
    def useSolver(self, value: int) -> None:
        self._core.solver = attributes.solver_of_use_solver(value)

    @property
    def updateTriangulation(self) -> bool:
        return self._core.remesh_due()

    @updateTriangulation.setter
    def updateTriangulation(self, value: bool) -> None:
        if value:
            self._core.request_remesh()

    @property
    def ompThreads(self) -> int:
        """Threads of the engine's parallel loops; -1 follows YADE's thread count (yade -jN)."""
        return -1 if self._threads is None else self._threads

    @ompThreads.setter
    def ompThreads(self, value: int) -> None:
        if not isinstance(value, numbers.Integral) or isinstance(value, bool):
            raise TypeError(f"ompThreads must be an integer, got {value!r}")
        if value > _MAX_THREADS:
            raise ValueError(f"ompThreads = {value} is more than {_MAX_THREADS} threads")
        self._threads = int(value) if value > 0 else None

    # -- time-step guard settings (held by the TimeStepGuard) --------------------------------
    time_step_safety = _guard_setting(
        "safety", "O.dt must stay below time_step_safety * critical_time_step (zeta of thesis 4.22); 0.8.")
    strict_time_step = _guard_setting(
        "strict", "True: an unsafe O.dt raises ValueError instead of warning (TimeStepWarning).")
    collective_iterations = _guard_setting(
        "iterations", "Operator applications at most for the collective limit of the first mesh (cold start); 40.")
    collective_iterations_warm = _guard_setting(
        "iterations_warm", "Operator applications at most for the collective limit of a later mesh (warm start); 10.")

    # -- the step ---------------------------------------------------------------------------
    def _rescan(self) -> SceneScan:
        """Scan the bodies again (sphere ids, radii, masses, walls); done at each remesh (bodies may change)."""
        self._apply_id_offset()
        self._scan = SceneScan(self._wall_ids, self._boundary_use_max_min, use_sphere_pack=self._use_sphere_pack,
                               warned=self._warned, previous=self._scan, **self._scan_options())
        return self._scan

    def _scanned(self) -> SceneScan:
        """The current scan; scans first if there is none or wallIds changed since."""
        if self._scan is None or self._scan.outdated:
            return self._rescan()
        return self._scan

    @property
    def position_source(self) -> str:
        """Where the sphere centres come from each step: "SpherePack" (YADE's C++ copy of the
        bodies' centres, read in place) or "coordinate lists" (yade._utils.coordsAndDisplacements,
        one Python list per axis; used when the pack's layout does not check out)."""
        return "coordinate lists" if self._scan is None else self._scan.position_source

    def _read_positions(self) -> tuple[np.ndarray, list[float]] | None:
        """Sphere centres (n, 3) and the six boundary coordinates, or None if bodies were erased
        since the last scan."""
        return self._scan.read_positions(self._boundary_use_max_min)

    def _in_scene(self, scene: Any) -> bool:
        """Whether this engine last ran in `scene` (which then holds its tag)."""
        try:
            return self._scene_tag is not None and scene.tags[f"{_SCENE_TAG}.{self._key}"] == self._scene_tag
        except KeyError:
            return False

    @_exclusive
    def _release(self) -> None:
        """Free the mesh and the scan (settings kept): the next step starts afresh."""
        self._core.release()
        self._scan = self._stepped = None
        self._last_step = None
        _holding.discard(self._key)

    def _notice_new_scene(self, scene: Any) -> None:
        """After O.reset() (or O.switchScene) the engine may be put into a scene it has never
        seen, possibly with as many bodies as the last one: forget everything of the old one."""
        if self._in_scene(scene):
            return
        if self._scene_tag is not None:  # not the first step: a new scene
            # The collective limit follows with the new mesh (its history and the mode that warm
            # starts it carry over: the mode is only a starting vector).
            self._scan = self._stepped = None
            self._core.request_remesh()
            self._core.reset_history()
            self._last_step = None
        self._scene_tag = uuid.uuid4().hex
        scene.tags[f"{_SCENE_TAG}.{self._key}"] = self._scene_tag

    def _time_since_last_step(self, scene: Any) -> float:
        """The time the positions moved over since the last step of this engine, or O.dt with the
        history forgotten when that step was not the last iteration's run of the engine (it was
        dead, its iterPeriod skipped, or the last step failed): dV/dt must not span a gap."""
        last = self._last_step
        period = max(1, int(self.iterPeriod))
        if last is not None and scene.iter - last[0] == period:
            return scene.dt if period == 1 else scene.time - last[1]
        if last is not None:
            self._core.reset_history()
        return scene.dt

    @_exclusive
    def _step(self) -> None:
        if not self._pressure_force:  # YADE's pressureForce=False: no flow at all
            return
        scene = yade.O
        core = self._core
        clock = StepClock(self._timings) if scene.timingEnabled else None
        self._notice_new_scene(scene)
        scan = self._scan
        bodies_changed = scan is None or scan.outdated or len(scene.bodies) != scan.n_bodies
        if bodies_changed or core.remesh_due():
            self._rescan()  # radii and masses may have changed too
            if bodies_changed:
                core.request_remesh()
        read = self._read_positions()
        if read is None:  # bodies erased (which leaves len(O.bodies) as it was)
            self._rescan()
            core.request_remesh()
            read = self._read_positions()
        scan = self._scan
        pos, walls = read
        set_num_threads(self._threads or scene.numThreads)
        if clock:
            clock.lap("scan and positions")
        dt = self._time_since_last_step(scene)
        if core.fluid_density > 0:  # buoyancy under the NewtonIntegrator's gravity
            core.gravity = _gravity(scene)
        # Before the step, only limits known for the mesh the step will use (a mesh about to be
        # rebuilt, or conductances about to change, have no limit yet: checked after the step).
        self._check_time_step(scene.dt, scan, before_step=True)
        remeshing = core.remesh_due()
        inversions, meshes = core.inversion_remeshes, core.remesh_count
        before = (core.remesh_count, core.system_builds) if self._after_step_reports else None
        if self._desired_porosity:
            self._correct_volumes(pos, scan.radii)
        if clock:
            clock.lap("time-step guard")
        if self._pressure_function is not None:
            self._prepare_pressure(scene, walls)
        with self._bodies_named(scan):
            if self._block_hook and remeshing and not core.background_remesh:
                self._remesh_for_block_hook(pos, scan, walls)  # blockHook, between the mesh and its system
            core.step(pos, scan.radii, walls, dt)
        if clock:
            clock.core_step(core, core.remesh_count != meshes)
        self._stepped = scan
        self._last_step = (scene.iter, scene.time, dt)  # dt: the time this step's dV/dt spanned
        _holding.add(self._key)
        _release_unused(self)
        if self._guard.unchecked(core):
            # A new mesh (the first, or a remesh adopted by this step) or new conductances: its
            # collective limit may be lower (a compacting sample), check again.
            self._check_time_step(scene.dt, scan)
        if not core.converged and "unconverged" not in self._warned:
            self._warned.add("unconverged")
            warnings.warn(f"pfv.FlowEngine: at iteration {scene.iter} the {core.solver.replace('_', ' ')} solve "
                          f"stopped at {core.max_iterations} iterations above tolerance = {core.tolerance:g}; "
                          "the pressures are not converged (raise the tolerance or use useSolver=3)", stacklevel=2)
        if core.inversion_remeshes != inversions and "inverted" not in self._warned:
            self._warned.add("inverted")
            warnings.warn(f"pfv.FlowEngine: at iteration {scene.iter} spheres had moved so far since the last "
                          "remesh that pore cells were turned inside out; remeshed (and will again whenever "
                          "this happens). Lower meshUpdateInterval or defTolerance for motion this fast",
                          stacklevel=2)
        # The choice changes only with a new system: look at it once per build, not per step.
        if "auto multigrid" not in self._warned and core.system_builds != self._choice_builds:
            self._choice_builds = core.system_builds
            choice = core.solver_choice
            if core.solver == "auto" and choice.startswith("multigrid: the Cholesky"):  # not "kept from ..."
                self._warned.add("auto multigrid")
                bound = ", or raise max_factor_bytes" if "budget" in choice else ""  # not CHOLMOD's index range
                warnings.warn(f"pfv.FlowEngine: solver='auto' solves by multigrid from iteration {scene.iter}: "
                              f"{choice[len('multigrid: '):]}. Set solver='multigrid' to skip the Cholesky "
                              f"analysis at the start{bound}", stacklevel=2)
        if remeshing or core.inversion_remeshes != inversions:
            hidden = core.hidden_spheres()
            if hidden:
                yade_ids = scan.ids[hidden][:10].tolist()
                warnings.warn(f"pfv.FlowEngine: {len(hidden)} spheres are hidden by larger neighbours in the "
                              f"regular triangulation and get no fluid force (ids {yade_ids}...)",
                              stacklevel=2)
        if clock:
            clock.lap("time-step guard and warnings")
        if self._after_step_reports:
            self._report_step(before)
        # The engine's force array is read in C++, without a numpy copy.
        if not self._decouple_forces:
            scan.force_bridge.apply(scene.forces.addF, core)
        if clock:
            clock.lap("forces to YADE")

    @property
    def timingDeltas(self) -> StageTimings:
        """The engine's stages for YADE's timing.stats() while O.timingEnabled (_timing.py)."""
        return self._timings

    @contextlib.contextmanager
    def _bodies_named(self, scan: SceneScan):
        """Errors of the core name spheres by their index in the scan and walls by number: say
        which YADE body is meant, and which sphere set a wall placed by boundaryUseMaxMin."""
        try:
            yield
        except (ValueError, RuntimeError) as error:
            message = re.sub(r"sphere (\d+)", lambda m: f"sphere #{scan.ids[int(m.group(1))]}", str(error))
            setters = [scan.describe_wall_setter(int(w)) for w in sorted(set(re.findall(r"walls? (\d)", message)))]
            setters = [s for s in setters if s]
            if setters:
                message += " (" + "; ".join(setters) + ")"
            raise type(error)(f"pfv.FlowEngine: {message}") from None

    @property
    @_exclusive
    def viscous_time_step(self) -> float:
        """dt_MV = pi rho d^2 / (1200 mu) at the smallest rho d^2 of the coupled dynamic spheres (thesis 4.20)."""
        return viscous_time_step(self._scanned().mass_per_diameter, self._core.viscosity)

    @property
    def collective_viscous_time_step(self) -> float:
        """2 / lambda_max(M^-1 V) of the current mesh: the viscous limit of the explicit coupling
        for collective motions (groups of spheres squeezing shared pores), which the thesis'
        single-particle dt_MV overestimates (0.3-0.5 dt_MV measured on dense packings).
        Computed when asked for, or by the time-step guard on a new mesh (or a new viscosity) when
        the certified bound on it (collective_viscous_bound) cannot show O.dt safe: by Arnoldi from
        a fixed start (at most collective_iterations = 40 operator applications, stopping once the
        estimate settles to 1e-6 or its Arnoldi residual is below 1e-3 of it), or by power iteration
        started from the mode of the mesh just before, if computed there (at most
        collective_iterations_warm = 10). Each operator application
        costs one back-substitution and one force evaluation; see collective_viscous_history
        ("iterations" there is the count made, "max_iterations" the cap, "seconds" the cost)."""
        with self._lock:
            if not self._core.has_mesh() or self._stepped is None:
                return float("inf")
            # The masses of the spheres the mesh holds (even if bodies or wallIds changed since).
            return self._guard.collective_limit(self._core, self._stepped.masses, yade.O.iter)

    @property
    def collective_viscous_bound(self) -> float:
        """The best certified lower bound on collective_viscous_time_step without computing it: the
        larger of the global bound (about one solve, up to four orders of magnitude below the limit;
        what the time-step guard checks O.dt against first) and the local one (small problems around
        each sphere, within an order of magnitude of the limit, several times the cost of the global
        one). O.dt = time_step_safety * min(this, dt_MV, P-wave step) is safe. 0 with viscousShear,
        which neither covers (doc/model.md, "Coupled time step")."""
        with self._lock:
            if not self._core.has_mesh() or self._stepped is None:
                return float("inf")
            masses = self._stepped.masses
            return max(self._core.viscous_stability_bound(masses), self._core.viscous_stability_local_bound(masses))

    @property
    def collective_viscous_history(self) -> list[dict[str, Any]]:
        """One dict per computation of the collective limit or its bound: iter, remesh_count, limit [s],
        method ("bound": the certified lower bound; "arnoldi"; "power": from the previous mesh's mode),
        iterations (operator applications made, each a solve and a force evaluation), max_iterations
        (the cap), warm (method == "power"), seconds (wall time)."""
        return self._guard.history

    @property
    def critical_time_step(self) -> float:
        """min(dt_MV, collective viscous limit, DEM P-wave limit): O.dt should not exceed
        time_step_safety times this."""
        with self._lock:
            scan = self._scanned()
            return min(self.viscous_time_step, self.collective_viscous_time_step, scan.dt_dem)

    def _check_time_step(self, dt: float, scan: SceneScan | None = None, before_step: bool = False) -> None:
        """Warn or raise (strict_time_step) if dt exceeds time_step_safety * critical_time_step,
        with the single-particle and DEM limits of `scan` (None: the current scan) and the collective
        limit of the current mesh, or its certified bound where that suffices (_time_step.py).
        `before_step`: the mesh may be about to change, nothing is computed for it then."""
        if scan is None:
            scan = self._scanned()
        dt_mv = viscous_time_step(scan.mass_per_diameter, self._core.viscosity)
        collective = float("inf")
        if self._stepped is not None:  # the masses of the spheres the mesh holds
            collective = self._guard.limit_to_check(self._core, self._stepped.masses, dt, min(dt_mv, scan.dt_dem),
                                                    yade.O.iter, before_step)
        self._guard.check(dt, dt_mv, collective, scan.dt_dem)

    def emulateAction(self) -> None:
        """Run one flow step outside the time-stepping loop, as YADE's method does."""
        self._step()

    # -- boundary conditions --------------------------------------------------------------
    @_exclusive
    def updateBCs(self) -> None:
        """Apply changed boundary values and types (PFV applies values at every step anyway)."""
        self._core.request_system_rebuild()

    @_exclusive
    def imposePressure(self, pos: Sequence[float], p: float) -> int:
        """Impose pressure p in the cell containing pos; returns the condition's index. A point
        outside the pore space is refused (at once once there is a mesh, else at the first step)."""
        return self._core.impose_pressure(attributes.as_point("imposePressure position", pos),
                                          attributes.as_number("imposePressure pressure", p))

    @_exclusive
    def setImposedPressure(self, cond: int, p: float) -> None:
        """Change the pressure of the imposed condition number cond."""
        self._core.set_imposed_pressure(int(cond), attributes.as_number("setImposedPressure pressure", p))

    @_exclusive
    def clearImposedPressure(self) -> None:
        self._core.clear_imposed_pressure()

    @_exclusive
    def imposeFlux(self, pos: Sequence[float], p: float) -> None:
        """YADE's sign: outflux positive, influx negative. A point outside the pore space is refused."""
        self._core.impose_flux(attributes.as_point("imposeFlux position", pos),
                               -attributes.as_number("imposeFlux flux", p))

    @_exclusive
    def clearImposedFlux(self) -> None:
        self._core.clear_imposed_flux()

    # -- queries: each waits for a step in progress on YADE's simulation thread -------------
    def _require_mesh(self) -> None:
        if not self._core.has_mesh() or self._stepped is None:
            raise RuntimeError("the flow engine has not run yet: no pore mesh (run at least one step)")

    def _cell_at(self, pos: Sequence[float]) -> int:
        self._require_mesh()
        cell = self._core.locate(attributes.as_point("position", pos))
        if cell < 0:
            raise ValueError(f"point {tuple(pos)} lies in no pore cell (outside the walls or the packing)")
        return cell

    def _vertex_of(self, body_id: int) -> int:
        self._require_mesh()
        v = self._stepped.vertex_of_id.get(int(body_id))
        if v is None:
            raise ValueError(f"body {body_id} is not coupled with the fluid (not a sphere nor a wall)")
        return v

    @_exclusive
    def getPorePressure(self, pos: Sequence[float]) -> float:
        return self._core.cell_pressure(self._cell_at(pos))

    @_exclusive
    def getCell(self, X: float, Y: float, Z: float) -> int:
        self._require_mesh()
        return self._core.locate(attributes.as_point("getCell position", (X, Y, Z)))

    @_exclusive
    def getCellPressure(self, id: int) -> float:
        return self._core.cell_pressure(int(id))

    @_exclusive
    def getCellCenter(self, id: int) -> Vector3:
        return Vector3(*self._core.cell_center(int(id)))

    @_exclusive
    def getCellVolume(self, pos: Sequence[float]) -> float:
        return self._core.cell_volume(self._cell_at(pos))

    @_exclusive
    def getBoundaryFlux(self, boundary: int) -> float:
        self._require_mesh()
        wall_ids = self._stepped.wall_ids  # those of the last step, if wallIds changed since
        if boundary not in wall_ids:
            raise ValueError(f"body {boundary} is not one of the boundaries wallIds = {wall_ids}")
        return self._core.boundary_flux(wall_ids.index(boundary))

    @_exclusive
    def fluidForce(self, idSph: int) -> Vector3:
        return Vector3(*self._core.forces()[self._vertex_of(idSph)])

    @_exclusive
    def shearLubForce(self, idSph: int) -> Vector3:
        """The viscous shear part of fluidForce(idSph) (viscousShear; zero while it is off).
        YADE's name: its shearLubForce reports the viscousShear force as well."""
        v = self._vertex_of(idSph)
        shear = self._core.shear_forces()
        return Vector3(*shear[v]) if len(shear) else Vector3(0, 0, 0)

    @_exclusive
    def nCells(self) -> int:
        return self._core.n_cells()

    @_exclusive
    def averagePressure(self) -> float:
        self._require_mesh()
        return self._core.average_pressure()

    @_exclusive
    def averageSlicePressure(self, posY: float, axis: int = 1) -> float:
        self._require_mesh()
        return self._core.average_slice_pressure(int(axis), attributes.as_number("averageSlicePressure position", posY))

    @_exclusive
    def metisUsed(self) -> bool:
        return self._core.metis_used()

    @_exclusive
    def absolute_pressure(self, pos: Sequence[float]) -> float:
        """The pore pressure at pos with its hydrostatic part: getPorePressure(pos) + fluid_density g.(pos - top),
        `top` the centre of the wall that faces up (against gravity's largest component). Equals the
        excess pressure without buoyancy (fluid_density = 0)."""
        p = self._core.cell_pressure(self._cell_at(pos))
        rho = self._core.fluid_density
        if rho == 0:
            return p
        g = np.array(self._core.gravity)
        walls = self._core.walls()
        top = np.array([(walls[0] + walls[1]) / 2, (walls[2] + walls[3]) / 2, (walls[4] + walls[5]) / 2])
        axis = int(np.abs(g).argmax())
        top[axis] = walls[2 * axis + 1] if g[axis] < 0 else walls[2 * axis]
        return p + rho * float(g @ (np.asarray(attributes.as_point("position", pos)) - top))

    # -- O.save / O.load (_persistence) -----------------------------------------------------
    @staticmethod
    def drives(command: str) -> bool:
        """Whether a PyRunner command is that of a pfv.FlowEngine (a restored one after a load)."""
        return command.startswith(_COMMAND.split("{")[0])

    @_exclusive
    def _saved_state(self) -> dict[str, Any]:
        """Everything a new engine needs to go on where this one is: settings, boundary conditions,
        the Python-side settings and, once it has run, the core's run state."""
        core = self._core
        running = core.has_mesh() and self._stepped is not None
        if self.boundary_pressure is not None and "unsaved function" not in self._warned:
            self._warned.add("unsaved function")
            warnings.warn("pfv.FlowEngine: the function of set_boundary_pressure is not saved with the scene; "
                          "set it again after O.load", stacklevel=3)
        return {
            "core": {name: getattr(core, name) for name in _SAVED_CORE_SETTINGS},
            "bnd_is_pressure": list(core.bnd_is_pressure),
            "bnd_value": list(core.bnd_value),
            "imposed_pressures": core.imposed_pressures(),
            "imposed_fluxes": core.imposed_fluxes(),
            "boundary_use_max_min": list(self._boundary_use_max_min),
            "wall_ids": list(self._wall_ids),
            "threads": self._threads,
            "use_sphere_pack": self._use_sphere_pack,
            "mixin": {name: getattr(self, name) for name in sorted(CELL_INTERNAL - CELL_CACHES)},
            "waves": {"wave_action": self._wave_action, "sine_magnitude": self._sine_magnitude,
                      "sine_average": self._sine_average},
            "guard": {name: getattr(self._guard, name) for name in _SAVED_GUARD_SETTINGS},
            "runner": {name: getattr(self, name) for name in ("iterPeriod", "dead", "initRun")},
            "last_step": list(self._last_step) if running and self._last_step else None,
            "run": core.run_state() if running else None,
        }

    @classmethod
    def _from_saved(cls, state: dict[str, Any], runner: PyRunner) -> FlowEngine:
        """A new engine from _saved_state() in the loaded scene, in place of the restored `runner`."""
        engine = cls()
        core = engine._core
        for name in _SAVED_CORE_SETTINGS:
            setattr(core, name, state["core"][name])
        core.bnd_is_pressure = state["bnd_is_pressure"]
        core.bnd_value = state["bnd_value"]
        for pos, p in state["imposed_pressures"]:
            core.impose_pressure(tuple(pos), p)
        for pos, q in state["imposed_fluxes"]:
            core.impose_flux(tuple(pos), q)
        engine._boundary_use_max_min = list(state["boundary_use_max_min"])
        engine._wall_ids = list(state["wall_ids"])
        engine._threads = state["threads"]
        engine._use_sphere_pack = state["use_sphere_pack"]
        for name, value in state["mixin"].items():
            setattr(engine, name, _as_tuples(value))
        waves = state.get("waves", {})
        engine.sineMagnitude = waves.get("sine_magnitude", 0.0)
        engine.sineAverage = waves.get("sine_average", 0.0)
        engine.waveAction = waves.get("wave_action", False)
        for name, value in state["guard"].items():
            setattr(engine._guard, name, value)
        for name, value in state["runner"].items():
            setattr(engine, name, value)
        engine.label = runner.label
        if state["run"] is not None:
            scene = yade.O
            engine._notice_new_scene(scene)
            core.resume(state["run"], scene.dt)
            engine._stepped = engine._rescan()
            engine._last_step = tuple(state["last_step"])
            _holding.add(engine._key)
        return engine

    # -- output ------------------------------------------------------------------------------
    def saveVtk(self, folder: str | os.PathLike = "./VTK", withBoundaries: bool = False,
                compress: bool = False) -> None:
        """Write the pore network (pressure, mean fluid velocity, imposed-pressure flag, volumes) and the spheres
        (radii, ids, fluid forces) of the last step into `folder` as VTK XML files for ParaView: out_<N>.vtu,
        spheres_<N>.vtu and the collection out.pvd of every snapshot this process wrote there, at O.time.
        withBoundaries=False leaves out the cells with a wall vertex (YADE's default); compress=True compresses
        the data with zlib. See doc/yade.md, "VTK output"."""
        if not isinstance(folder, (str, os.PathLike)):
            raise TypeError(f"saveVtk folder must be a path, got {folder!r}")
        with_boundaries = attributes.as_flag("saveVtk withBoundaries", withBoundaries)
        compress = attributes.as_flag("saveVtk compress", compress)
        try:
            from . import _vtk_output
        except ImportError as error:
            raise ImportError(f"pfv.FlowEngine.saveVtk needs VTK's Python package (Debian: apt-get install "
                              f"python3-vtk9): {error}") from None
        with self._lock:
            self._require_mesh()
            scan = self._stepped
            state = _vtk_output.read_state(self._core, scan.ids, scan.radii, scan.wall_ids, yade.O.time)
        _vtk_output.save(state, os.fspath(folder), with_boundaries, compress)

    # -- PFV extras -------------------------------------------------------------------------
    @property
    def core(self) -> Engine:
        """The C++ engine (pfv.Engine): geometry, timings and diagnostics."""
        return self._core


# Names set as ordinary attributes: PyRunner's (command, iterPeriod, label, ...) and the properties
# of FlowEngine and its mixin.
_OWN_ATTRIBUTES = frozenset(a for a in dir(PyRunner) if not a.startswith("__")) | {
    name for klass in FlowEngine.__mro__ for name, v in vars(klass).items() if isinstance(v, property)}

_persistence.install()  # O.save / O.load carry the engines' state
