"""The --quick oedometer with pfv.FlowEngine reproduces Terzaghi's consolidation (examples/oedometer.py).

    yade-double -n -x tests/yade/test_oedometer_quick.py        (exit 0 = pass, 1 = fail)

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
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(sys.argv[0]))
EXAMPLE = os.path.normpath(os.path.join(HERE, '..', '..', 'examples', 'oedometer.py'))

# name, value in summary.json, lower bound, upper bound
THRESHOLDS = [
    ('max |U_sim - U_theory| (measured C_v)', 'U_max_abs_error', 0.0, 0.10),
    ('RMS isochrone pressure error / load', 'isochrone_rms_error', 0.0, 0.075),
    ('RMS mid-height pressure error / load', 'mid_pressure_rms_error', 0.0, 0.09),
    ('peak mid-height excess pressure / load (the fluid takes the load)', 'max_p_mid_over_load', 0.85, 1.5),
    ('U at the end (T_v = 1, Terzaghi 0.931)', 'final_U', 0.90, 0.99),
    ('max |total vertical stress on the bottom - applied| / load', 'bottom_total_stress_max_error', 0.0, 0.10),
    ('max |U_sim - U_theory| with a drained layer of one radius', 'U_max_abs_error_layer', 0.0, 0.04),
]


def main():
    out = tempfile.mkdtemp(prefix='pfv-oedometer-quick-')
    yade = shutil.which('yade-double') or '/usr/bin/yade-double'
    cmd = [yade, '-n', '-x', EXAMPLE, '--quick', '--engine=pfv', '--out=' + out]
    print('running: ' + ' '.join(cmd), flush=True)
    proc = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    lines = [l for l in proc.stdout.splitlines() if l.startswith('oedometer:')]
    print('\n'.join(lines))
    path = os.path.join(out, 'summary.json')
    if proc.returncode != 0 or not os.path.exists(path):
        print(proc.stdout[-3000:])
        print('FAIL the example did not complete (exit code %d)' % proc.returncode)
        return 1
    with open(path) as f:
        s = json.load(f)
    failures = 0
    for name, key, lo, hi in THRESHOLDS:
        v = s[key]
        ok = math.isfinite(v) and lo <= v <= hi
        failures += not ok
        print('%s %s = %.4f (allowed %g .. %g)' % ('ok  ' if ok else 'FAIL', name, v, lo, hi))
    ok = s['Cv'] > 0 and s['K'] > 0 and abs(abs(s['Qin']) / abs(s['Qout']) - 1) < 1e-6
    failures += not ok
    print('%s permeameter: K = %.4g m/s, |Qin| = |Qout| (%.6g, %.6g)' % ('ok  ' if ok else 'FAIL', s['K'], s['Qin'],
                                                                         s['Qout']))
    print('%d failed; outputs in %s' % (failures, out))
    if not failures:
        shutil.rmtree(out, ignore_errors=True)
    return 1 if failures else 0


sys.exit(main())
