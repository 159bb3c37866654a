"""The usual scene of the robustness tests, the 1000-sphere permeameter with a new pfv engine, and the checks they
share (pfv_testing.checks, re-exported here)."""
import math

from pfv import FlowEngine
from pfv_testing import scenes
from pfv_testing.checks import check, expect_error, fail, failures, report  # noqa: F401 (re-exported)
from yade import O


def finish_iteration():
    """An exception inside an engine leaves YADE's iteration half-done (O.subStep >= 0); YADE's
    next run finishes it without re-running the failed engine. Finish it so that each check
    starts on a whole iteration."""
    if O.subStep >= 0:
        O.run(1, True)


def run(steps=1):
    try:
        O.run(steps, True)
    finally:
        finish_iteration()


def fresh(frozen=True, **kw):
    """The 1000-sphere permeameter (walls 0..5, pressure 1 on ymin, 0 on ymax) with a new engine."""
    scenes.build_permeameter(num=1000, frozen=frozen)
    flow = FlowEngine(label="flow", **kw)
    scenes.configure_flow(flow, axis=1, dp=1.0)
    scenes.insert_flow(flow)
    return flow


def conserved(flow, tol=1e-8):
    """What leaves through the six walls equals what the imposed fluxes inject less what the pores
    take up, relative to the largest wall flux. (Imposed pressures are sources of unknown
    strength, and a compressible fluid stores some: not for scenes with those.)"""
    fluxes = [flow.core.boundary_flux(w) for w in range(6)]
    imbalance = sum(fluxes) + flow.core.volume_rate_total() - flow.core.imposed_flux_total()
    scale = max(abs(q) for q in fluxes)
    return all(map(math.isfinite, fluxes)) and abs(imbalance) <= tol * scale, (scale, imbalance)
