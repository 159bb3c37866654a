"""The engine's stages in YADE's timing report: ``O.timingEnabled = True``, then ``timing.stats()``.

YADE prints, under each engine's line, the checkpoints of its ``timingDeltas`` (label, time in
nanoseconds, count), as its own FlowEngine does. A PyRunner has none, so pfv.FlowEngine gives
``timingDeltas`` an object with the same two members ``timing.stats()`` and ``timing.reset()``
use: ``data`` and ``reset()``. Only while ``O.timingEnabled`` does the step record anything (a
clock read per stage); the core measures its own stages at every step anyway (``step_times()``).
"""
from __future__ import annotations

import time
from typing import Any

# Stages of the core's step and remesh (step_times() / remesh_times() keys) and their labels.
_REMESH_STAGES = (
    ("triangulation", "remesh: triangulation"),
    ("geometry", "remesh: pore geometry"),
    ("conductance", "remesh: conductances"),
    ("force_cache", "remesh: force cache"),
    ("shear_geometry", "remesh: shear pairs"),
    ("assembly", "system: assembly"),
    ("analysis", "system: ordering"),
    ("factorization", "system: factorization"),
    ("carry_over", "remesh: pressures carried over"),
)
_STEP_STAGES = (
    ("conductance", "system: conductances"),  # a system rebuilt by the step without a remesh (periodic engine)
    ("assembly", "system: assembly"),
    ("factorization", "system: factorization"),
    ("volumes", "dV/dt"),
    ("pressure_field", "boundary pressure"),
    ("solve", "solve"),
    ("forces", "forces"),
    ("shear_forces", "shear forces"),
)


class StageTimings:
    """Accumulated time and count per stage, in YADE's TimingDeltas form."""

    def __init__(self) -> None:
        self._stages: dict[str, list[float]] = {}  # label -> [nanoseconds, count], in first-seen order

    def add(self, label: str, seconds: float) -> None:
        entry = self._stages.setdefault(label, [0.0, 0])
        entry[0] += seconds * 1e9
        entry[1] += 1

    @property
    def data(self) -> list[tuple[str, int, int]]:
        """[(label, nanoseconds, count), ...] as YADE's TimingDeltas.data."""
        return [(label, int(ns), count) for label, (ns, count) in self._stages.items()]

    def reset(self) -> None:
        self._stages.clear()


class StepClock:
    """Times the Python parts of one step and collects the core's stages into a StageTimings."""

    def __init__(self, timings: StageTimings) -> None:
        self._timings = timings
        self._last = time.perf_counter()

    def lap(self, label: str) -> None:
        """The time since the previous lap (or the start) goes to `label`."""
        now = time.perf_counter()
        self._timings.add(label, now - self._last)
        self._last = now

    def core_step(self, core: Any, remeshed: bool) -> None:
        """The core's stages of the step just made (and of its remesh), in place of one lap."""
        step = core.step_times()
        parts = 0.0
        if remeshed:
            remesh = core.remesh_times()
            for key, label in _REMESH_STAGES:
                if remesh[key] > 0:
                    self._timings.add(label, remesh[key])
                    parts += remesh[key]
        for key, label in _STEP_STAGES:
            if step[key] > 0:
                self._timings.add(label, step[key])
                parts += step[key]
        self._timings.add("core: rest of the step", max(step["total"] - parts, 0.0))
        self._last = time.perf_counter()


class IdleClock:
    """The step's clock while O.timingEnabled is off: records nothing."""

    def lap(self, label: str) -> None:
        pass

    def core_step(self, core: Any, remeshed: bool) -> None:
        pass
