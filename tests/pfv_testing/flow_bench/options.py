"""The command line of bench/flow_benchmark.py (see its docstring)."""
import os

from pfv_testing.paths import REPO


# Flags without a value: the option each sets and to what (--quick and --startup are read first).
FLAGS = {
    '--quick': ('quick', True),
    '--startup': ('startup', True),
    '--report-only': ('report_only', True),
    '--no-memory': ('memory', False),
    '--no-oedometer': ('oedometer', False),
    '--no-multithread': ('multithread', False),
    '--no-double': ('double', False),
}
LISTS = ('sizes', 'threads', 'oedo_sizes')
INTEGERS = ('rounds', 'oedo_steps', 'oedo_interval', 'steady', 'size', 'gen_threads')
STRINGS = ('out', 'json', 'child', 'engine', 'child_json')


def _apply(opts, a):
    """Sets the option of one command-line argument."""
    if a in FLAGS:
        key, value = FLAGS[a]
        opts[key] = value
        return
    if not a.startswith('--') or '=' not in a:
        raise SystemExit('flow_benchmark: unknown argument %r (see the docstring)' % a)
    k, v = a[2:].split('=', 1)
    k = k.replace('-', '_')
    if k in LISTS:
        opts[k] = [int(x) for x in v.split(',') if x]
    elif k in INTEGERS:
        opts[k] = int(v)
    elif k in STRINGS:
        opts[k] = v
    else:
        raise SystemExit('flow_benchmark: unknown option --%s' % k)


def parse_args(argv):
    quick = '--quick' in argv
    startup = '--startup' in argv
    opts = dict(
        quick=quick,
        startup=startup,
        sizes=[300] if quick else [10000, 50000] if startup else [1000, 10000, 50000],
        rounds=1 if quick else 3,
        threads=[1] if quick or startup else [1, 2],
        out=None,
        json=None,
        memory=True,
        oedometer=True,
        multithread=True,
        double=True,
        oedo_sizes=None,
        oedo_steps=60 if quick else 600,
        oedo_interval=20 if quick else 200,
        steady=10 if quick else 5 if startup else 20,
        child=None,
        size=None,
        engine=None,
        child_json=None,
        gen_threads=None,
        report_only=False,
    )
    for a in argv:
        _apply(opts, a)
    if opts['oedo_sizes'] is None:
        opts['oedo_sizes'] = [n for n in opts['sizes'] if n <= 10000] or [min(opts['sizes'])]
    if opts['out'] is None:
        opts['out'] = '/tmp/bench/benchmarks-quick.md' if quick else os.path.join(REPO, 'doc', 'benchmarks.md')
    if opts['json'] is None:
        opts['json'] = '/tmp/bench/flow_benchmark%s.json' % ('-quick' if quick else '-startup' if startup else '')
    return opts
