"""The time-step guard: is O.dt within the stability limit of the explicit DEM-flow coupling?

The coupling is explicit, so O.dt must stay below ``time_step_safety`` (zeta of thesis 4.22) times
the smallest of three limits: the single-particle viscous limit dt_MV (thesis 4.20), the collective
viscous limit of the current mesh (2 / lambda_max(M^-1 V), groups of spheres squeezing shared pores)
and YADE's DEM P-wave limit. ``TimeStepGuard`` holds what this needs between steps: the collective
limit and the mesh and viscosity it was computed for, the mode that warm-starts the next
computation, the history of computations, and whether the step was already reported unsafe (one
warning on becoming unsafe, not one per step). It knows nothing of YADE: the engine passes it the
core, the masses and the limits. Kept apart so that the warning logic is readable on its own.

The collective limit costs tens of solves; a certified lower bound on it costs about one
(``core.viscous_stability_bound``, loose by up to four orders of magnitude). A check first asks
the bound and computes the limit only when the bound cannot show the step safe, so a step far
below the limit (water at a DEM time step) never pays for the limit, and a step near it is
checked against the limit itself, as before.
"""
from __future__ import annotations

import collections
import time
import warnings
from typing import Any

import numpy as np


HISTORY_LENGTH = 200  # computations of the collective limit kept in the history


class TimeStepWarning(UserWarning):
    """O.dt exceeds the coupled stability limit (thesis 4.20-4.22)."""


def viscous_time_step(mass_per_diameter: float, viscosity: float) -> float:
    """dt_MV = pi rho d^2 / (1200 mu), written with rho = 6 m / (pi d^3) as m / (200 mu d)."""
    return mass_per_diameter / (200.0 * viscosity)


class TimeStepGuard:
    """The collective viscous limit of the current mesh and the unsafe-step warning."""

    def __init__(self) -> None:
        self.safety = 0.8  # O.dt must stay below safety * min(limits)
        self.strict = False  # raise ValueError instead of warning
        self.iterations = 40  # operator applications at most, cold start (first mesh)
        self.iterations_warm = 10  # operator applications at most, warm start (later meshes)
        self._limit: float | None = None
        self._limit_state: tuple[int, float, bool] | None = None  # the _state the limit was computed in
        self._mode: np.ndarray | None = None  # its eigenvector, the next mesh's start
        self._bound: float | None = None  # the certified lower bound on the limit
        self._bound_state: tuple[int, float, bool] | None = None
        # The latest computations (a long run remeshes without end: the record must not grow).
        self._history: collections.deque[dict[str, Any]] = collections.deque(maxlen=HISTORY_LENGTH)
        self._unsafe = False

    @staticmethod
    def _state(core: Any) -> tuple[int, float, bool]:
        # The mesh, the viscosity of its conductances (a new one applies at the next step), and the
        # shear term, which adds damping to the operator (switched on, its pairs arrive with a
        # remesh, which recomputes again).
        return core.mesh_id, core.mesh_viscosity, core.viscous_shear

    def stale(self, core: Any) -> bool:
        """Whether the core has a mesh, or conductances, the collective limit was not computed for."""
        return core.has_mesh() and self._limit_state != self._state(core)

    def unchecked(self, core: Any) -> bool:
        """Whether neither the limit nor its bound is known for the core's mesh as it is."""
        if not core.has_mesh():
            return False
        state = self._state(core)
        return self._limit_state != state and self._bound_state != state

    def limit_to_check(
        self, core: Any, masses: np.ndarray, dt: float, other_limits: float, iteration: int, before_step: bool = False
    ) -> float:
        """The collective limit to check dt against: the limit if computed for the core's mesh as it is,
        else its certified lower bound when that shows dt safe (dt <= safety * min(bound, other_limits)),
        else the limit, computed now. Before a step (`before_step`) nothing is computed for a mesh about
        to be replaced: inf, the check follows on the new mesh."""
        if not core.has_mesh() or (before_step and core.remesh_due()):
            return float("inf")
        state = self._state(core)
        if self._limit_state == state:
            return self._limit
        if self._bound_state != state:
            t0 = time.perf_counter()
            self._bound, self._bound_state = core.viscous_stability_bound(masses), state
            self._history.append(
                dict(
                    iter=iteration,
                    remesh_count=core.remesh_count,
                    limit=self._bound,
                    iterations=0,
                    max_iterations=0,
                    warm=False,
                    method="bound",
                    seconds=time.perf_counter() - t0,
                )
            )
        if dt <= self.safety * min(self._bound, other_limits):
            return self._bound
        return self.collective_limit(core, masses, iteration)

    def collective_limit(self, core: Any, masses: np.ndarray, iteration: int) -> float:
        """The collective viscous limit of the core's mesh, computed again on a new mesh or when the
        viscosity or the shear term changed; `iteration` (O.iter) goes into the history."""
        if not core.has_mesh():
            return float("inf")
        state = self._state(core)
        if self._limit_state != state:
            mode = self._mode
            # Warm only from the mesh just before: a mode older than that (meshes the bound sufficed
            # for) may be far from the new one, and power iteration is only accurate from close by.
            warm = (
                mode is not None
                and len(mode) == len(masses)
                and self._limit_state is not None
                and self._limit_state[0] in (state[0], state[0] - 1)
            )
            iterations = self.iterations_warm if warm else self.iterations
            t0 = time.perf_counter()
            limit, mode, applied = core.viscous_stability_mode(masses, iterations, mode if warm else None)
            seconds = time.perf_counter() - t0
            self._limit, self._limit_state = limit, state
            self._mode = mode if len(mode) else None
            self._history.append(
                dict(
                    iter=iteration,
                    remesh_count=core.remesh_count,
                    limit=limit,
                    iterations=applied,
                    max_iterations=iterations,
                    warm=warm,
                    method="power" if warm else "arnoldi",
                    seconds=seconds,
                )
            )
        return self._limit

    @property
    def history(self) -> list[dict[str, Any]]:
        """The latest HISTORY_LENGTH computations of the collective limit (one dict each), oldest first."""
        return list(self._history)

    def check(self, dt: float, dt_mv: float, dt_collective: float, dt_dem: float) -> None:
        """Warn (TimeStepWarning) when dt becomes unsafe, or raise ValueError if strict."""
        limit = self.safety * min(dt_mv, dt_collective, dt_dem)
        if dt <= limit:
            self._unsafe = False
            return
        message = (
            f"pfv.FlowEngine: O.dt = {dt:.4g} exceeds the coupled stability limit "
            f"{self.safety:g} x min(dt_MV = {dt_mv:.4g}, collective viscous limit = "
            f"{dt_collective:.4g}, dt_DEM = {dt_dem:.4g}) = {limit:.4g}; "
            f"the explicit coupling may blow up (thesis 4.20-4.22)"
        )
        if self.strict:
            raise ValueError(message)
        if not self._unsafe:  # warn on becoming unsafe, not at every step while it stays so
            self._unsafe = True
            # stacklevel 3: the engine's step, the caller of TimeStepLimits.check.
            warnings.warn(message, TimeStepWarning, stacklevel=3)
