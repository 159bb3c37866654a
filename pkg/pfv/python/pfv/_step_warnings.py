"""The one-time warnings of a pfv.FlowEngine, a part of the engine: what a step found that a user
should know once (an unconverged solve, inverted cells, auto's switch to multigrid, hidden spheres),
and the record of the warnings given, which the scene scan and the save share.
"""
from __future__ import annotations

import warnings
from typing import Any


class StepWatch:
    """What the core counted before a step, for StepWarnings.after_step to compare with."""

    def __init__(self, core: Any) -> None:
        self.remeshing = core.remesh_due()
        self.inversions = core.inversion_remeshes
        self.remeshes = core.remesh_count

    def remeshed(self, core: Any) -> bool:
        """Whether the step built a new mesh (its own or an adopted background one)."""
        return core.remesh_count != self.remeshes


class StepWarnings:
    """The warnings given once per engine; `given` holds their keys."""

    def __init__(self) -> None:
        self.given: set[str] = set()
        self._choice_builds = 0  # core.system_builds when the solver choice was last looked at

    def once(self, key: str) -> bool:
        """True the first time `key` is asked for: give the warning then."""
        if key in self.given:
            return False
        self.given.add(key)
        return True

    def after_step(self, core: Any, iteration: int, scan: Any, watch: StepWatch) -> None:
        """The warnings of the step just made at O.iter = `iteration` with the spheres of `scan`."""
        inverted = core.inversion_remeshes != watch.inversions
        if not core.converged and self.once("unconverged"):
            warnings.warn(
                f"pfv.FlowEngine: at iteration {iteration} the {core.solver.replace('_', ' ')} solve "
                f"stopped at {core.max_iterations} iterations above tolerance = {core.tolerance:g}; "
                "the pressures are not converged (raise the tolerance or use useSolver=3)",
                stacklevel=3,
            )
        if inverted and self.once("inverted"):
            warnings.warn(
                f"pfv.FlowEngine: at iteration {iteration} spheres had moved so far since the last "
                "remesh that 2 % of the pore volume was turned inside out; remeshed (and will again "
                "whenever this happens). Lower meshUpdateInterval or defTolerance for motion this fast",
                stacklevel=3,
            )
        self._auto_multigrid(core, iteration)
        if watch.remeshing or inverted:
            self._hidden_spheres(core, scan)

    def _auto_multigrid(self, core: Any, iteration: int) -> None:
        # The choice changes only with a new system: look at it once per build, not per step.
        if "auto multigrid" in self.given or core.system_builds == self._choice_builds:
            return
        self._choice_builds = core.system_builds
        choice = core.solver_choice
        if core.solver == "auto" and choice.startswith("multigrid: the Cholesky"):  # not "kept from ..."
            self.given.add("auto multigrid")
            bound = ", or raise max_factor_bytes" if "budget" in choice else ""  # not CHOLMOD's index range
            warnings.warn(
                f"pfv.FlowEngine: solver='auto' solves by multigrid from iteration {iteration}: "
                f"{choice[len('multigrid: '):]}. Set solver='multigrid' to skip the Cholesky "
                f"analysis at the start{bound}",
                stacklevel=4,
            )

    @staticmethod
    def _hidden_spheres(core: Any, scan: Any) -> None:
        hidden = core.hidden_spheres()
        if hidden:
            yade_ids = scan.ids[hidden][:10].tolist()
            warnings.warn(
                f"pfv.FlowEngine: {len(hidden)} spheres are hidden by larger neighbours in the "
                f"regular triangulation and get no fluid force (ids {yade_ids}...)",
                stacklevel=4,
            )
