"""The --quick oedometer with pfv.FlowEngine reproduces Terzaghi's consolidation (examples/oedometer.py).

    yade-double -n -x tests/yade/examples/test_oedometer_quick.py        (exit 0 = pass, 1 = fail)

Runs `yade-double -n -x examples/oedometer.py --quick --engine=pfv --out=DIR` (1000 spheres, drained top wall,
impermeable bottom; the prepared dry sample is cached in $PFV_CACHE_DIR) and checks its summary.json.
The thresholds are about 1.5 times the errors measured with pfv (and with YADE's own FlowEngine, which does slightly
worse on the same sample, see doc/validation.md), and far from what a broken coupling gives:

* without the dV/dt term in the pressure system there is no excess pore pressure at all and the sample settles at
  once: p_mid/load ~ 0, max |U_sim - U_theory| ~ 0.8;
* without the fluid forces on the wall bodies the impermeable bottom wall only feels the effective stress, so the
  total vertical stress it reads misses the pore pressure (error ~ 0.9 of the load right after loading).

Error figures are taken once the load has crossed the sample twice at the oedometric wave speed (Terzaghi's theory
is quasi-static; the example prints and plots the earlier samples too).
"""
from pfv_testing import checks
from pfv_testing.oedometer import run_and_check

# name, value in summary.json, lower bound, upper bound
THRESHOLDS = [
    ('max |U_sim - U_theory| (measured C_v)', 'U_max_abs_error', 0.0, 0.10),
    ('RMS isochrone pressure error / load', 'isochrone_rms_error', 0.0, 0.075),
    ('RMS mid-height pressure error / load', 'mid_pressure_rms_error', 0.0, 0.09),
    # the window's peak: the whole record's includes the servo's overshoot at loading, 2.6 x the load in both engines
    (
        'peak mid-height excess pressure / load in the error window (the fluid takes the load)',
        'max_p_mid_over_load_window',
        0.85,
        1.5,
    ),
    ('U at the end (T_v = 1, Terzaghi 0.931)', 'final_U', 0.90, 0.99),
    ('max |total vertical stress on the bottom - applied| / load', 'bottom_total_stress_max_error', 0.0, 0.10),
    ('max |U_sim - U_theory| with a drained layer of one radius', 'U_max_abs_error_layer', 0.0, 0.04),
    # claim 18; measured 0.078, at the top slice (spheres cut by the drained wall's layer), interior below 0.05
    ('max |p + d(sigma\'_yy) - load| / load over 10 slices at T_v = 0.1', 'p_plus_sigma_eff_max_error_Tv01', 0.0, 0.12),
]


def permeameter(s):
    ok = s['Cv'] > 0 and s['K'] > 0 and abs(abs(s['Qin']) / abs(s['Qout']) - 1) < 1e-6
    return [(ok, 'permeameter: K = %.4g m/s, |Qin| = |Qout| (%.6g, %.6g)' % (s['K'], s['Qin'], s['Qout']))]


run_and_check(['--quick', '--engine=pfv'], THRESHOLDS, permeameter)
checks.report('oedometer')
