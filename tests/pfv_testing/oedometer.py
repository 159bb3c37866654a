"""Shared by the oedometer tests: run examples/oedometer.py headless and check its summary.json against bounds."""
import json
import math
import os
import shutil
import subprocess
import tempfile

from pfv_testing import paths

EXAMPLE = paths.example('oedometer.py')


def run_and_check(args, thresholds, extra_check=None):
    """thresholds: (name, summary key, lower, upper); extra_check(summary) -> list of (ok, message).
    Returns the process exit code (0 = pass)."""
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
        print('FAIL the example did not complete (exit code %d)' % proc.returncode)
        return 1
    with open(path) as f:
        s = json.load(f)
    failures = 0
    for name, key, lo, hi in thresholds:
        v = s[key]
        ok = math.isfinite(v) and lo <= v <= hi
        failures += not ok
        print('%s %s = %.4f (allowed %g .. %g)' % ('ok  ' if ok else 'FAIL', name, v, lo, hi))
    for ok, message in extra_check(s) if extra_check else []:
        failures += not ok
        print('%s %s' % ('ok  ' if ok else 'FAIL', message))
    print('%d failed; outputs in %s' % (failures, out))
    if not failures:
        shutil.rmtree(out, ignore_errors=True)
    return 1 if failures else 0
