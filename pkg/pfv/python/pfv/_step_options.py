"""YADE's attributes that change what a pfv.FlowEngine step does, a part of the engine: pressureForce
(no flow at all while False), decoupleForces (forces computed, not applied) and desiredPorosity (the
volume correction of dV/dt).
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np

from . import _attributes as attributes


class StepOptions:
    """pressureForce, decoupleForces and desiredPorosity of the engine whose pfv.Engine is `core`."""

    def __init__(self, core: Any) -> None:
        self._core = core
        self._pressure_force = True
        self._decouple_forces = False
        self._desired_porosity = 0.0

    @property
    def pressureForce(self) -> bool:
        """False: the engine computes no flow at all (its step does nothing; the next step after it is on again
        has no dV/dt term)."""
        return self._pressure_force

    @pressureForce.setter
    def pressureForce(self, value: bool) -> None:
        self._pressure_force = attributes.as_flag("pressureForce", value)

    @property
    def decoupleForces(self) -> bool:
        """The fluid forces are computed (fluidForce) but not applied to the bodies."""
        return self._decouple_forces

    @decoupleForces.setter
    def decoupleForces(self, value: bool) -> None:
        self._decouple_forces = attributes.as_flag("decoupleForces", value)

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
        self._desired_porosity = value

    def correct_volumes(self, pos: np.ndarray, radii: np.ndarray) -> None:
        """Before a step, with desiredPorosity: volumeCorrection from the porosity of the spheres' bounding box."""
        if not self._desired_porosity:
            return
        low, high = (pos - radii[:, None]).min(axis=0), (pos + radii[:, None]).max(axis=0)
        box = float(np.prod(high - low))
        porosity = (box - 4.0 / 3.0 * math.pi * float(np.sum(radii**3))) / box
        if porosity > 0:
            self._core.volume_correction = self._desired_porosity / porosity

    # -- O.save / O.load ----------------------------------------------------------------------------
    def saved(self) -> dict[str, Any]:
        return {
            "pressure_force": self._pressure_force,
            "decouple_forces": self._decouple_forces,
            "desired_porosity": self._desired_porosity,
        }

    def restore(self, state: dict[str, Any]) -> None:
        self._pressure_force = state["pressure_force"]
        self._decouple_forces = state["decouple_forces"]
        self._desired_porosity = state["desired_porosity"]
