"""The benchmark's quick mode runs and reports both engines (no timing is asserted).

Run inside YADE (exit code 0 = pass, 1 = fail):

    yade-double -n -x tests/yade/bench/test_bench_quick.py

It runs `yade-double -n -x bench/flow_benchmark.py --quick` (a few hundred spheres, one round, 1 thread, memory and
oedometer parts included) in a subprocess, writing its report and JSON to a temporary directory, and checks that:
  * the benchmark exits with 0;
  * the Markdown report holds the timing table with a row for the quick size and numbers for YADE and PFV;
  * the JSON summary has positive, finite remesh / flow-step / dry-step times for both engines, PFV's per-stage
    breakdown, a pressure comparison, peak-memory figures for dry / YADE / PFV and the oedometer ratios.
The pytest function at the bottom runs this file under yade-double (skipped without yade-double).
"""
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile

from pfv_testing import checks, paths


def _here():
    if 'yade' in sys.modules and sys.argv and sys.argv[0].endswith('.py'):
        return os.path.dirname(os.path.abspath(sys.argv[0]))
    return os.path.dirname(os.path.abspath(__file__))


HERE = _here()
BENCH = os.path.join(paths.BENCH, 'flow_benchmark.py')
QUICK_SIZE = 300  # the benchmark's quick size


def _positive(x):
    return isinstance(x, (int, float)) and math.isfinite(x) and x > 0


def _check_report(out):
    """The Markdown report: between its markers, a timing table with a row of times for both engines."""
    md = open(out).read() if os.path.exists(out) else ''
    checks.check('report written between markers', 'flow_benchmark output' in md)
    lines = md.splitlines()
    head = next((i for i, line in enumerate(lines) if 'remesh YADE' in line and 'remesh PFV' in line), None)
    checks.check('timing table has YADE and PFV columns', head is not None)
    rows = []
    if head is not None:
        for line in lines[head + 2 :]:
            if not line.startswith('|'):
                break
            rows.append(line)
    rows = [line for line in rows if line.startswith('| %d |' % QUICK_SIZE)]
    checks.check('timing table has a row for N=%d' % QUICK_SIZE, len(rows) >= 1)
    if rows:
        cells = [c.strip() for c in rows[0].strip('|').split('|')]
        checks.check(
            'row has times for both engines', sum(1 for c in cells if c.endswith(' ms') or c.endswith(' s')) >= 6
        )


def _check_timings(row):
    """The summary's times, cells, PFV breakdown and pressure comparison at the quick size."""
    for kind in ('yade', 'pfv'):
        e = row.get(kind, {})
        for what in ('remesh', 'flow', 'coupled', 'first'):
            checks.check('%s %s time positive and finite' % (kind, what), _positive(e.get(what)))
        checks.check('%s reports a number of cells' % kind, isinstance(e.get('cells'), int) and e['cells'] > 0)
    checks.check('dry step time positive and finite', _positive(row.get('dry')))
    br = row.get('pfv_breakdown', {})
    for stage in ('triangulation', 'geometry', 'factorization', 'force_cache'):
        checks.check('PFV remesh breakdown has %s' % stage, _positive(br.get('remesh', {}).get(stage)))
    for stage in ('solve', 'python + exchange'):
        checks.check('PFV steady breakdown has %s' % stage, stage in br.get('steady', {}))
    a = row.get('agreement', {})
    checks.check('pressure comparison computed', isinstance(a.get('max_dp'), float) and math.isfinite(a['max_dp']))
    print('  (info) probe pressures: max |dp|/dp = %s, Qin rel. diff = %s' % (a.get('max_dp'), a.get('flux_in_rel')))


def _check_json(js):
    """The raw data: timings, memory and the oedometer."""
    data = json.load(open(js)) if os.path.exists(js) else {}
    summ = data.get('summary', {})
    t = next(iter(summ.values()), {})
    _check_timings(t.get('sizes', {}).get(str(QUICK_SIZE), {}))
    mem = data.get('memory', {}).get(str(QUICK_SIZE), {})
    for kind in ('dry', 'yade', 'pfv'):
        m = mem.get(kind, {})
        checks.check('memory figures for %s' % kind, _positive(m.get('peak_kb')) and _positive(m.get('rss_before_kb')))
    oe = next(iter(t.get('oedometer', {}).values()), {})
    for kind in ('yade', 'pfv'):
        checks.check('oedometer coupled/dry ratio for %s' % kind, _positive(oe.get(kind, {}).get('ratio')))


def main():
    exe = shutil.which('yade-double') or 'yade-double'
    with tempfile.TemporaryDirectory(prefix='pfv-bench-quick-') as d:
        out, js = os.path.join(d, 'bench.md'), os.path.join(d, 'bench.json')
        cmd = [exe, '-n', '-x', BENCH, '--quick', '--out=' + out, '--json=' + js]
        print('running:', ' '.join(cmd), flush=True)
        r = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
        print('\n'.join(line for line in r.stdout.splitlines() if line.startswith(('bench:', '  [')))[-4000:])
        checks.check('benchmark exit code 0 (got %d)' % r.returncode, r.returncode == 0)
        if r.returncode != 0:
            print(r.stdout[-4000:], r.stderr[-2000:])
            return
        _check_report(out)
        _check_json(js)


def test_bench_quick():
    """pytest entry: runs this file under yade-double."""
    import pytest

    exe = shutil.which('yade-double')
    if exe is None:
        pytest.skip('yade-double not installed')
    r = subprocess.run(
        [exe, '-n', '-x', os.path.join(HERE, 'test_bench_quick.py')], capture_output=True, text=True, timeout=900
    )
    print(r.stdout[-6000:])
    assert r.returncode == 0, 'yade-double exited with %d\n%s\n%s' % (r.returncode, r.stdout[-4000:], r.stderr[-2000:])


if __name__ == '__main__' and 'yade' in sys.modules:
    main()
    checks.report('bench quick')
elif __name__ == '__main__':
    print('run me with: yade-double -n -x %s' % sys.argv[0])
    sys.exit(2)
