"""What a pfv.FlowEngine runs and prints around its steps on request, a part of the engine: YADE's
blockHook (Python code the core runs for every new mesh, between the mesh and its linear system), debug,
getCHOLMODPerfTimings and meanKStat. With none of them on, a step does not look here again.
"""
from __future__ import annotations

from typing import Any

import numpy as np

import yade

from . import _attributes as attributes


class StepReports:
    """blockHook and the reports of the engine whose pfv.Engine is `core`."""

    def __init__(self, core: Any) -> None:
        self._core = core
        self._block_hook = ""
        self._debug = False
        self._perf_timings = False
        self._mean_k_stat = False
        self.active = False  # any of the reports (or a blockHook) is on

    # -- YADE's attributes ------------------------------------------------------------------------
    @property
    def blockHook(self) -> str:
        """Python code run in __main__ for every new mesh, after the mesh is built and before its linear
        system: the place for blockCell and other conditions on the new cells. The core runs it on every
        mesh, whichever way it came (the step's own remesh, one built in the background with multithread,
        one forced by inverted cells), so its conditions hold from the mesh's first step."""
        return self._block_hook

    @blockHook.setter
    def blockHook(self, value: str) -> None:
        if not isinstance(value, str):
            raise TypeError(f"blockHook must be a string (Python code), got {value!r}")
        if value.strip():
            compile(value, "blockHook", "exec")  # a syntax error now, not at the next remesh
        self._block_hook = value
        self._core.set_mesh_hook(self.run_block_hook if value.strip() else None)
        self._update()

    @property
    def debug(self) -> bool:
        """Print one line per step: remesh, system, cells, solve."""
        return self._debug

    @debug.setter
    def debug(self, value: bool) -> None:
        self._debug = attributes.as_flag("debug", value)
        self._update()

    @property
    def getCHOLMODPerfTimings(self) -> bool:
        """Print the times to build, analyse and factorise each new linear system."""
        return self._perf_timings

    @getCHOLMODPerfTimings.setter
    def getCHOLMODPerfTimings(self, value: bool) -> None:
        self._perf_timings = attributes.as_flag("getCHOLMODPerfTimings", value)
        self._update()

    @property
    def meanKStat(self) -> bool:
        """Print, at each remesh, how many throat conductances the clamp (clampKValues) changed."""
        return self._mean_k_stat

    @meanKStat.setter
    def meanKStat(self, value: bool) -> None:
        self._mean_k_stat = attributes.as_flag("meanKStat", value)
        self._update()

    def _update(self) -> None:
        self.active = bool(self._debug or self._perf_timings or self._mean_k_stat or self._block_hook)

    # -- around a step ------------------------------------------------------------------------------
    def run_block_hook(self) -> None:
        import __main__

        exec(compile(self._block_hook, "blockHook", "exec"), vars(__main__))

    def before_step(self) -> tuple[int, int] | None:
        """What after_step compares with: the core's remesh and system counts, None with nothing on."""
        return (self._core.remesh_count, self._core.system_builds) if self.active else None

    def after_step(self, before: tuple[int, int] | None) -> None:
        """The reports that are on."""
        if before is None:
            return
        core = self._core
        remeshed = core.remesh_count != before[0]
        rebuilt = core.system_builds != before[1]
        if self._perf_timings and rebuilt:
            t = core.system_times()
            print(
                f"CHOLMOD Time to build linear equations {round(t['assembly'] * 1e6)}\n"
                f"CHOLMOD Time to analyze {round(t['analysis'] * 1e6)}\n"
                f"CHOLMOD Time to factorize {round(t['factorization'] * 1e6)}  (microseconds, pfv)"
            )
        if self._mean_k_stat and remeshed:
            self._print_clamped()
        if self._debug:
            print(
                f"pfv.FlowEngine: iter {yade.O.iter}: {'remeshed, ' if remeshed else ''}"
                f"{'new system, ' if rebuilt else ''}{core.n_cells()} cells, "
                f"solve {core.step_times()['solve']:.3g} s"
            )

    def _print_clamped(self) -> None:
        core = self._core
        k = core.conductances()
        k = k[k > 0]
        if len(k):
            median = float(np.median(k))
            low, high = core.min_k_div_k_mean * median, core.max_k_div_k_mean * median
            print(
                f"meanKStat (pfv): median k {median:.6g}; {int(np.sum(np.isclose(k, low)))} throats at "
                f"minKdivKmean x median, {int(np.sum(np.isclose(k, high)))} at maxKdivKmean x median"
                + ("" if core.clamp_k_values else " (clampKValues off)")
            )

    # -- O.save / O.load ----------------------------------------------------------------------------
    def saved(self) -> dict[str, Any]:
        return {
            "block_hook": self._block_hook,
            "debug": self._debug,
            "perf_timings": self._perf_timings,
            "mean_k_stat": self._mean_k_stat,
        }

    def restore(self, state: dict[str, Any]) -> None:
        self.blockHook = state["block_hook"]
        self._debug = state["debug"]
        self._perf_timings = state["perf_timings"]
        self._mean_k_stat = state["mean_k_stat"]
        self._update()
