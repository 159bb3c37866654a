"""Shared by the oedometer tests: run examples/oedometer.py headless and check its summary.json against bounds."""
import json
import math
import os
import shutil
import subprocess
import tempfile

from pfv_testing import checks, paths

EXAMPLE = paths.example('oedometer.py')


def run_and_check(args, thresholds, extra_check=None):
    """thresholds: (name, summary key, lower, upper); extra_check(summary) -> list of (ok, message).
    Each bound is a check of pfv_testing.checks; returns the exit code of the checks so far (0 = all passed)."""
    out = tempfile.mkdtemp(prefix='pfv-oedometer-test-')
    yade = shutil.which('yade-double') or '/usr/bin/yade-double'
    cmd = [yade, '-n', '-x', EXAMPLE] + list(args) + ['--out=' + out]
    print('running: ' + ' '.join(cmd), flush=True)
    proc = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    lines = [line for line in proc.stdout.splitlines() if line.startswith('oedometer:')]
    print('\n'.join(lines))
    path = os.path.join(out, 'summary.json')
    if proc.returncode != 0 or not os.path.exists(path):
        print(proc.stdout[-3000:])
        checks.fail('the example did not complete (exit code %d)' % proc.returncode)
        return 1
    with open(path) as f:
        s = json.load(f)
    for name, key, lo, hi in thresholds:
        v = s[key]
        checks.check(name, math.isfinite(v) and lo <= v <= hi, '= %.4f (allowed %g .. %g)' % (v, lo, hi))
    for ok, message in extra_check(s) if extra_check else []:
        checks.check(message, ok)
    print('%d failed; outputs in %s' % (len(checks.failures), out))
    if not checks.failures:
        shutil.rmtree(out, ignore_errors=True)
    return 1 if checks.failures else 0
