"""YADE attributes a pfv.FlowEngine keeps for YADE's scripts without acting on them, a part of the
engine: values other than YADE's defaults are accepted (unlike the attributes ``_attributes`` refuses)
because they configure what PFV does otherwise or not at all, and read back as set.
"""
from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from yade.minieigenHP import Vector3

from . import _attributes as attributes


def _thread_count(name: str, value: Any) -> int:
    return attributes.as_integer(name, value, low=1)


class KeptSettings:
    """permeabilityMap, numSolveThreads, numFactorizeThreads, boundaryVelocity, ids and volumeFactor."""

    def __init__(self) -> None:
        self._permeability_map = False
        self._solve_threads = 1
        self._factorize_threads = 1
        self._boundary_velocity = ((0.0, 0.0, 0.0),) * 6
        self._ids: tuple[int, ...] = ()
        self._volume_factor = 1.0

    @property
    def permeabilityMap(self) -> bool:
        """Accepted for YADE's scripts: YADE keeps a per-cell permeability for its VTK output with it; PFV's step
        does not change."""
        return self._permeability_map

    @permeabilityMap.setter
    def permeabilityMap(self, value: bool) -> None:
        self._permeability_map = attributes.as_flag("permeabilityMap", value)

    @property
    def numSolveThreads(self) -> int:
        """Accepted for YADE's scripts (YADE's OpenBLAS threads of a solve); PFV's threads are ompThreads."""
        return self._solve_threads

    @numSolveThreads.setter
    def numSolveThreads(self, value: int) -> None:
        self._solve_threads = _thread_count("numSolveThreads", value)

    @property
    def numFactorizeThreads(self) -> int:
        """Accepted for YADE's scripts (YADE's OpenBLAS threads of a factorisation); PFV's are ompThreads."""
        return self._factorize_threads

    @numFactorizeThreads.setter
    def numFactorizeThreads(self, value: int) -> None:
        self._factorize_threads = _thread_count("numFactorizeThreads", value)

    @property
    def boundaryVelocity(self) -> list[Vector3]:
        """Velocities of the six boundaries, kept for YADE's scripts: YADE's own shear term skips the
        sphere-wall pairs that would read them, and PFV's pairs no sphere with a wall either."""
        return [Vector3(*v) for v in self._boundary_velocity]

    @boundaryVelocity.setter
    def boundaryVelocity(self, value: Sequence[Any]) -> None:
        if isinstance(value, (str, bytes)) or not isinstance(value, Sequence | np.ndarray):
            raise TypeError(f"boundaryVelocity must be a sequence of 6 vectors, got {value!r}")
        if len(value) != 6:
            raise ValueError("boundaryVelocity needs 6 vectors (xmin, xmax, ymin, ymax, zmin, zmax)")
        self._boundary_velocity = tuple(attributes.as_point(f"boundaryVelocity[{w}]", v) for w, v in enumerate(value))

    @property
    def ids(self) -> list[int]:
        """PartialEngine's body list, kept for YADE's scripts (YADE's FlowEngine does not use it)."""
        return list(self._ids)

    @ids.setter
    def ids(self, value: Sequence[int]) -> None:
        if isinstance(value, (str, bytes)) or not isinstance(value, Sequence | np.ndarray):
            raise TypeError(f"ids must be a sequence of body ids, got {value!r}")
        self._ids = tuple(attributes.as_index(f"ids[{i}]", v) for i, v in enumerate(value))

    @property
    def volumeFactor(self) -> float:
        """YADE's low-porosity factor for its thermal engine only (out of PFV's scope): kept, no effect."""
        return self._volume_factor

    @volumeFactor.setter
    def volumeFactor(self, value: float) -> None:
        value = attributes.as_number("volumeFactor", value)
        if value <= 0:
            raise ValueError(f"volumeFactor must be positive, got {value}")
        self._volume_factor = value

    # -- O.save / O.load ----------------------------------------------------------------------------
    def saved(self) -> dict[str, Any]:
        return {
            "permeability_map": self._permeability_map,
            "solve_threads": self._solve_threads,
            "factorize_threads": self._factorize_threads,
            "boundary_velocity": self._boundary_velocity,
            "ids": self._ids,
            "volume_factor": self._volume_factor,
        }

    def restore(self, state: dict[str, Any]) -> None:
        self._permeability_map = state["permeability_map"]
        self._solve_threads = state["solve_threads"]
        self._factorize_threads = state["factorize_threads"]
        self._boundary_velocity = tuple(tuple(v) for v in state["boundary_velocity"])
        self._ids = tuple(state["ids"])
        self._volume_factor = state["volume_factor"]
