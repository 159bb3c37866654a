"""Side-by-side benchmark of YADE's FlowEngine and PFV's FlowEngine.

Run with YADE from the repository root with PYTHONPATH=build/python (the parts of this benchmark are in
pfv_testing.flow_bench; the driver re-invokes yade-double on this file for every measurement):

    yade-double -n -x bench/flow_benchmark.py [--quick] [--sizes=1000,10000,50000] [--rounds=3]
                [--threads=1,2] [--out=doc/benchmarks.md] [--json=FILE] [--no-memory] [--no-oedometer]
                [--no-multithread] [--no-double] [--oedo-sizes=1000,10000] [--oedo-steps=600] [--oedo-interval=200]
                [--steady=20]
                [--gen-threads=T]    (threads of the child that generates a missing packing; default max of --threads)
    yade-double -n -x bench/flow_benchmark.py --report-only --json=FILE [--out=doc/benchmarks.md]
    yade-double -n -x bench/flow_benchmark.py --startup --report-only --json=FILE [--out=doc/benchmarks.md]
                (the report of an earlier full run from its JSON, for a change of the report's layout)
    yade-double -n -x bench/flow_benchmark.py --startup [--sizes=10000,50000] [--rounds=3] [--threads=1]
                [--steady=5] [--out=doc/benchmarks.md]

--startup: only the start-up of the engines (issue 19 item 1): YADE and PFV trials (as in 2. below, 5 steady steps
unless --steady is given, the order swapped every round) at --sizes (default 10000,50000) and -j1; reports the
first-step/remesh ratio of PFV (target <= 1.2), PFV/YADE first step (target <= 0.5) and where PFV's first step spends
the time it does not spend in a remesh (ordering, factorisation, the cold collective viscous limit, Python), into its
own markers in --out (the full report's section is left alone), JSON in /tmp/bench/flow_benchmark-startup.json.

--quick: 300 spheres, 1 round, -j1, 10 steady steps, oedometer 60 steps with a remesh every 20, report written to
/tmp/bench/benchmarks-quick.md unless --out is given (tests/yade/bench/test_bench_quick.py runs it).

What it does
  1. Packings: dense packings of N spheres (N in --sizes) in a cube of side (N/1000)^(1/3) (so the sphere size does not
     depend on N), made once by radius growth under a TriaxialStressController (makeCloud at porosity 0.7, growth to a
     mean stress of 10 kPa with E = 1 MPa, 3 deg friction, damping 0.5) and cached as text in
     $PFV_CACHE_DIR or ~/.cache/pfv (bench_packing_v1_n<N>_s1.txt).  Every scene below is built from that file.
  2. Timing (one yade process per thread count, `yade-double -jT`): for each N the permeameter scene (the packing,
     six fixed walls, spheres *dynamic* (no blocked DOFs), friction 30 deg, no gravity, pressure drop 100 Pa along y =
     1 % of the confining stress, viscosity 1e-3, O.dt = 0.5 P-wave step, slipBoundary=False in both engines) is
     settled (damping 0.5 until the unbalanced force is < 0.01: the file has no contact history), saved once with
     O.saveTmp, and every trial starts from it.  Trials are interleaved YADE / PFV / dry / PFV-double (PFV with
     mixed_precision=False, the direct double solve the default is refined towards; not with --no-double), rotating
     the order every round.  A trial runs
     W=3 first steps, S steady steps, a forced remesh (updateTriangulation=True) followed by W steps, and 3 more steps,
     timing every O.step() (wall clock) and the engine's execTime (O.timingEnabled).  Both engines use CHOLMOD
     (useSolver=3), meshUpdateInterval=1e9, defTolerance=0, everything else at its default.
  3. Memory (one fresh `yade-double -j1` per engine and N): VmRSS before the engine is added, peak (VmHWM after
     resetting it through /proc/self/clear_refs) and VmRSS after a first step, S steady steps and a forced remesh.
  4. Oedometer (coupled/dry cost ratio): the packing with the top wall under a TriaxialStressController (stressMask=2,
     load step 10 -> 11 kPa), drained top, impermeable other walls, viscosity 10, meshUpdateInterval=200,
     defTolerance=0.3, O.dt=1e-4 (as in YADE's examples/FluidCouplingPFV/oedometer.py), O.run(M) timed for YADE,
     PFV and dry, interleaved like the trials; and (unless --no-multithread) both engines again with
     multithread=True, the remesh built in a background thread while the DEM runs (PFV's background_remesh).
  Children run with OPENBLAS_NUM_THREADS = OMP_NUM_THREADS = T (Debian's OpenBLAS would use every core otherwise).

Definitions (medians over rounds of per-trial medians)
  flow step   : engine execTime of a steady step (no remesh)
  remesh      : engine execTime summed over the W steps from the forced remesh minus (W-1) flow steps, i.e. one flow
                step with remesh (triangulation, geometry, assembly, ordering, factorisation, first solve, forces).
                YADE remeshes at the end of the step and factorises in the next one: the window covers both.
  coupled     : wall clock of O.step() in a steady step with the engine;  dry: the same without flow engine.

Output: a Markdown report (between markers in --out, text outside the markers is kept), the same tables on stdout, and
the raw per-trial data as JSON (--json, default /tmp/bench/flow_benchmark.json).  No timing is asserted anywhere.
"""
import datetime
import json
import os
import shutil
import subprocess
import sys
import time
import traceback

from pfv_testing import paths
from pfv_testing.flow_bench.machine import machine_description, pfv_fingerprint
from pfv_testing.flow_bench.options import parse_args
from pfv_testing.flow_bench.report import (
    REPORT_VERSION,
    STARTUP_BEGIN_MARK,
    STARTUP_END_MARK,
    report,
    startup_report,
    write_report,
)
from pfv_testing.flow_bench.scene import generate_packing, log, packing_digest, packing_path, read_packing
from pfv_testing.flow_bench.summary import startup_summary, summarise
from pfv_testing.flow_bench.trials import memory_child, startup_child, timing_child

SCRIPT = os.path.join(paths.BENCH, 'flow_benchmark.py')
REPO = paths.REPO


def run_child(args, threads, label):
    exe = shutil.which('yade-double') or 'yade-double'
    os.makedirs('/tmp/bench', exist_ok=True)
    path = '/tmp/bench/child-%d-%s.json' % (os.getpid(), label)
    if os.path.exists(path):
        os.remove(path)
    cmd = [exe, '-j%d' % threads, '-n', '-x', SCRIPT] + args + ['--child-json=%s' % path]
    t0 = time.time()
    # CHOLMOD's supernodal factorisation calls BLAS; Debian's OpenBLAS (pthread build) would otherwise use every
    # core whatever yade's -jN: pin it to the thread count being measured, for both engines alike.
    env = dict(os.environ, OPENBLAS_NUM_THREADS=str(threads), OMP_NUM_THREADS=str(threads))
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, cwd=REPO, env=env)
    tail = []
    for line in proc.stdout:
        line = line.rstrip('\n')
        tail = (tail + [line])[-60:]
        if line.startswith('bench:') or 'Error' in line or 'Traceback' in line:
            print('  [%s] %s' % (label, line), flush=True)
    rc = proc.wait()
    if rc != 0 or not os.path.exists(path):
        raise RuntimeError('child %s failed (exit %d): %s\n%s' % (label, rc, ' '.join(cmd), '\n'.join(tail)))
    with open(path) as f:
        data = json.load(f)
    os.remove(path)
    log('%s finished in %.0f s' % (label, time.time() - t0))
    return data


def startup_driver(opts, argv):
    command = 'yade-double -n -x bench/flow_benchmark.py ' + ' '.join(argv)
    machine = machine_description()
    for n in opts['sizes']:
        if not os.path.exists(packing_path(n)):
            log('generating packing n=%d into %s (once; cached)' % (n, packing_path(n)))
            run_child(['--child=generate', '--size=%d' % n], opts['gen_threads'] or 1, 'generate-%d' % n)
    child_opts = [
        '--startup',
        '--sizes=' + ','.join(map(str, opts['sizes'])),
        '--rounds=%d' % opts['rounds'],
        '--steady=%d' % opts['steady'],
    ]
    texts, raw = [], {}
    for t in opts['threads']:
        data = run_child(['--child=startup'] + child_opts, t, 'startup-j%d' % t)
        raw[str(t)] = data
        machine['load average at end'] = ' '.join('%.2f' % x for x in os.getloadavg())
        rows = startup_summary(data)
        texts.append(startup_report(opts, machine, rows, command, t))
    text = '\n\n'.join(texts)
    print('\n' + text + '\n', flush=True)
    write_report(opts['out'], text, STARTUP_BEGIN_MARK, STARTUP_END_MARK)
    os.makedirs(os.path.dirname(os.path.abspath(opts['json'])), exist_ok=True)
    with open(opts['json'], 'w') as f:
        json.dump(dict(version=REPORT_VERSION, command=command, machine=machine, timing=raw), f, indent=1, default=str)
    log('report written to %s, raw data to %s' % (opts['out'], opts['json']))
    return 0


def driver(opts, argv):
    started = datetime.datetime.now().strftime('%Y-%m-%d %H:%M')
    command = 'yade-double -n -x bench/flow_benchmark.py' + ('' if not argv else ' ' + ' '.join(argv))
    machine = machine_description()
    log(
        'machine: %s, %s CPUs, %s; load %s'
        % (machine.get('Model name'), machine.get('CPU(s)'), machine.get('RAM'), machine['load average at start'])
    )
    need = sorted(set(opts['sizes']) | (set(opts['oedo_sizes']) if opts['oedometer'] else set()))
    gen_threads = opts['gen_threads'] or max(opts['threads'] + [1])
    packings = {}
    for n in need:
        if not os.path.exists(packing_path(n)):
            log('generating packing n=%d into %s (once; cached)' % (n, packing_path(n)))
            run_child(['--child=generate', '--size=%d' % n], gen_threads, 'generate-%d' % n)
        spheres, meta = read_packing(n)
        meta['digest'] = packing_digest(spheres)
        packings[n] = meta
        log('packing n=%d: %s, porosity %.4f, digest %s' % (n, packing_path(n), meta['porosity'], meta['digest']))
    child_opts = [
        '--sizes=' + ','.join(map(str, opts['sizes'])),
        '--rounds=%d' % opts['rounds'],
        '--steady=%d' % opts['steady'],
        '--oedo-sizes=' + ','.join(map(str, opts['oedo_sizes'])),
        '--oedo-steps=%d' % opts['oedo_steps'],
        '--oedo-interval=%d' % opts['oedo_interval'],
    ]
    if not opts['oedometer']:
        child_opts.append('--no-oedometer')
    if not opts['multithread']:
        child_opts.append('--no-multithread')
    if not opts['double']:
        child_opts.append('--no-double')
    if opts['quick']:
        child_opts.append('--quick')
    timing = {}
    for t in opts['threads']:
        timing[str(t)] = run_child(['--child=timing'] + child_opts, t, 'timing-j%d' % t)
    memory = []
    if opts['memory']:
        for n in opts['sizes']:
            for kind in ('dry', 'yade', 'pfv'):
                memory.append(
                    run_child(
                        ['--child=memory', '--size=%d' % n, '--engine=' + kind, '--steady=%d' % opts['steady']]
                        + (['--quick'] if opts['quick'] else []),
                        1,
                        'memory-%s-%d' % (kind, n),
                    )
                )
    finished = datetime.datetime.now().strftime('%Y-%m-%d %H:%M')
    builds = sorted(set(d.get('pfv_build') for d in list(timing.values()) + memory if d.get('pfv_build')))
    machine['pfv extension'] = ' | '.join(builds) + (
        ' -- WARNING: the children used different pfv builds ' '(pfv was reinstalled during the run)'
        if len(builds) > 1
        else ''
    )
    if len(builds) > 1:
        log('WARNING: pfv was reinstalled during the run: %s' % builds)
    machine['load average at end'] = ' '.join('%.2f' % x for x in os.getloadavg())
    summ, mem = summarise(timing, memory)
    text = report(opts, machine, {n: packings[n] for n in opts['sizes']}, summ, mem, command)
    print('\n' + text + '\n', flush=True)
    write_report(opts['out'], text)
    os.makedirs(os.path.dirname(os.path.abspath(opts['json'])), exist_ok=True)
    with open(opts['json'], 'w') as f:
        json.dump(
            dict(
                version=REPORT_VERSION,
                command=command,
                started=started,
                finished=finished,
                machine=machine,
                packings={str(k): v for k, v in packings.items()},
                summary=summ,
                memory=mem,
                timing=timing,
                memory_raw=memory,
            ),
            f,
            indent=1,
            default=str,
        )
    log('report written to %s, raw data to %s' % (opts['out'], opts['json']))
    return 0


def report_only(opts):
    """The report of an earlier full run, from its JSON (--json), written to --out: for a change of the report's
    layout, without measuring again. The run's own options come from the command stored in the JSON."""
    with open(opts['json']) as f:
        data = json.load(f)
    if data.get('version') != REPORT_VERSION:
        raise SystemExit(
            'flow_benchmark: %s has layout version %s, this script writes %s'
            % (opts['json'], data.get('version'), REPORT_VERSION)
        )
    run = parse_args(data['command'].split()[4:])
    packings = {int(n): m for n, m in data['packings'].items() if int(n) in run['sizes']}
    summ, mem = summarise(data['timing'], data['memory_raw'])
    text = report(run, data['machine'], packings, summ, mem, data['command'])
    write_report(opts['out'], text)
    log('report of %s written to %s' % (opts['json'], opts['out']))
    return 0


def startup_report_only(opts):
    """The start-up report of an earlier --startup run, from its JSON (--json), written to --out. The load average
    at the end of each thread count's child is the one the child recorded."""
    with open(opts['json']) as f:
        data = json.load(f)
    run = parse_args(data['command'].split()[4:])
    machine, texts = data['machine'], []
    for t, child in sorted(data['timing'].items(), key=lambda kv: int(kv[0])):
        machine['load average at end'] = ' '.join('%.2f' % x for x in child['load_end'])
        texts.append(startup_report(run, machine, startup_summary(child), data['command'], int(t)))
    write_report(opts['out'], '\n\n'.join(texts), STARTUP_BEGIN_MARK, STARTUP_END_MARK)
    log('start-up report of %s written to %s' % (opts['json'], opts['out']))
    return 0


def main(argv):
    opts = parse_args(argv)
    child = opts['child']
    if opts['report_only']:
        return startup_report_only(opts) if opts['startup'] else report_only(opts)
    if child is None:
        return startup_driver(opts, argv) if opts['startup'] else driver(opts, argv)
    try:
        if child == 'generate':
            data = generate_packing(opts['size'])
        elif child == 'timing':
            data = timing_child(opts)
        elif child == 'startup':
            data = startup_child(opts)
        elif child == 'memory':
            data = memory_child(opts)
        else:
            raise SystemExit('unknown --child=%s' % child)
    except Exception:
        traceback.print_exc()
        sys.stdout.flush()
        return 1
    data['pfv_build'] = pfv_fingerprint()
    with open(opts['child_json'], 'w') as f:
        json.dump(data, f, default=str)
    return 0


if __name__ == '__main__' and 'yade' in sys.modules:
    sys.exit(main(sys.argv[1:]))
elif __name__ == '__main__':
    print('run me with: yade-double -n -x %s [--quick] ...' % sys.argv[0])
    sys.exit(2)
