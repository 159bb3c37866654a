"""YADE adapter: ``pfv.FlowEngine``, a drop-in replacement for YADE's FlowEngine.

The object is a PyRunner placed in ``O.engines`` like YADE's engine (after the
InteractionLoop, before NewtonIntegrator). Each step it reads the sphere positions in bulk,
runs the C++ pipeline (remesh when due, dV/dt, solve, forces) and adds the fluid forces to
the spheres and to the six wall bodies. Attribute names and sign conventions are YADE's.

An attribute YADE's FlowEngine has but PFV does not support may only be set to YADE's
default value; any other value raises NotImplementedError naming it. Misspelt names raise
AttributeError. Nothing is silently ignored.

The engine composes parts, each owning its state, and forwards YADE's names to them
(``_forwarding``): the coupled bodies (``_coupled_bodies``), the run history
(``_run_history``), the time-step limits (``_time_step_limits``), the boundary pressures
(``_boundary_pressure``), the step's options, reports and warnings (``_step_options``,
``_step_reports``, ``_step_warnings``), the settings kept for YADE's scripts
(``_kept_settings``), the cells (``_cell_geometry``, ``_flow_queries``, ``_cell_conditions``)
and the file outputs (``_file_outputs``). The attribute surface's rules are in ``_attributes``.
"""
from __future__ import annotations

import secrets
import threading
import warnings
from collections.abc import Sequence
from typing import Any

import numpy as np

import yade
from yade.wrapper import NewtonIntegrator, PyRunner

from . import _attributes as attributes
from . import _lifecycle
from . import _persistence
from . import _registry as registry
from ._boundary_pressure import BoundaryPressure
from ._cell_conditions import CellConditions
from ._cell_geometry import CellGeometry
from ._core import get_max_threads, set_num_threads
from ._engine import Engine
from ._coupled_bodies import CoupledBodies
from ._file_outputs import FileOutputs
from ._flow_queries import FlowQueries
from ._forwarding import exclusive, method, setting
from ._kept_settings import KeptSettings
from ._run_history import RunHistory
from ._scene_scan import SceneScan
from ._step_options import StepOptions
from ._step_reports import StepReports
from ._step_warnings import StepWarnings, StepWatch
from ._time_step import TimeStepWarning
from ._time_step_limits import TimeStepLimits
from ._timing import IdleClock, StageTimings, StepClock

__all__ = ["FlowEngine", "TimeStepWarning"]

_MAX_THREADS = 1024  # ompThreads beyond this is a typo, not a machine
_COMMAND = "__import__('pfv.flow_engine').flow_engine._run({})"  # in saved scenes: keep the name _run
_IDLE_CLOCK = IdleClock()


def _run(key: int) -> None:
    _persistence.running_engine(registry.get(key), _COMMAND.format(key), "FlowEngine")._step()


def _gravity(scene: Any) -> tuple[float, float, float]:
    """The gravity of the scene's NewtonIntegrator (zero without one)."""
    for engine in scene.engines:
        if isinstance(engine, NewtonIntegrator):
            return tuple(engine.gravity)
    return (0.0, 0.0, 0.0)


# The core's settings saved with a scene: every one a user may set (YADE's names map onto most).
# The upper clamp first: restoring must never meet a lower bound above the default upper one.
_SAVED_CORE_SETTINGS = ("max_k_div_k_mean",) + tuple(
    sorted(
        (
            set(attributes.CORE_NAME.values())
            | {"solver", "ordering", "max_iterations", "reuse_ordering", "cholmod_openmp_teams"}
        )
        - {"max_k_div_k_mean"}
    )
)

# The engine's own fields (plain instance attributes, not YADE attributes): the core, the engine's
# key in the registry, its lock, its timings, ompThreads, and its parts.
_FIELDS = frozenset(
    {
        "_core",
        "_key",
        "_lock",
        "_timings",
        "_threads",
        "_warnings",
        "_history",
        "_bodies",
        "_time_step",
        "_loads",
        "_options",
        "_reports",
        "_kept",
        "_geometry",
        "_flow",
        "_conditions",
        "_outputs",
    }
)
# The parts saved with a scene, under these keys.
_SAVED_PARTS = {
    "bodies": "_bodies",
    "loads": "_loads",
    "options": "_options",
    "reports": "_reports",
    "kept": "_kept",
    "cells": "_geometry",
    "guard": "_time_step",
}


class FlowEngine(PyRunner):
    """PFV's DEM-PFV flow engine with the interface of YADE's FlowEngine."""

    xmin, xmax, ymin, ymax, zmin, zmax = range(6)

    def __init__(self, **kwargs: Any) -> None:
        PyRunner.__init__(self)
        self._core = core = Engine()
        self._key = secrets.randbits(62)  # unlike id(), never that of an engine saved by another process
        self._lock = threading.RLock()  # held by a step and by every query (O.run steps on its own thread)
        self._timings = StageTimings()
        self._threads = None  # ompThreads, None: follow YADE's -j
        self._warnings = StepWarnings()
        self._history = RunHistory(self._key)
        self._bodies = CoupledBodies(core, self._warnings.given)
        self._time_step = TimeStepLimits(core, self._bodies)
        self._loads = BoundaryPressure(core)
        self._options = StepOptions(core)
        self._reports = StepReports(core)
        self._kept = KeptSettings()
        self._geometry = CellGeometry(core, self._bodies, self._history)
        self._flow = FlowQueries(core, self._bodies, self._geometry)
        self._conditions = CellConditions(core, self._geometry, self._flow)
        self._outputs = FileOutputs(core, self._bodies, self._lock)
        registry.add(self)
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
                    self._core.assign(core_name, value)
                except (TypeError, ValueError) as error:
                    raise type(error)(f"pfv.FlowEngine.{name}: {error}") from None
        elif name in _RUNNER_ATTRIBUTES:
            self._set_runner_attribute(name, value)
        elif name in _FIELDS or name in _OWN_ATTRIBUTES:
            member = getattr(type(self), name, None)
            if isinstance(member, property) and member.fset is None:
                raise AttributeError(f"{name} is read-only (computed by the engine)")
            object.__setattr__(self, name, value)
        elif attributes.is_yade_attribute(name):
            attributes.check_default(name, value)
        else:
            raise attributes.unknown_attribute(name, setting=True)

    def _set_runner_attribute(self, name: str, value: Any) -> None:
        """An attribute of YADE's PyRunner: YADE's converter checks it; its refusal names the attribute
        here. The command drives this engine (and its saved state): it is the engine's own."""
        current = getattr(self, name)
        if name == "command" and current and isinstance(value, str) and value != current:
            raise ValueError("command drives this pfv.FlowEngine and cannot be changed (create a PyRunner instead)")
        try:
            object.__setattr__(self, name, value)
        except TypeError:  # Boost.Python's ArgumentError, which names neither
            raise TypeError(
                f"pfv.FlowEngine.{name} (YADE's PyRunner attribute) must be a {type(current).__name__}, "
                f"got {value!r}"
            ) from None

    def __getattr__(self, name: str) -> Any:  # only called when normal lookup fails
        if name in attributes.CORE_NAME:
            return getattr(self._core, attributes.CORE_NAME[name])
        if attributes.is_yade_method(name):
            raise attributes.unsupported_method(name)
        if attributes.is_yade_attribute(name):
            return attributes.default(name)
        raise attributes.unknown_attribute(name, setting=False)

    # -- the core's boundary conditions and solver, and the engine's threads --------------------
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
    def useSolver(self) -> int:
        """YADE's solver number: 0 Gauss-Seidel, 1 conjugate gradients (PFV), 3 the direct solve (solver='auto',
        PFV's default, which takes multigrid where the factor would not fit or its step costs more; also read for
        solver='cholesky'), -1 for solver='multigrid', which YADE lacks. Setting 3 sets solver='auto'."""
        return attributes.use_solver_of(self._core.solver)

    @useSolver.setter
    def useSolver(self, value: int) -> None:
        self._core.solver = attributes.solver_of_use_solver(value)

    @property
    def updateTriangulation(self) -> bool:
        return self._core.remesh_due()

    @updateTriangulation.setter
    def updateTriangulation(self, value: bool) -> None:
        if attributes.as_flag("updateTriangulation", value):
            self._core.request_remesh()

    @property
    def ompThreads(self) -> int:
        """Threads of the engine's parallel loops; -1 follows YADE's thread count (yade -jN)."""
        return -1 if self._threads is None else self._threads

    @ompThreads.setter
    def ompThreads(self, value: int) -> None:
        value = attributes.as_integer("ompThreads", value)
        if value > _MAX_THREADS:
            raise ValueError(f"ompThreads = {value} is more than {_MAX_THREADS} threads")
        self._threads = value if value > 0 else None

    # -- the coupled bodies (_coupled_bodies) -----------------------------------------------
    boundaryUseMaxMin = setting("_bodies", CoupledBodies.boundaryUseMaxMin)
    wallIds = setting("_bodies", CoupledBodies.wallIds)
    convertClumps = setting("_bodies", CoupledBodies.convertClumps)
    mask = setting("_bodies", CoupledBodies.mask)
    wallThickness = setting("_bodies", CoupledBodies.wallThickness)
    idOffset = setting("_bodies", CoupledBodies.idOffset)
    position_source = setting("_bodies", CoupledBodies.position_source)
    setBoundaryNormal = method("_bodies", CoupledBodies.setBoundaryNormal)

    # -- the time-step limits (_time_step_limits) ---------------------------------------------
    time_step_safety = setting("_time_step", TimeStepLimits.time_step_safety)
    strict_time_step = setting("_time_step", TimeStepLimits.strict_time_step)
    collective_iterations = setting("_time_step", TimeStepLimits.collective_iterations)
    collective_iterations_warm = setting("_time_step", TimeStepLimits.collective_iterations_warm)
    viscous_time_step = setting("_time_step", TimeStepLimits.viscous_time_step)
    collective_viscous_time_step = setting("_time_step", TimeStepLimits.collective_viscous_time_step)
    collective_viscous_bound = setting("_time_step", TimeStepLimits.collective_viscous_bound)
    collective_viscous_history = setting("_time_step", TimeStepLimits.collective_viscous_history)
    critical_time_step = setting("_time_step", TimeStepLimits.critical_time_step)

    # -- boundary pressures beyond bndCondValue (_boundary_pressure) ----------------------------
    waveAction = setting("_loads", BoundaryPressure.waveAction)
    sineMagnitude = setting("_loads", BoundaryPressure.sineMagnitude)
    sineAverage = setting("_loads", BoundaryPressure.sineAverage)
    boundaryXPos = setting("_loads", BoundaryPressure.boundaryXPos)
    boundaryPressure = setting("_loads", BoundaryPressure.boundaryPressure)
    boundary_pressure = setting("_loads", BoundaryPressure.boundary_pressure)
    set_boundary_pressure = method("_loads", BoundaryPressure.set_boundary_pressure)
    clear_boundary_pressure = method("_loads", BoundaryPressure.clear_boundary_pressure)

    # -- what a step does and reports (_step_options, _step_reports) ----------------------------
    pressureForce = setting("_options", StepOptions.pressureForce)
    decoupleForces = setting("_options", StepOptions.decoupleForces)
    desiredPorosity = setting("_options", StepOptions.desiredPorosity)
    blockHook = setting("_reports", StepReports.blockHook)
    debug = setting("_reports", StepReports.debug)
    getCHOLMODPerfTimings = setting("_reports", StepReports.getCHOLMODPerfTimings)
    meanKStat = setting("_reports", StepReports.meanKStat)

    # -- kept for YADE's scripts, no effect (_kept_settings) --------------------------------------
    permeabilityMap = setting("_kept", KeptSettings.permeabilityMap)
    numSolveThreads = setting("_kept", KeptSettings.numSolveThreads)
    numFactorizeThreads = setting("_kept", KeptSettings.numFactorizeThreads)
    boundaryVelocity = setting("_kept", KeptSettings.boundaryVelocity)
    ids = setting("_kept", KeptSettings.ids)
    volumeFactor = setting("_kept", KeptSettings.volumeFactor)

    # -- the mesh: cells, throats, volumes (_cell_geometry) ---------------------------------------
    iniVoidVolumes = setting("_geometry", CellGeometry.iniVoidVolumes)
    porosity = setting("_geometry", CellGeometry.porosity)
    epsVolMax = setting("_geometry", CellGeometry.epsVolMax)
    nCells = method("_geometry", CellGeometry.nCells)
    getCell = method("_geometry", CellGeometry.getCell)
    getCellCenter = method("_geometry", CellGeometry.getCellCenter)
    getCellVolume = method("_geometry", CellGeometry.getCellVolume)
    getCellBarycenter = method("_geometry", CellGeometry.getCellBarycenter)
    getVertices = method("_geometry", CellGeometry.getVertices)
    getNeighbors = method("_geometry", CellGeometry.getNeighbors)
    isCellNeighbor = method("_geometry", CellGeometry.isCellNeighbor)
    getIncidentCells = method("_geometry", CellGeometry.getIncidentCells)
    getConductivity = method("_geometry", CellGeometry.getConductivity)
    getDiffusionCoeff = method("_geometry", CellGeometry.getDiffusionCoeff)
    surfaceSolidThroatInPore = method("_geometry", CellGeometry.surfaceSolidThroatInPore)
    getConstrictions = method("_geometry", CellGeometry.getConstrictions)
    getConstrictionsFull = method("_geometry", CellGeometry.getConstrictionsFull)
    getCellInvVoidVolume = method("_geometry", CellGeometry.getCellInvVoidVolume)
    initializeVolumes = method("_geometry", CellGeometry.initializeVolumes)
    updateVolumes = method("_geometry", CellGeometry.updateVolumes)
    compTessVolumes = method("_geometry", CellGeometry.compTessVolumes)
    volume = method("_geometry", CellGeometry.volume)

    # -- the flow: pressures, fluxes, velocities, forces (_flow_queries) ----------------------------
    getPorePressure = method("_flow", FlowQueries.getPorePressure)
    getCellPressure = method("_flow", FlowQueries.getCellPressure)
    averagePressure = method("_flow", FlowQueries.averagePressure)
    averageSlicePressure = method("_flow", FlowQueries.averageSlicePressure)
    absolute_pressure = method("_flow", FlowQueries.absolute_pressure)
    getCellFluxFromId = method("_flow", FlowQueries.getCellFluxFromId)
    getCellFlux = method("_flow", FlowQueries.getCellFlux)
    getBoundaryFlux = method("_flow", FlowQueries.getBoundaryFlux)
    getBoundaryFluidArea = method("_flow", FlowQueries.getBoundaryFluidArea)
    getBoundaryVel = method("_flow", FlowQueries.getBoundaryVel)
    getBoundaryVolume = method("_flow", FlowQueries.getBoundaryVolume)
    getCellVelocity = method("_flow", FlowQueries.getCellVelocity)
    averageVelocity = method("_flow", FlowQueries.averageVelocity)
    avFlVelOnSph = method("_flow", FlowQueries.avFlVelOnSph)
    fluidForce = method("_flow", FlowQueries.fluidForce)
    shearLubForce = method("_flow", FlowQueries.shearLubForce)
    metisUsed = method("_flow", FlowQueries.metisUsed)

    # -- conditions on points and cells (_cell_conditions) ------------------------------------------
    updateBCs = method("_conditions", CellConditions.updateBCs)
    imposePressure = method("_conditions", CellConditions.imposePressure)
    setImposedPressure = method("_conditions", CellConditions.setImposedPressure)
    clearImposedPressure = method("_conditions", CellConditions.clearImposedPressure)
    imposeFlux = method("_conditions", CellConditions.imposeFlux)
    clearImposedFlux = method("_conditions", CellConditions.clearImposedFlux)
    getCellPImposed = method("_conditions", CellConditions.getCellPImposed)
    setCellPImposed = method("_conditions", CellConditions.setCellPImposed)
    setCellPressure = method("_conditions", CellConditions.setCellPressure)
    blockCell = method("_conditions", CellConditions.blockCell)
    imposePressureFromId = method("_conditions", CellConditions.imposePressureFromId)
    resetLinearSystem = method("_conditions", CellConditions.resetLinearSystem)

    # -- file outputs (_file_outputs) -----------------------------------------------------------------
    pressureProfile = method("_outputs", FileOutputs.pressureProfile)
    printVertices = method("_outputs", FileOutputs.printVertices)
    exportTriplets = method("_outputs", FileOutputs.exportTriplets)
    exportMatrix = method("_outputs", FileOutputs.exportMatrix)
    cholmodStats = method("_outputs", FileOutputs.cholmodStats)
    saveVtk = method("_outputs", FileOutputs.saveVtk, locked=False)  # locks while it reads, not while it writes

    # -- the step ---------------------------------------------------------------------------
    @exclusive
    def _step(self) -> None:
        """One step, all or nothing: if any part fails (the core's step, blockHook, a boundary load, the
        time-step guard after a new mesh, the forces to YADE), the core is put back as it was before
        the step (its mesh, system, results and history) and the exception goes to YADE."""
        # YADE's pressureForce=False: no flow at all; nor once Python is about to finalize (_lifecycle)
        if not self._options.pressureForce or _lifecycle.exiting():
            return
        scene = yade.O
        clock = StepClock(self._timings) if scene.timingEnabled else _IDLE_CLOCK
        self._enter_scene(scene)
        stepped = self._bodies.stepped
        # OpenMP's thread count belongs to the thread running YADE's engines: ompThreads is the flow engine's
        # own, so the engines after it get the caller's count back.
        caller_threads = get_max_threads()
        set_num_threads(self._threads or scene.numThreads)
        try:
            self._step_parts(scene, clock)
        except BaseException:
            self._bodies.stepped = stepped
            self._core.retract_step()
            raise
        finally:
            set_num_threads(caller_threads)
        self._core.accept_step()

    def _step_parts(self, scene: Any, clock: Any) -> None:
        if scene.periodic:
            raise RuntimeError(
                "pfv.FlowEngine needs a box bounded by walls, and the scene is periodic (O.periodic = True): use "
                "pfv.PeriodicFlowEngine"
            )
        scan, pos, walls = self._bodies.for_step(scene)
        clock.lap("scan and positions")
        dt = self._before_step(scene, scan)
        watch, reports = StepWatch(self._core), self._reports.before_step()
        self._options.correct_volumes(pos, scan.radii)
        clock.lap("time-step guard")
        self._advance(scene, scan, pos, walls, dt)
        clock.core_step(self._core, watch.remeshed(self._core))
        self._time_step.check_new_mesh(scene.dt, scan)
        self._warnings.after_step(self._core, scene.iter, scan, watch)
        clock.lap("time-step guard and warnings")
        self._reports.after_step(reports)
        self._apply_forces(scene, scan)
        self._record(scene, scan, dt)
        clock.lap("forces to YADE")

    def _enter_scene(self, scene: Any) -> None:
        """After O.reset() (or O.switchScene) the engine may be put into a scene it has never
        seen, possibly with as many bodies as the last one: forget everything of the old one.
        The collective limit follows with the new mesh (its history and the mode that warm
        starts it carry over: the mode is only a starting vector)."""
        if self._history.enter(scene):
            self._bodies.forget()
            self._core.request_remesh()
            self._core.reset_history()

    def _before_step(self, scene: Any, scan: SceneScan) -> float:
        """The time this step's dV/dt spans (the history forgotten after a gap), the gravity of the
        buoyancy, and the time-step check on the limits known before the step; returns the time."""
        dt, forget = self._history.time_since_last_step(scene, self.iterPeriod)
        if forget:
            self._core.reset_history()
        if self._core.fluid_density > 0:  # buoyancy under the NewtonIntegrator's gravity
            self._core.gravity = _gravity(scene)
        # Before the step, only limits known for the mesh the step will use (a mesh about to be
        # rebuilt, or conductances about to change, have no limit yet: checked after the step).
        self._time_step.check(scene.dt, scan, before_step=True)
        return dt

    def _advance(self, scene: Any, scan: SceneScan, pos: np.ndarray, walls: list[float], dt: float) -> None:
        """The core's step: remesh when due (blockHook between a new mesh and its system, in the core),
        dV/dt, solve, forces; with a load evaluated at this step's time."""
        if self._loads.active:
            self._loads.prepare(scene, walls)
        # The spheres of any mesh the step builds: what blockHook's queries name.
        self._bodies.stepped = scan
        with self._bodies.named_in_errors(scan):
            self._core.step(pos, scan.radii, walls, dt)

    def _record(self, scene: Any, scan: SceneScan, dt: float) -> None:
        """A step made: the mesh holds the spheres of `scan`; `dt` the time its dV/dt spanned."""
        self._bodies.stepped = scan
        self._history.record(scene, dt)
        registry.hold(self)
        registry.release_unused(self)

    def _apply_forces(self, scene: Any, scan: SceneScan) -> None:
        """The fluid forces to YADE's bodies, unless decoupleForces (read in C++, without a numpy copy)."""
        if not self._options.decoupleForces:
            scan.force_bridge.apply(scene.forces.addF, self._core)

    def emulateAction(self) -> None:
        """Run one flow step outside the time-stepping loop, as YADE's method does."""
        self._step()

    @property
    def timingDeltas(self) -> StageTimings:
        """The engine's stages for YADE's timing.stats() while O.timingEnabled (_timing.py)."""
        return self._timings

    # -- the engine's mesh ----------------------------------------------------------------------
    @exclusive
    def _release(self) -> None:
        """Free the mesh and the scan (settings kept): the next step starts afresh."""
        self._core.release()
        self._bodies.forget()
        self._history.last_step = None
        registry.drop(self)

    def _ran_in(self, scene: Any) -> bool:
        """Whether this engine last ran in `scene`."""
        return self._history.in_scene(scene)

    def _release_if_gone(self, scene: Any, engines: Sequence[Any]) -> None:
        """_release() if this engine ran in `scene` but is no longer among its `engines`."""
        if self._history.in_scene(scene) and not any(e is self for e in engines):
            self._release()

    # -- O.save / O.load (_persistence) -----------------------------------------------------
    @staticmethod
    def drives(command: str) -> bool:
        """Whether a PyRunner command is that of a pfv.FlowEngine (a restored one after a load)."""
        return command.startswith(_COMMAND.split("{")[0])

    @exclusive
    def _saved_state(self) -> dict[str, Any]:
        """Everything a new engine needs to go on where this one is: settings, boundary conditions,
        the parts' settings and, once it has run, the core's run state."""
        core = self._core
        running = self._bodies.has_mesh()
        if self._loads.boundary_pressure is not None and self._warnings.once("unsaved function"):
            warnings.warn(
                "pfv.FlowEngine: the function of set_boundary_pressure is not saved with the scene; "
                "set it again after O.load",
                stacklevel=3,
            )
        last_step = self._history.last_step
        return {
            "core": {name: getattr(core, name) for name in _SAVED_CORE_SETTINGS},
            "bnd_is_pressure": list(core.bnd_is_pressure),
            "bnd_value": list(core.bnd_value),
            "imposed_pressures": core.imposed_pressures(),
            "imposed_fluxes": core.imposed_fluxes(),
            "threads": self._threads,
            **{key: getattr(self, part).saved() for key, part in _SAVED_PARTS.items()},
            "runner": {name: getattr(self, name) for name in ("iterPeriod", "dead", "initRun")},
            "last_step": list(last_step) if running and last_step else None,
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
        engine._threads = state["threads"]
        for key, part in _SAVED_PARTS.items():
            getattr(engine, part).restore(state[key])
        for name in attributes.RUNNER_SCHEDULE:  # YADE restores them (a script may have changed them since the load)
            setattr(engine, name, getattr(runner, name))
        engine.label = runner.label
        if state["run"] is not None:
            engine._resume(state["run"], state["last_step"])
        return engine

    def _resume(self, run: dict[str, Any], last_step: Sequence[Any]) -> None:
        """Rebuild the saved mesh and step history in the loaded scene."""
        scene = yade.O
        self._enter_scene(scene)
        self._core.resume(run, scene.dt)
        self._bodies.stepped = self._bodies.rescan()
        self._history.last_step = tuple(last_step)
        registry.hold(self)

    # -- PFV extras -------------------------------------------------------------------------
    @property
    def core(self) -> Engine:
        """The C++ engine (pfv.Engine): geometry, timings and diagnostics."""
        return self._core


# Names set as ordinary attributes: PyRunner's (command, iterPeriod, label, ...) and the properties
# of FlowEngine (its own and those forwarded to its parts).
_OWN_ATTRIBUTES = frozenset(a for a in dir(PyRunner) if not a.startswith("__")) | {
    name for klass in FlowEngine.__mro__ for name, v in vars(klass).items() if isinstance(v, property)
}
# YADE's PyRunner attributes, checked by YADE's converters: all but FlowEngine's own properties
# (ompThreads, timingDeltas).
_RUNNER_ATTRIBUTES = attributes.runner_attributes(PyRunner, FlowEngine)

_persistence.install()  # O.save / O.load carry the engines' state
