"""The --quick --nonlinear oedometer (200 kPa, thesis 4.4.2) with pfv.FlowEngine.

    yade-double -n -x tests/yade/examples/test_oedometer_nonlinear_quick.py        (exit 0 = pass, 1 = fail)

Runs `examples/oedometer.py --quick --nonlinear --engine=pfv` (1000 spheres; the sample compacts by ~5 % and its
conductivity falls by ~30 %) and checks summary.json. Measured with pfv (doc/validation.md, section 3): max |dU|
0.062 against Terzaghi with the initial C_v and 0.096 with the final one; 0.089 / isochrones 0.023 against the
reference whose K falls with the strain; bottom-wall stress error 0.005 of the load; drained volume / settlement
1.0000. Bounds are about 1.5 times those, far from a broken coupling (no dV/dt: dU ~ 0.8, no wall forces: the
bottom stress error ~ 0.9 of the load, see test_oedometer_quick.py).
"""
from pfv_testing import checks
from pfv_testing.oedometer import run_and_check

THRESHOLDS = [
    ('max |U_sim - U_theory| with C_v,init', 'U_max_abs_error', 0.0, 0.095),
    ('max |U_sim - U_theory| with C_v,final', 'U_max_abs_error_final_Cv', 0.0, 0.145),
    ('max |U_sim - U_theory| with K falling with the strain', 'U_max_abs_error_variable_K', 0.0, 0.135),
    ('RMS isochrone error / load, K falling with the strain', 'isochrone_rms_error_variable_K', 0.0, 0.035),
    ('peak mid-height excess pressure / load in the error window', 'max_p_mid_over_load_window', 0.85, 1.5),
    ('U at the end (T_v = 2)', 'final_U', 0.95, 1.05),
    ('max |total vertical stress on the bottom - applied| / load', 'bottom_total_stress_max_error', 0.0, 0.02),
    ('drained volume / settlement volume at the end', 'drained_over_settlement_volume_end', 0.99, 1.01),
]


def compaction(s):
    return [
        (
            s['K_final'] < 0.9 * s['K'] and s['Cv_final'] < s['Cv'],
            'the sample compacts: K %.4g -> %.4g m/s, C_v %.4g -> %.4g m2/s'
            % (s['K'], s['K_final'], s['Cv'], s['Cv_final']),
        )
    ]


run_and_check(['--quick', '--nonlinear', '--engine=pfv'], THRESHOLDS, compaction)
checks.report('nonlinear oedometer')
