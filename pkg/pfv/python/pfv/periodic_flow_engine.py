"""pfv.PeriodicFlowEngine: the flow through a periodic cell (O.periodic = True) under an imposed mean pressure
gradient, with the interface of YADE's PeriodicFlowEngine where it has a meaning (doc/periodic.md).

A PyRunner, as pfv.FlowEngine: its command finds the engine by a key, and each step reads the spheres' centres, the
cell's vectors (O.cell.hSize) and O.dt, runs the C++ step (pfv._core.PeriodicFlow) and adds the fluid forces to
O.forces. The pressure is p = p~ + gradP . x with p~ periodic (doc/model.md); the cell may be a cuboid or sheared,
and deform (its velocity gradient moves the images of the spheres, shear included).
"""
from __future__ import annotations

import math
import secrets
import weakref
from typing import Any

import numpy as np
import yade
from yade.minieigenHP import Vector3
from yade._packSpheres import SpherePack
from yade.wrapper import PyRunner, Sphere

from . import _attributes as attributes
from . import _persistence
from ._attributes import runner_attributes
from ._core import PeriodicFlow, YadeForceBridge, gather_sphere_pack, sphere_pack_size
from ._timing import IdleClock, StageTimings, StepClock

_COMMAND = "__import__('pfv.periodic_flow_engine').periodic_flow_engine._run({})"
_engines = weakref.WeakValueDictionary()  # key -> engine: the PyRunner commands find their engine here

# Members of YADE's FlowEngine that describe the walls of a box: a periodic cell has none.
_WALLED_ONLY = frozenset(
    {
        "wallIds",
        "bndCondIsPressure",
        "bndCondValue",
        "boundaryUseMaxMin",
        "wallThickness",
        "slipBoundary",
        "boundaryVelocity",
        "boundaryPressure",
        "boundaryXPos",
        "xmin",
        "xmax",
        "ymin",
        "ymax",
        "zmin",
        "zmax",
        "getBoundaryFlux",
        "setBoundaryNormal",
        "bndCondIsTemperature",
        "thermalBndCondValue",
    }
)
_FIELDS = frozenset(
    {
        "_core",
        "_key",
        "_settings",
        "_spheres",
        "_bridge",
        "_pack",
        "_last_remesh",
        "_remesh_asked",
        "_last_step",
        "_timings",
    }
)
_IDLE_CLOCK = IdleClock()
_SOLVER_CODE = {"gauss_seidel": 0, "conjugate_gradient": 1, "cholesky": 3, "multigrid": 3}


def _run(key: int) -> None:
    _persistence.running_engine(_engines.get(key), _COMMAND.format(key), "PeriodicFlowEngine")._step()


def _finite_vector(name: str, value: Any) -> tuple[float, float, float]:
    try:
        v = tuple(float(x) for x in value)
    except TypeError:
        raise TypeError(f"pfv.PeriodicFlowEngine.{name} must be a vector of three numbers, got {value!r}") from None
    if len(v) != 3 or not all(math.isfinite(x) for x in v):
        raise ValueError(f"pfv.PeriodicFlowEngine.{name} must be three finite numbers, got {value!r}")
    return v


def _number(name: str, value: Any, minimum: float, strict: bool) -> float:
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise TypeError(f"pfv.PeriodicFlowEngine.{name} must be a number, got {value!r}") from None
    if not math.isfinite(x) or x < minimum or (strict and x == minimum):
        bound = f"{'>' if strict else '>='} {minimum:g}"
        raise ValueError(f"pfv.PeriodicFlowEngine.{name} must be finite and {bound}, got {value!r}")
    return x


class PeriodicFlowEngine(PyRunner):
    """PFV's flow engine for periodic cells with the interface of YADE's PeriodicFlowEngine."""

    def __init__(self, **kwargs: Any) -> None:
        PyRunner.__init__(self)
        self._core = PeriodicFlow()
        self._key = secrets.randbits(62)
        self._settings = dict(
            gradP=(0.0, 0.0, 0.0),
            viscosity=1.0,
            permeabilityFactor=1.0,
            fluidBulkModulus=0.0,
            meshUpdateInterval=1000,
            defTolerance=0.0,
            duplicateThreshold=0.06,
            solver="cholesky",
            tolerance=1e-6,
            relax=1.9,
        )
        self._spheres = None  # (ids, radii, body count) of the last scan
        self._bridge = None
        self._pack = None  # a SpherePack whose array holds the centres (YADE's fromSimulation), or None
        self._last_remesh = None
        self._remesh_asked = False
        self._last_step = None  # O.iter of the last step
        self._timings = StageTimings()
        _engines[self._key] = self
        self.command = _COMMAND.format(self._key)
        self.iterPeriod = 1
        self.initRun = True
        for name, value in kwargs.items():
            setattr(self, name, value)

    # -- attributes ------------------------------------------------------------------------------
    def __setattr__(self, name: str, value: Any) -> None:
        if name in _FIELDS or isinstance(getattr(type(self), name, None), property):
            object.__setattr__(self, name, value)
        elif name in _RUNNER_ATTRIBUTES:
            if name == "command" and getattr(self, "command", "") and value != self.command:
                raise ValueError("command drives this pfv.PeriodicFlowEngine and cannot be changed")
            object.__setattr__(self, name, value)
        elif name in _WALLED_ONLY:
            raise AttributeError(f"pfv.PeriodicFlowEngine has no walls: {name} has no meaning in a periodic cell")
        else:
            raise AttributeError(f"pfv.PeriodicFlowEngine has no attribute {name!r}")

    def __getattr__(self, name: str) -> Any:  # only called when normal lookup fails
        if name in _WALLED_ONLY:
            raise AttributeError(f"pfv.PeriodicFlowEngine has no walls: {name} has no meaning in a periodic cell")
        raise AttributeError(f"pfv.PeriodicFlowEngine has no attribute {name!r}")

    def _apply_settings(self, **changes: Any) -> None:
        s = dict(self._settings, **changes)
        self._core.set_settings(
            s["viscosity"],
            s["permeabilityFactor"],
            s["gradP"],
            s["fluidBulkModulus"],
            solver=s["solver"],
            tolerance=s["tolerance"],
            relax=s["relax"],
            def_tolerance=s["defTolerance"],
        )
        self._settings = s

    @property
    def gradP(self) -> Vector3:
        """The imposed macroscopic pressure gradient (YADE's gradP): p = p~ + gradP . x."""
        return Vector3(*self._settings["gradP"])

    @gradP.setter
    def gradP(self, value: Any) -> None:
        self._apply_settings(gradP=_finite_vector("gradP", value))

    @property
    def viscosity(self) -> float:
        return self._settings["viscosity"]

    @viscosity.setter
    def viscosity(self, value: Any) -> None:
        self._apply_settings(viscosity=_number("viscosity", value, 0.0, strict=True))

    @property
    def permeabilityFactor(self) -> float:
        return self._settings["permeabilityFactor"]

    @permeabilityFactor.setter
    def permeabilityFactor(self, value: Any) -> None:
        self._apply_settings(permeabilityFactor=_number("permeabilityFactor", value, 0.0, strict=True))

    @property
    def fluidBulkModulus(self) -> float:
        """The fluid's bulk modulus; 0 (YADE's default): incompressible."""
        return self._settings["fluidBulkModulus"]

    @fluidBulkModulus.setter
    def fluidBulkModulus(self, value: Any) -> None:
        self._apply_settings(fluidBulkModulus=_number("fluidBulkModulus", value, 0.0, strict=False))

    @property
    def meshUpdateInterval(self) -> int:
        """Iterations between two remeshes."""
        return self._settings["meshUpdateInterval"]

    @meshUpdateInterval.setter
    def meshUpdateInterval(self, value: Any) -> None:
        self._settings["meshUpdateInterval"] = int(_number("meshUpdateInterval", value, 1.0, strict=False))

    @property
    def defTolerance(self) -> float:
        """YADE's: a remesh once the pores' strain summed over the steps since the last (each step's largest
        relative volume change of a pore) exceeds it; 0 (YADE's default): by meshUpdateInterval only."""
        return self._settings["defTolerance"]

    @defTolerance.setter
    def defTolerance(self, value: Any) -> None:
        self._apply_settings(defTolerance=_number("defTolerance", value, 0.0, strict=False))

    @property
    def duplicateThreshold(self) -> float:
        """Accepted for YADE's scripts: YADE duplicates bodies near the cell's faces; PFV triangulates the
        spheres' images (doc/periodic.md) and has nothing to duplicate."""
        return self._settings["duplicateThreshold"]

    @duplicateThreshold.setter
    def duplicateThreshold(self, value: Any) -> None:
        self._settings["duplicateThreshold"] = _number("duplicateThreshold", value, 0.0, strict=False)

    @property
    def useSolver(self) -> int:
        """YADE's code of the linear solver: 0 Gauss-Seidel (to `tolerance`, over-relaxed by `relax`), 1
        incomplete-Cholesky conjugate gradients (a PFV extension, to `tolerance`), 3 the Cholesky factor (the
        default); 3 also while `solver` is "multigrid"."""
        return _SOLVER_CODE[self._settings["solver"]]

    @useSolver.setter
    def useSolver(self, value: Any) -> None:
        code = attributes.as_integer("useSolver", value)
        names = {v: k for k, v in _SOLVER_CODE.items() if k != "multigrid"}
        if code not in names:
            raise ValueError(
                f"pfv.PeriodicFlowEngine.useSolver must be 0 (Gauss-Seidel), 1 (conjugate gradients) or 3 (Cholesky), "
                f"got {value!r}"
            )
        self._apply_settings(solver=names[code])

    @property
    def solver(self) -> str:
        """The linear solver by name (a PFV extension): "cholesky", "gauss_seidel", "conjugate_gradient" or
        "multigrid" (conjugate gradients preconditioned by hypre's BoomerAMG, memory O(N))."""
        return self._settings["solver"]

    @solver.setter
    def solver(self, value: Any) -> None:
        if value not in _SOLVER_CODE:
            raise ValueError(f"pfv.PeriodicFlowEngine.solver must be one of {sorted(_SOLVER_CODE)}, got {value!r}")
        self._apply_settings(solver=value)

    @property
    def tolerance(self) -> float:
        """The iterative solvers' stopping tolerance (YADE's: Gauss-Seidel's max|dp|/max|p|)."""
        return self._settings["tolerance"]

    @tolerance.setter
    def tolerance(self, value: Any) -> None:
        self._apply_settings(tolerance=_number("tolerance", value, 0.0, strict=True))

    @property
    def relax(self) -> float:
        """Gauss-Seidel's over-relaxation, in (0, 2)."""
        return self._settings["relax"]

    @relax.setter
    def relax(self, value: Any) -> None:
        self._apply_settings(relax=_number("relax", value, 0.0, strict=True))

    @property
    def updateTriangulation(self) -> bool:
        return self._remesh_asked

    @updateTriangulation.setter
    def updateTriangulation(self, value: Any) -> None:
        if value:
            self._remesh_asked = True
            self._core.request_remesh()

    @property
    def timingDeltas(self) -> StageTimings:
        """The engine's stages for YADE's timing.stats() while O.timingEnabled."""
        return self._timings

    # -- point conditions ------------------------------------------------------------------------
    def imposePressure(self, pos: Any, p: Any) -> int:
        """Impose pressure p in the pore holding pos (any point, in any period): its p~ is set so that
        getPorePressure(pos) is p, which fixes the constant of p~ (no reference pore then). Kept through remeshes;
        returns the condition's index for setImposedPressure."""
        return self._core.impose_pressure(
            attributes.as_point("imposePressure position", pos), attributes.as_number("imposePressure pressure", p)
        )

    def setImposedPressure(self, cond: Any, p: Any) -> None:
        """Change the pressure of imposed condition number cond (at the next step, without a new factor)."""
        try:
            self._core.set_imposed_pressure(
                attributes.as_index("setImposedPressure cond", cond),
                attributes.as_number("setImposedPressure pressure", p),
            )
        except IndexError as error:
            raise IndexError(f"pfv.PeriodicFlowEngine.{error}") from None

    def clearImposedPressure(self) -> None:
        self._core.clear_imposed_pressure()

    def imposeFlux(self, pos: Any, p: Any) -> None:
        """A flux p through the pore holding pos, YADE's sign: outflow positive, inflow negative. Incompressible and
        without an imposed pressure, the reference pore takes the net inflow."""
        self._core.impose_flux(
            attributes.as_point("imposeFlux position", pos), -attributes.as_number("imposeFlux flux", p)
        )

    def clearImposedFlux(self) -> None:
        self._core.clear_imposed_flux()

    # -- queries ---------------------------------------------------------------------------------
    def _require_mesh(self) -> None:
        if not self._core.has_mesh():
            raise RuntimeError("pfv.PeriodicFlowEngine has not run yet: no pore mesh (run at least one step)")

    def getPorePressure(self, pos: Any) -> float:
        """The pressure of the pore holding pos (any point, in any period): p~ + gradP . x at the power centre x of
        that pore's translate, as YADE's gives a cell's pressure."""
        self._require_mesh()
        return self._core.pressure_at(_finite_vector("getPorePressure position", pos))

    def averageVelocity(self) -> Vector3:
        """The superficial (Darcy) velocity of the cell."""
        self._require_mesh()
        return Vector3(*self._core.mean_velocity())

    def fluidForce(self, id: int) -> Vector3:
        """The fluid force on sphere `id` at the last step."""
        self._require_mesh()
        ids = self._spheres[0]
        rows = np.nonzero(ids == id)[0]
        if len(rows) == 0:
            raise IndexError(f"pfv.PeriodicFlowEngine.fluidForce: body {id} is not a sphere of the flow")
        return Vector3(*self._core.forces()[rows[0]])

    def nCells(self) -> int:
        return self._core.n_cells

    def getCellPressure(self, id: int) -> float:
        """The pressure p~ + gradP . x of pore cell `id` (0 <= id < nCells()), x its power centre."""
        self._require_mesh()
        n = self._core.n_cells
        if isinstance(id, bool) or not isinstance(id, (int, np.integer)) or not 0 <= id < n:
            raise IndexError(f"pfv.PeriodicFlowEngine.getCellPressure: no cell {id!r} (the mesh has {n} cells)")
        return float(self._core.pressure()[id])

    def averagePressure(self) -> float:
        """The pores' pressure averaged over one period, weighted by the cells' volumes as YADE's."""
        self._require_mesh()
        return float(np.average(self._core.pressure(), weights=self._core.cell_volumes()))

    def average_fluid_pressure(self) -> float:
        """The pores' pressure averaged over the fluid: weighted by the cells' fluid volumes (what changes by
        K dV / V_f in an undrained loading)."""
        self._require_mesh()
        return float(np.average(self._core.pressure(), weights=self._core.fluid_volumes()))

    def saveVtk(self, folder: Any = "./VTK", withBoundaries: Any = False, compress: Any = False) -> None:
        """Write one period's pores (pressure, imposed flag, volumes) and the spheres (radii, ids, fluid forces) of
        the last step into `folder` as VTK XML files for ParaView: out_<N>.vtu, spheres_<N>.vtu and the collection
        out.pvd, at O.time (doc/periodic.md). withBoundaries is accepted for YADE's scripts: a periodic cell has no
        boundary cells."""
        import os

        if not isinstance(folder, (str, os.PathLike)):
            raise TypeError(f"saveVtk folder must be a path, got {folder!r}")
        attributes.as_flag("saveVtk withBoundaries", withBoundaries)
        compress = attributes.as_flag("saveVtk compress", compress)
        self._require_mesh()
        try:
            from . import _periodic_vtk
        except ImportError as error:
            raise ImportError(
                f"pfv.PeriodicFlowEngine.saveVtk needs VTK's Python package (apt-get install python3-vtk9): {error}"
            ) from None
        _periodic_vtk.save(_periodic_vtk.read_state(self), os.fspath(folder), compress)

    # -- O.save / O.load (_persistence) -----------------------------------------------------------
    @staticmethod
    def drives(command: str) -> bool:
        """Whether a PyRunner command is that of a pfv.PeriodicFlowEngine (a restored one after a load)."""
        return command.startswith(_COMMAND.split("{")[0])

    def _saved_state(self) -> dict[str, Any]:
        """Everything a new engine needs to go on where this one is: settings, conditions and, once it has run,
        the spheres it ran with and the core's run state."""
        running = self._core.has_mesh() and self._spheres is not None
        return {
            "settings": dict(self._settings),
            "imposed_pressures": self._core.imposed_pressures(),
            "imposed_fluxes": self._core.imposed_fluxes(),
            "ids": self._spheres[0].astype(float) if running else None,
            "last_remesh": self._last_remesh,
            "last_step": self._last_step,
            "remesh_asked": self._remesh_asked,
            "run": self._core.run_state() if running else None,
        }

    @classmethod
    def _from_saved(cls, state: dict[str, Any], runner: PyRunner) -> PeriodicFlowEngine:
        """A new engine from _saved_state() in the loaded scene, in place of the restored `runner`."""
        engine = cls()
        engine._apply_settings(**state["settings"])
        for pos, p in state["imposed_pressures"]:
            engine._core.impose_pressure(tuple(pos), p)
        for pos, q in state["imposed_fluxes"]:
            engine._core.impose_flux(tuple(pos), q)
        for name in attributes.RUNNER_SCHEDULE:  # YADE restores them (a script may have changed them since)
            setattr(engine, name, getattr(runner, name))
        engine.label = runner.label
        if state["run"] is not None:
            engine._resume(state)
        return engine

    def _resume(self, state: dict[str, Any]) -> None:
        """Rebuild the saved mesh and step history in the loaded scene, whose spheres must be those saved."""
        self._scan(yade.O)
        saved_ids = np.asarray(state["ids"]).astype(np.int64)
        if not np.array_equal(saved_ids, self._spheres[0]):
            raise RuntimeError(
                "pfv.PeriodicFlowEngine: the loaded scene's spheres are not those its engine was saved with"
            )
        self._core.resume(state["run"])
        self._last_remesh, self._last_step = state["last_remesh"], state["last_step"]
        self._remesh_asked = state["remesh_asked"]
        if self._remesh_asked:
            self._core.request_remesh()

    # -- the step --------------------------------------------------------------------------------
    def _scan(self, scene: Any) -> None:
        """The spheres (ids, radii), the force bridge, and how the centres are read: from a SpherePack filled by
        YADE's C++ fromSimulation (unwrapped centres, sphere bodies in id order) when it gives what YADE's Python
        interface gives for every sphere, else body by body."""
        ids, radii, centres = [], [], []
        for b in scene.bodies:
            if b is not None and isinstance(b.shape, Sphere):
                ids.append(b.id)
                radii.append(b.shape.radius)
                centres.append(tuple(b.state.pos))
        if not ids:
            raise RuntimeError("pfv.PeriodicFlowEngine: the scene has no spheres")
        n = len(ids)
        ids = np.array(ids, dtype=np.int64)
        self._spheres = (ids, np.array(radii), len(scene.bodies))
        self._bridge = YadeForceBridge(Vector3, ids, np.arange(n, dtype=np.int64))
        pack = SpherePack()
        pack.fromSimulation()
        read, read_radii = np.empty((n, 3)), np.empty(n)
        index = np.arange(n, dtype=np.int64)
        same = (
            sphere_pack_size(pack) == n
            and gather_sphere_pack(pack, index, read, read_radii, n)
            and np.array_equal(read, np.array(centres))
            and np.array_equal(read_radii, self._spheres[1])
        )
        self._pack = (pack, index) if same else None

    def _centres(self, scene: Any) -> np.ndarray | None:
        """The spheres' centres now, or None if bodies were added or erased since the scan."""
        ids = self._spheres[0]
        if self._pack is not None:
            pack, index = self._pack
            pack.fromSimulation()
            centres = np.empty((len(ids), 3))
            return centres if gather_sphere_pack(pack, index, centres, None, len(ids)) else None
        bodies = scene.bodies
        if len(bodies) != self._spheres[2]:
            return None
        try:
            return np.array([tuple(bodies[int(i)].state.pos) for i in ids])
        except (AttributeError, IndexError):  # an erased body
            return None

    def _step(self) -> None:
        scene = yade.O
        clock = StepClock(self._timings) if scene.timingEnabled else _IDLE_CLOCK
        if not scene.periodic:
            raise RuntimeError(
                "pfv.PeriodicFlowEngine needs a periodic cell (O.periodic = True); for a box bounded by walls use "
                "pfv.FlowEngine"
            )
        # dV/dt compares this step's positions with the last step's: not across a gap in the iterations (the engine
        # dead for a while, O.reset, O.loadTmp of an earlier state), where the motion since then is unknown.
        if self._last_step is not None and self._last_step != scene.iter - 1:
            self._core.forget_motion()
        scheduled = self._last_remesh is not None and scene.iter - self._last_remesh >= self.meshUpdateInterval
        if self._spheres is None or self._spheres[2] != len(scene.bodies) or self._remesh_asked or scheduled:
            self._scan(scene)  # the radii are read at each remesh
            self._core.request_remesh()
        centres = self._centres(scene)
        if centres is None:  # bodies erased (which keeps len(O.bodies)) or added
            self._scan(scene)
            self._core.request_remesh()
            centres = self._centres(scene)
        hsize = scene.cell.hSize  # a copy at each access: read once
        h = np.array([[hsize[i, j] for j in range(3)] for i in range(3)])
        clock.lap("positions")
        count = self._core.remesh_count
        self._core.step(centres, self._spheres[1], h, scene.dt)
        remeshed = self._core.remesh_count != count
        clock.core_step(self._core, remeshed)
        if remeshed or self._last_remesh is None:
            self._last_remesh = scene.iter
            self._remesh_asked = False
        self._bridge.apply(scene.forces.addF, self._core.forces())
        self._last_step = scene.iter
        clock.lap("forces to YADE")


# Kept as a PyRunner keeps them, but ompThreads: the periodic engine runs at the caller's thread count, and a setting
# that did nothing would be silent.
_RUNNER_ATTRIBUTES = runner_attributes(PyRunner, PeriodicFlowEngine) - {"ompThreads"}
