"""pfv.diagnostics.instability_onset, the criterion of examples/wave_ramp.py, on synthetic records:
the amplitude where a bed under a growing load starts to move, i.e. where the root-mean-square grain
velocity sqrt(2 KE / M) exceeds threshold * sqrt(g d50) after having been at or below it.

    yade-double -n -x tests/yade/robustness/test_instability_onset.py        (exit 0 = pass)

A bed still settling from its deposition when the load starts (the 5000-grain loose bed's record
begins above the 1 % threshold) must not count as failing at once; a bed that never settles or never
moves again gives NaN; bad records are refused by name.
"""
import math

import numpy as np

from pfv_testing import robustness as rb
from pfv_testing.robustness import expect_error
from pfv import diagnostics  # noqa: E402

MASS, D50, G, F = 1500.0, 0.06, 9.81, 0.01
V_REF = F * math.sqrt(G * D50)  # the threshold velocity


def energy(v):
    """KE of the bed whose rms grain velocity is v."""
    return 0.5 * MASS * np.asarray(v) ** 2


amplitude = np.linspace(0, 2000, 401)  # 5 Pa per record
at_rest = np.full(amplitude.shape, 1e-3 * V_REF)
fails = at_rest.copy()
fails[amplitude >= 1425] = 3 * V_REF
onset = diagnostics.instability_onset(amplitude, energy(fails), MASS, D50, F, G)
rb.check("a bed at rest that moves from 1425 Pa on", onset == 1425.0, f"(got {onset})")

settling = fails.copy()
settling[amplitude <= 40] = 5 * V_REF  # still creeping from its deposition, at rest from 45 Pa
onset = diagnostics.instability_onset(amplitude, energy(settling), MASS, D50, F, G)
rb.check("the settling transient at the start does not count", onset == 1425.0, f"(got {onset})")
just_below = at_rest.copy()
just_below[amplitude >= 300] = 0.999 * V_REF
just_below[amplitude >= 310] = 1.001 * V_REF
onset = diagnostics.instability_onset(amplitude, energy(just_below), MASS, D50, F, G)
rb.check("the threshold is sharp: 0.999 of it is rest, 1.001 motion", onset == 310.0, f"(got {onset})")
rb.check(
    "a looser threshold fires at the first excursion",
    diagnostics.instability_onset(amplitude, energy(just_below), MASS, D50, 0.5 * F, G) == 300.0,
)

never_rests = np.full(amplitude.shape, 2 * V_REF)


def onset_of(v):
    return diagnostics.instability_onset(amplitude, energy(v), MASS, D50, F, G)


rb.check("never at rest: NaN", math.isnan(onset_of(never_rests)))
rb.check("never moves again: NaN", math.isnan(onset_of(at_rest)))

expect_error(
    "records of two lengths",
    ValueError,
    "one length",
    lambda: diagnostics.instability_onset(amplitude[:-1], energy(fails), MASS, D50, F),
)
expect_error(
    "a negative kinetic energy",
    ValueError,
    "non-negative",
    lambda: diagnostics.instability_onset(amplitude, -energy(fails), MASS, D50, F),
)
nan_record = energy(fails)
nan_record[7] = float("nan")
expect_error(
    "a NaN in the record",
    ValueError,
    "finite",
    lambda: diagnostics.instability_onset(amplitude, nan_record, MASS, D50, F),
)
expect_error(
    "a zero mass", ValueError, "mass", lambda: diagnostics.instability_onset(amplitude, energy(fails), 0.0, D50, F)
)
expect_error(
    "a negative threshold",
    ValueError,
    "threshold",
    lambda: diagnostics.instability_onset(amplitude, energy(fails), MASS, D50, -F),
)
rb.report("instability onset")
