"""Pressures on a wall beyond its bndCondValue, a part of ``pfv.FlowEngine``: YADE's waveAction and
its pressure profile on ymax (boundaryXPos, boundaryPressure), and PFV's general form
``set_boundary_pressure(wall, p)`` (pfv.waves, doc/waves.md).

waveAction and set_boundary_pressure hand the core one function of the positions of a pressure
wall's Dirichlet cells, which the core calls once per step after any remesh
(pfv/model/boundary_conditions.hpp, PressureField); the profile is a table the core interpolates.
Their values replace the wall's bndCondValue in the right-hand side only: a time-dependent load
never rebuilds the system. Without a load nothing here runs during a step.
"""
from __future__ import annotations

import math
import numbers
import weakref
from collections.abc import Sequence
from typing import Any, Callable

import numpy as np

from . import _attributes as attributes

WALL_NAMES = ("xmin", "xmax", "ymin", "ymax", "zmin", "zmax")
_YADE_WAVE_WALL = 3  # YADE's waveAction loads ymax and its profile lies on ymax


def _real_values(name: str, p: Any) -> np.ndarray:
    """What a pressure function returned, as floats: real numbers only (Python or numpy ints and floats,
    or an array of them). A string, None, a bool, a complex number or an array of those raises
    TypeError, where numpy would read "5.0" as 5, True as 1, None as NaN or drop an imaginary part."""
    refused = TypeError(
        f"{name}: the pressure function must return numbers (real: no strings, bools, None or complex), got {p!r:.80}"
    )
    if isinstance(p, (str, bytes, bool, np.bool_)) or p is None:
        raise refused
    try:
        values = np.asarray(p)
    except (TypeError, ValueError):  # ragged sequences
        raise refused from None
    if values.dtype.kind not in "iuf":
        raise refused
    return values.astype(float)


class BoundaryPressure:
    """waveAction, sineMagnitude, sineAverage, boundaryXPos, boundaryPressure and set_boundary_pressure
    of the engine whose pfv.Engine is `core`."""

    def __init__(self, core: Any) -> None:
        self._core = core
        self._wave_action = False
        self._sine_magnitude = 0.0
        self._sine_average = 0.0
        self._function: tuple[int, Callable[..., Any]] | None = None  # (wall, p), or None
        self._time = 0.0  # O.time of the step being computed
        self._walls = (0.0, 1.0, 0.0, 1.0, 0.0, 1.0)  # the six boundary coordinates of that step
        self._x_pos: tuple[float, ...] = ()  # boundaryXPos
        self._pressures: tuple[float, ...] = ()  # boundaryPressure

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
        if value and self._function is not None:
            raise ValueError(
                "waveAction: a boundary pressure function is set (set_boundary_pressure); clear it "
                "first (clear_boundary_pressure), the engine takes one time-dependent load"
            )
        self._wave_action = value
        self._install((_YADE_WAVE_WALL, self._yade_wave) if value else None)

    @property
    def sineMagnitude(self) -> float:
        """Amplitude of waveAction's cosine [Pa]; a change applies at the next step."""
        return self._sine_magnitude

    @sineMagnitude.setter
    def sineMagnitude(self, value: float) -> None:
        self._sine_magnitude = attributes.as_number("sineMagnitude", value)

    @property
    def sineAverage(self) -> float:
        """Mean of waveAction's pressure [Pa]; a change applies at the next step."""
        return self._sine_average

    @sineAverage.setter
    def sineAverage(self, value: float) -> None:
        self._sine_average = attributes.as_number("sineAverage", value)

    def _yade_wave(self, x: np.ndarray, y: np.ndarray, z: np.ndarray, t: float) -> np.ndarray:
        walls = self._walls
        return self._sine_average + self._sine_magnitude * np.cos(math.pi * (x - walls[0]) / (walls[1] - walls[0]))

    # -- YADE's pressure profile on ymax ------------------------------------------------------------
    @property
    def boundaryXPos(self) -> list[float]:
        """x of the points of the pressure profile on ymax (see boundaryPressure)."""
        return list(self._x_pos)

    @boundaryXPos.setter
    def boundaryXPos(self, value: Sequence[float]) -> None:
        self._x_pos = tuple(attributes.as_numbers("boundaryXPos", value))
        self._push_profile()

    @property
    def boundaryPressure(self) -> list[float]:
        """Pressures along x on the ymax boundary, at boundaryXPos: while both lists have the same length
        (at least 2) the Dirichlet cells of ymax (bndCondIsPressure[ymax]) take the pressure interpolated
        at the x of their power centre, bndCondValue[ymax] beyond the points. Applies at the next step."""
        return list(self._pressures)

    @boundaryPressure.setter
    def boundaryPressure(self, value: Sequence[float]) -> None:
        self._pressures = tuple(attributes.as_numbers("boundaryPressure", value))
        self._push_profile()

    def _push_profile(self) -> None:
        xs, ps = list(self._x_pos), list(self._pressures)
        consistent = len(xs) == len(ps) and len(xs) >= 2
        self._core.pressure_profile = (_YADE_WAVE_WALL, 0, xs, ps) if consistent else (_YADE_WAVE_WALL, 0, [], [])

    # -- the general form ---------------------------------------------------------------------------
    def set_boundary_pressure(self, wall: int, pressure: Callable[..., Any]) -> None:
        """Impose the time-dependent pressure ``pressure(x, y, z, t)`` on the pressure wall `wall` (0..5,
        e.g. flow.ymax): once per step it is called with numpy arrays of the x, y, z of the power centres of
        the wall's Dirichlet cells and t = O.time, and must return one finite pressure per cell (an array
        of their shape, or a number); these replace bndCondValue[wall] in the right-hand side only (no new
        system). pfv.waves has the thesis' profiles. It must not call the engine (that raises RuntimeError).
        One load per engine: this replaces the previous one."""
        if isinstance(wall, (bool, np.bool_)) or not isinstance(wall, numbers.Integral):
            raise TypeError(f"set_boundary_pressure wall must be a wall index 0..5 (e.g. flow.ymax), got {wall!r}")
        wall = int(wall)
        if not 0 <= wall < 6:
            raise ValueError(f"set_boundary_pressure wall must be in 0..5, got {wall}")
        if not callable(pressure):
            raise TypeError(f"set_boundary_pressure pressure must be a callable p(x, y, z, t), got {pressure!r}")
        if self._wave_action:
            raise ValueError(
                "set_boundary_pressure: waveAction is on; set waveAction = False first, the engine "
                "takes one time-dependent load"
            )
        self._install((wall, pressure))

    def clear_boundary_pressure(self) -> None:
        """Remove the load of set_boundary_pressure (waveAction = False removes YADE's): the wall's
        bndCondValue applies again from the next step."""
        if not self._wave_action:
            self._install(None)

    @property
    def boundary_pressure(self) -> tuple[int, Callable[..., Any]] | None:
        """(wall, p) of set_boundary_pressure, or None."""
        function = self._function
        return None if function is None or self._wave_action else function

    def _install(self, function: tuple[int, Callable[..., Any]] | None) -> None:
        self._function = function
        if function is None:
            self._core.set_pressure_field(-1, None)
        else:
            # A weak reference: the core must not keep its engine alive.
            method = weakref.WeakMethod(self._evaluate_pressure)
            self._core.set_pressure_field(function[0], lambda positions: method()(positions))

    @property
    def active(self) -> bool:
        """Whether a function load is set (waveAction or set_boundary_pressure)."""
        return self._function is not None

    def prepare(self, scene: Any, walls: Any) -> None:
        """Before a step with a load: the time and boundaries it is evaluated at."""
        wall = self._function[0]
        if not self._core.bnd_is_pressure[wall]:
            name = "waveAction" if self._wave_action else "set_boundary_pressure"
            raise ValueError(
                f"{name}: wall {wall} ({WALL_NAMES[wall]}) is not a pressure boundary; set "
                f"bndCondIsPressure[{wall}] = True"
            )
        self._time = float(scene.time)
        self._walls = tuple(walls)

    def _evaluate_pressure(self, positions: np.ndarray) -> np.ndarray:
        """Called by the core inside its step: the load at the wall's Dirichlet cells, checked."""
        wall, function = self._function
        name = "waveAction" if self._wave_action else f"set_boundary_pressure({WALL_NAMES[wall]})"
        n = len(positions)
        p = function(positions[:, 0], positions[:, 1], positions[:, 2], self._time)
        p = _real_values(name, p)
        if p.ndim == 0:
            p = np.full(n, float(p))
        elif p.shape != (n,):
            raise ValueError(
                f"{name}: the pressure function returned shape {p.shape} for {n} boundary cells; "
                f"it must return one pressure per cell, shape ({n},)"
            )
        bad = ~np.isfinite(p)
        if bad.any():
            i = int(np.argmax(bad))
            raise ValueError(
                f"{name}: the pressure function gave {p[i]} (not finite) at {tuple(positions[i])}, "
                f"t = {self._time} ({int(bad.sum())} of {n} cells)"
            )
        return np.ascontiguousarray(p)

    # -- O.save / O.load ----------------------------------------------------------------------------
    def saved(self) -> dict[str, Any]:
        """The settings (a function of set_boundary_pressure is not saved: the engine warns)."""
        return {
            "wave_action": self._wave_action,
            "sine_magnitude": self._sine_magnitude,
            "sine_average": self._sine_average,
            "boundary_x_pos": list(self._x_pos),
            "boundary_pressure": list(self._pressures),
        }

    def restore(self, state: dict[str, Any]) -> None:
        self.sineMagnitude = state["sine_magnitude"]
        self.sineAverage = state["sine_average"]
        self.waveAction = state["wave_action"]
        self._x_pos = tuple(state["boundary_x_pos"])
        self._pressures = tuple(state["boundary_pressure"])
