"""The coupled time-step limits of a pfv.FlowEngine, a part of the engine: what they are for the
current scene and mesh, and the check of O.dt against them around each step.

The limits come from the bodies (``_coupled_bodies``: the masses and sizes of the coupled spheres,
YADE's P-wave step) and the core (the collective viscous limit of its mesh); ``_time_step``'s
``TimeStepGuard`` keeps the collective limit between steps and warns. The guard's settings are the
engine's attributes time_step_safety, strict_time_step, collective_iterations(_warm).
"""
from __future__ import annotations

from typing import Any, Callable

import yade

from . import _attributes as attributes
from ._coupled_bodies import CoupledBodies
from ._scene_scan import SceneScan
from ._time_step import TimeStepGuard, viscous_time_step

# The guard's settings saved with a scene.
_SAVED_GUARD_SETTINGS = ("safety", "strict", "iterations", "iterations_warm")


def _guard_setting(name: str, attribute: str, convert: Callable[[str, Any], Any], doc: str) -> property:
    """A property that reads and writes the TimeStepGuard's attribute `name`, checked by `convert` under
    the engine's name `attribute` of it."""
    return property(
        lambda self: getattr(self.guard, name),
        lambda self, value: setattr(self.guard, name, convert(attribute, value)),
        doc=doc,
    )


def _iterations(name: str, value: Any) -> int:
    return attributes.as_integer(name, value, low=1)


class TimeStepLimits:
    """The limits of the engine whose pfv.Engine is `core` and whose coupled bodies are `bodies`."""

    def __init__(self, core: Any, bodies: CoupledBodies) -> None:
        self._core = core
        self._bodies = bodies
        self.guard = TimeStepGuard()

    time_step_safety = _guard_setting(
        "safety",
        "time_step_safety",
        attributes.as_positive,
        "O.dt must stay below time_step_safety * critical_time_step (zeta of thesis 4.22); 0.8 (positive).",
    )
    strict_time_step = _guard_setting(
        "strict",
        "strict_time_step",
        attributes.as_flag,
        "True: an unsafe O.dt raises ValueError instead of warning (TimeStepWarning).",
    )
    collective_iterations = _guard_setting(
        "iterations",
        "collective_iterations",
        _iterations,
        "Operator applications at most for the collective limit of the first mesh (cold start); 40 (at least 1).",
    )
    collective_iterations_warm = _guard_setting(
        "iterations_warm",
        "collective_iterations_warm",
        _iterations,
        "Operator applications at most for the collective limit of a later mesh (warm start); 10 (at least 1).",
    )

    @property
    def viscous_time_step(self) -> float:
        """dt_MV = pi rho d^2 / (1200 mu) at the smallest rho d^2 of the coupled dynamic spheres (thesis 4.20)."""
        return viscous_time_step(self._bodies.scanned().mass_per_diameter, self._core.viscosity)

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
        if not self._bodies.has_mesh():
            return float("inf")
        # The masses of the spheres the mesh holds (even if bodies or wallIds changed since).
        return self.guard.collective_limit(self._core, self._bodies.stepped.masses, yade.O.iter)

    @property
    def collective_viscous_bound(self) -> float:
        """The best certified lower bound on collective_viscous_time_step without computing it: the
        larger of the global bound (about one solve, up to four orders of magnitude below the limit;
        what the time-step guard checks O.dt against first) and the local one (small problems around
        each sphere, within an order of magnitude of the limit, several times the cost of the global
        one). O.dt = time_step_safety * min(this, dt_MV, P-wave step) is safe. 0 with viscousShear,
        which neither covers (doc/model.md, "Coupled time step")."""
        if not self._bodies.has_mesh():
            return float("inf")
        masses = self._bodies.stepped.masses
        return max(self._core.viscous_stability_bound(masses), self._core.viscous_stability_local_bound(masses))

    @property
    def collective_viscous_history(self) -> list[dict[str, Any]]:
        """One dict per computation of the collective limit or its bound: iter, remesh_count, limit [s],
        method ("bound": the certified lower bound; "arnoldi"; "power": from the previous mesh's mode),
        iterations (operator applications made, each a solve and a force evaluation), max_iterations
        (the cap), warm (method == "power"), seconds (wall time)."""
        return self.guard.history

    @property
    def critical_time_step(self) -> float:
        """min(dt_MV, collective viscous limit, DEM P-wave limit): O.dt should not exceed
        time_step_safety times this."""
        scan = self._bodies.scanned()
        return min(self.viscous_time_step, self.collective_viscous_time_step, scan.dt_dem)

    def check(self, dt: float, scan: SceneScan | None = None, before_step: bool = False) -> None:
        """Warn or raise (strict_time_step) if dt exceeds time_step_safety * critical_time_step,
        with the single-particle and DEM limits of `scan` (None: the current scan) and the collective
        limit of the current mesh, or its certified bound where that suffices (_time_step.py).
        `before_step`: the mesh may be about to change, nothing is computed for it then."""
        if scan is None:
            scan = self._bodies.scanned()
        dt_mv = viscous_time_step(scan.mass_per_diameter, self._core.viscosity)
        collective = float("inf")
        stepped = self._bodies.stepped
        if stepped is not None:  # the masses of the spheres the mesh holds
            collective = self.guard.limit_to_check(
                self._core, stepped.masses, dt, min(dt_mv, scan.dt_dem), yade.O.iter, before_step
            )
        self.guard.check(dt, dt_mv, collective, scan.dt_dem)

    def check_new_mesh(self, dt: float, scan: SceneScan) -> None:
        """After a step: a new mesh (the first, or a remesh adopted by this step) or new conductances
        may have a lower collective limit (a compacting sample), check again."""
        if self.guard.unchecked(self._core):
            self.check(dt, scan)

    # -- O.save / O.load ----------------------------------------------------------------------------
    def saved(self) -> dict[str, Any]:
        return {name: getattr(self.guard, name) for name in _SAVED_GUARD_SETTINGS}

    def restore(self, state: dict[str, Any]) -> None:
        for name, value in state.items():
            setattr(self.guard, name, value)
