"""Time-dependent pressures on a boundary: the wave loads of the thesis' chapter 6.

A load is any callable ``p(x, y, z, t)`` taking numpy arrays of the positions of a pressure wall's
boundary cells (and the time, a float) and returning one pressure per cell. ``pfv.FlowEngine``
calls it once per step with all the cells at once (never per cell) and applies the result as
the Dirichlet values of those cells: only the right-hand side of the pressure system changes,
never the system or its factor::

    from pfv import FlowEngine, waves
    flow = FlowEngine(bndCondIsPressure=[0, 0, 0, 1, 0, 0])
    flow.set_boundary_pressure(flow.ymax, waves.HalfWave(amplitude=0, rate=100, length=2.0))

The two profiles of the thesis are built in (doc/waves.md):

* ``HalfWave``: ``mean + A(t) (1 + cos(pi (x - origin) / length))`` with ``A(t) = amplitude +
  rate t``, the half-wavelength sinusoid of eq. (6.20) whose amplitude grows linearly (sections
  6.2, 6.3);
* ``StandingWave``: ``mean + amplitude sin(2 pi t / period) cos(pi (x - origin) / length)``, the
  oscillating load of section 6.4 (the thesis prints no formula; this is its reconstruction).
"""
from __future__ import annotations

import math
import numbers
from typing import Any

import numpy as np

__all__ = ["HalfWave", "StandingWave"]


def _number(owner: str, name: str, value: Any) -> float:
    if isinstance(value, (bool, str, bytes)) or not isinstance(value, numbers.Real):
        raise TypeError(f"{owner} {name} must be a number, got {value!r}")
    value = float(value)
    if not math.isfinite(value):
        raise ValueError(f"{owner} {name} must be finite, got {value!r}")
    return value


def _positive(owner: str, name: str, value: Any) -> float:
    value = _number(owner, name, value)
    if value <= 0:
        raise ValueError(f"{owner} {name} must be positive, got {value!r}")
    return value


class HalfWave:
    """``mean + (amplitude + rate t) (1 + cos(pi (x - origin) / length))``: the half-wavelength
    sinusoid of thesis eq. (6.20) with the amplitude ``A = gamma_f H0 / 2`` growing linearly in
    time (sections 6.2-6.3). ``length`` is the half-wavelength L (the sample's length along x),
    ``origin`` the x where the load is largest (the xmin wall)."""

    def __init__(
        self, amplitude: float = 0.0, length: float = 1.0, origin: float = 0.0, rate: float = 0.0, mean: float = 0.0
    ) -> None:
        self.amplitude = _number("HalfWave", "amplitude", amplitude)
        self.length = _positive("HalfWave", "length", length)
        self.origin = _number("HalfWave", "origin", origin)
        self.rate = _number("HalfWave", "rate", rate)
        self.mean = _number("HalfWave", "mean", mean)

    def amplitude_at(self, t: float) -> float:
        """A(t) [Pa]."""
        return self.amplitude + self.rate * t

    def __call__(self, x: np.ndarray, y: np.ndarray, z: np.ndarray, t: float) -> np.ndarray:
        return self.mean + self.amplitude_at(t) * (1.0 + np.cos((math.pi / self.length) * (x - self.origin)))

    def __repr__(self) -> str:
        return (
            f"HalfWave(amplitude={self.amplitude!r}, length={self.length!r}, origin={self.origin!r}, "
            f"rate={self.rate!r}, mean={self.mean!r})"
        )


class StandingWave:
    """``mean + amplitude sin(2 pi t / period) cos(pi (x - origin) / length)``: the standing wave of
    thesis section 6.4, oscillating between +-amplitude with the given period, over the
    half-wavelength ``length``."""

    def __init__(
        self, amplitude: float, period: float, length: float = 1.0, origin: float = 0.0, mean: float = 0.0
    ) -> None:
        self.amplitude = _number("StandingWave", "amplitude", amplitude)
        self.period = _positive("StandingWave", "period", period)
        self.length = _positive("StandingWave", "length", length)
        self.origin = _number("StandingWave", "origin", origin)
        self.mean = _number("StandingWave", "mean", mean)

    def amplitude_at(self, t: float) -> float:
        """The signed amplitude amplitude sin(2 pi t / period) [Pa]."""
        return self.amplitude * math.sin(2.0 * math.pi * t / self.period)

    def __call__(self, x: np.ndarray, y: np.ndarray, z: np.ndarray, t: float) -> np.ndarray:
        return self.mean + self.amplitude_at(t) * np.cos((math.pi / self.length) * (x - self.origin))

    def __repr__(self) -> str:
        return (
            f"StandingWave(amplitude={self.amplitude!r}, period={self.period!r}, length={self.length!r}, "
            f"origin={self.origin!r}, mean={self.mean!r})"
        )
