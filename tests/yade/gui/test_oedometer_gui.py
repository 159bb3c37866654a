"""examples/oedometer.py with YADE's GUI, under a virtual X server (xvfb-run), non-interactive.

    yade-double -n -x tests/yade/gui/test_oedometer_gui.py        (exit 0 = pass, 1 = fail, 77 = skipped: no xvfb-run)

Runs tests/pfv_testing/gui_oedometer_driver.py (which runs the example) with `xvfb-run -a yade-double -j1 -x` on the
quick sample up to T_v = 0.2 (-x: YADE leaves after the script instead of opening its IPython prompt; stdin is /dev/null
as well), then the same run headless, and checks:
* the run completes (exit 0, within a timeout) in GUI mode (YADE saw a display), with no Python traceback printed
  (a redraw of the live plot racing with its set-up once raised there, and a redraw killed at exit aborted YADE);
* YADE's controller, its 3D view and the example's live matplotlib figure were on screen while the coupled phase ran;
* the GUI stayed live during the run (the example steps in YADE's background thread and keeps processing Qt events):
  the driver's half-second timer fired while the iterations advanced and the live plot gained points;
* the GUI run gives exactly the numbers of the headless run (same steps).
A screenshot of the last second of the run is left in the output directory when a check fails.
"""
import json
import os
import shutil
import subprocess
import tempfile

from pfv_testing import checks, paths

DRIVER = paths.tool('gui_oedometer_driver.py')
EXAMPLE = paths.example('oedometer.py')
ARGS = ['--quick', '--set=Tv_end=0.2']
KEYS = ('K', 'Cv', 'steps', 'final_U', 'U_max_abs_error', 'isochrone_rms_error', 'mid_pressure_rms_error')


def main():
    xvfb = shutil.which('xvfb-run')
    if not xvfb:
        checks.skip('xvfb-run not found (apt-get install xvfb xauth)')
    yade = shutil.which('yade-double') or '/usr/bin/yade-double'
    out = tempfile.mkdtemp(prefix='pfv-oedometer-gui-')
    env = dict(os.environ)
    env.pop('DISPLAY', None)
    cmd = [xvfb, '-a', '-s', '-screen 0 1600x1200x24', yade, '-j1', '-x', DRIVER, os.path.join(out, 'gui')] + ARGS
    print('running: ' + ' '.join(cmd), flush=True)
    try:
        proc = subprocess.run(
            cmd,
            stdin=subprocess.DEVNULL,
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
            env=env,
            timeout=600,
        )
        code, text = proc.returncode, proc.stdout
    except subprocess.TimeoutExpired as e:
        code, text = 'timeout', (
            (e.stdout or b'').decode(errors='replace') if isinstance(e.stdout, bytes) else (e.stdout or '')
        )
    print('\n'.join(line for line in text.splitlines() if line.startswith(('oedometer:', 'gui driver:'))))
    checks.check('GUI run completed (exit %s)' % code, code == 0)
    checks.check('no Python traceback in the GUI run (live plot, Qt callbacks)', 'Traceback' not in text)
    gui_json = os.path.join(out, 'gui', 'gui.json')
    summary_path = os.path.join(out, 'gui', 'run', 'summary.json')
    if code != 0 or not os.path.exists(gui_json) or not os.path.exists(summary_path):
        print(text[-3000:])
        checks.fail('the GUI run wrote gui.json and summary.json; outputs in %s' % out)
        return
    with open(gui_json) as f:
        g = json.load(f)
    checks.check(
        'the example ran in GUI mode (status %s, display %s)' % (g['status'], g['hasDisplay']),
        g['status'] == 'ok' and g['hasDisplay'],
    )
    running = [t for t in g['ticks'] if t['running']]
    seen = set(w.split(':')[0] for t in running for w in t['windows'])
    checks.check(
        "controller, 3D view and live figure on screen during the run (%s)" % sorted(seen),
        {'ControllerClass', 'QOpenGLWidget', 'MainWindow'} <= seen
        and max((t['views'] for t in running), default=0) >= 1,
    )
    iters = [t['iter'] for t in running]
    points = [t['points'] for t in running]
    checks.check(
        'GUI live during the run: %d half-second ticks while running, iterations %s .. %s, plot points %s .. %s'
        % (
            len(running),
            iters[0] if iters else '-',
            iters[-1] if iters else '-',
            points[0] if points else '-',
            points[-1] if points else '-',
        ),
        len(running) >= 3 and iters[-1] > iters[0] and points[-1] > points[0],
    )
    checks.check('screenshot taken', os.path.exists(os.path.join(out, 'gui', 'screen.png')))

    head = os.path.join(out, 'headless')
    proc = subprocess.run(
        [yade, '-j1', '-n', '-x', EXAMPLE, '--out=' + head] + ARGS,
        stdin=subprocess.DEVNULL,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        timeout=600,
    )
    checks.check('headless run completed (exit %d)' % proc.returncode, proc.returncode == 0)
    if proc.returncode == 0:
        with open(summary_path) as f:
            a = json.load(f)
        with open(os.path.join(head, 'summary.json')) as f:
            b = json.load(f)
        diff = [k for k in KEYS if a[k] != b[k]]
        checks.check(
            'GUI and headless runs give the same results (%s; differ: %s)'
            % (', '.join('%s %.6g' % (k, a[k]) for k in KEYS), diff or 'none'),
            not diff,
        )
    print('outputs in %s' % out)
    if not checks.failures:
        shutil.rmtree(out, ignore_errors=True)


main()
checks.report('GUI oedometer')
