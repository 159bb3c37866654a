"""Time-dependent boundary pressures, as a mixin of ``pfv.FlowEngine``: YADE's waveAction and
PFV's general form ``set_boundary_pressure(wall, p)`` (pfv.waves, doc/waves.md).

Both hand the core one function of the positions of a pressure wall's Dirichlet cells, which the
core calls once per step after any remesh (pfv/model/boundary_conditions.hpp, PressureField).
Its values replace the wall's bndCondValue in the right-hand side only: a time-dependent load
never rebuilds the system. Without a load nothing here runs during a step.
"""
from __future__ import annotations

import math
import weakref
from typing import Any, Callable

import numpy as np

from . import _attributes as attributes
from ._locking import exclusive

# Python-side state of the mixin (plain instance attributes, not YADE attributes).
FIELD_INTERNAL = frozenset({
    "_wave_action",        # waveAction
    "_sine_magnitude",     # sineMagnitude
    "_sine_average",       # sineAverage
    "_pressure_function",  # (wall, p) of set_boundary_pressure, or None
    "_field_time",         # O.time of the step being computed
    "_field_walls",        # the six boundary coordinates of that step
})
WALL_NAMES = ("xmin", "xmax", "ymin", "ymax", "zmin", "zmax")
_YADE_WAVE_WALL = 3  # YADE's waveAction loads ymax


class BoundaryPressure:
    """waveAction, sineMagnitude, sineAverage and set_boundary_pressure (mixed into pfv.FlowEngine)."""

    _wave_action = False
    _sine_magnitude = 0.0
    _sine_average = 0.0
    _pressure_function: tuple[int, Callable[..., Any]] | None = None
    _field_time = 0.0
    _field_walls = (0.0, 1.0, 0.0, 1.0, 0.0, 1.0)

    # -- YADE's attributes ------------------------------------------------------------------------
    @property
    def waveAction(self) -> bool:
        """YADE's sinusoidal load on ymax: p = sineAverage + sineMagnitude cos(pi (x - xmin) / (xmax - xmin))
        on the Dirichlet cells of ymax (bndCondIsPressure[ymax] must be True), x the cell's power centre,
        xmin and xmax the boundaries of the step. Evaluated at every step with the current sineAverage and
        sineMagnitude (YADE: per 30 bins of x, when it builds a triangulation); doc/waves.md."""
        return self._wave_action

    @waveAction.setter
    def waveAction(self, value: bool) -> None:
        value = attributes.as_flag("waveAction", value)
        if value == self._wave_action:
            return
        if value and self._pressure_function is not None:
            raise ValueError("waveAction: a boundary pressure function is set (set_boundary_pressure); clear it "
                             "first (clear_boundary_pressure), the engine takes one time-dependent load")
        object.__setattr__(self, "_wave_action", value)
        self._install((_YADE_WAVE_WALL, self._yade_wave) if value else None)

    @property
    def sineMagnitude(self) -> float:
        """Amplitude of waveAction's cosine [Pa]; a change applies at the next step."""
        return self._sine_magnitude

    @sineMagnitude.setter
    def sineMagnitude(self, value: float) -> None:
        object.__setattr__(self, "_sine_magnitude", attributes.as_number("sineMagnitude", value))

    @property
    def sineAverage(self) -> float:
        """Mean of waveAction's pressure [Pa]; a change applies at the next step."""
        return self._sine_average

    @sineAverage.setter
    def sineAverage(self, value: float) -> None:
        object.__setattr__(self, "_sine_average", attributes.as_number("sineAverage", value))

    def _yade_wave(self, x: np.ndarray, y: np.ndarray, z: np.ndarray, t: float) -> np.ndarray:
        walls = self._field_walls
        return self._sine_average + self._sine_magnitude * np.cos(math.pi * (x - walls[0]) / (walls[1] - walls[0]))

    # -- the general form ---------------------------------------------------------------------------
    def set_boundary_pressure(self, wall: int, pressure: Callable[..., Any]) -> None:
        """Impose the time-dependent pressure ``pressure(x, y, z, t)`` on the pressure wall `wall` (0..5,
        e.g. flow.ymax): once per step it is called with numpy arrays of the x, y, z of the power centres of
        the wall's Dirichlet cells and t = O.time, and must return one finite pressure per cell (an array
        of their shape, or a number); these replace bndCondValue[wall] in the right-hand side only (no new
        system). pfv.waves has the thesis' profiles. It must not call the engine (that raises RuntimeError).
        One load per engine: this replaces the previous one."""
        if isinstance(wall, bool) or not isinstance(wall, int):
            raise TypeError(f"set_boundary_pressure wall must be a wall index 0..5 (e.g. flow.ymax), got {wall!r}")
        if not 0 <= wall < 6:
            raise ValueError(f"set_boundary_pressure wall must be in 0..5, got {wall}")
        if not callable(pressure):
            raise TypeError(f"set_boundary_pressure pressure must be a callable p(x, y, z, t), got {pressure!r}")
        if self._wave_action:
            raise ValueError("set_boundary_pressure: waveAction is on; set waveAction = False first, the engine "
                             "takes one time-dependent load")
        self._install((wall, pressure))

    def clear_boundary_pressure(self) -> None:
        """Remove the load of set_boundary_pressure (waveAction = False removes YADE's): the wall's
        bndCondValue applies again from the next step."""
        if not self._wave_action:
            self._install(None)

    @property
    def boundary_pressure(self) -> tuple[int, Callable[..., Any]] | None:
        """(wall, p) of set_boundary_pressure, or None."""
        function = self._pressure_function
        return None if function is None or self._wave_action else function

    @exclusive
    def _install(self, function: tuple[int, Callable[..., Any]] | None) -> None:
        object.__setattr__(self, "_pressure_function", function)
        if function is None:
            self._core.set_pressure_field(-1, None)
        else:
            # A weak reference: the core must not keep its engine alive.
            method = weakref.WeakMethod(self._evaluate_pressure)
            self._core.set_pressure_field(function[0], lambda positions: method()(positions))

    def _prepare_pressure(self, scene: Any, walls: Any) -> None:
        """Before a step with a load: the time and boundaries it is evaluated at."""
        wall = self._pressure_function[0]
        if not self._core.bnd_is_pressure[wall]:
            name = "waveAction" if self._wave_action else "set_boundary_pressure"
            raise ValueError(f"{name}: wall {wall} ({WALL_NAMES[wall]}) is not a pressure boundary; set "
                             f"bndCondIsPressure[{wall}] = True")
        object.__setattr__(self, "_field_time", float(scene.time))
        object.__setattr__(self, "_field_walls", tuple(walls))

    def _evaluate_pressure(self, positions: np.ndarray) -> np.ndarray:
        """Called by the core inside its step: the load at the wall's Dirichlet cells, checked."""
        wall, function = self._pressure_function
        name = "waveAction" if self._wave_action else f"set_boundary_pressure({WALL_NAMES[wall]})"
        n = len(positions)
        p = function(positions[:, 0], positions[:, 1], positions[:, 2], self._field_time)
        try:
            if p is None:  # numpy would take it for NaN
                raise TypeError
            p = np.asarray(p, dtype=float)
        except (TypeError, ValueError):
            raise TypeError(f"{name}: the pressure function must return numbers, got {p!r:.80}") from None
        if p.ndim == 0:
            p = np.full(n, float(p))
        elif p.shape != (n,):
            raise ValueError(f"{name}: the pressure function returned shape {p.shape} for {n} boundary cells; "
                             f"it must return one pressure per cell, shape ({n},)")
        bad = ~np.isfinite(p)
        if bad.any():
            i = int(np.argmax(bad))
            raise ValueError(f"{name}: the pressure function gave {p[i]} (not finite) at {tuple(positions[i])}, "
                             f"t = {self._field_time} ({int(bad.sum())} of {n} cells)")
        return np.ascontiguousarray(p)
