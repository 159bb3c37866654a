"""Runs examples/oedometer.py in YADE's GUI mode and records what is on screen (driven by test_oedometer_gui.py).

    xvfb-run -a -s "-screen 0 1600x1000x24" yade-double -j1 -x tests/pfv_testing/gui_oedometer_driver.py \
        OUTDIR [example args]

Every half second, while the example runs, a Qt timer lists the visible top-level windows, the iteration reached and the
number of points of the live plot, tiles the windows (Xvfb has no window manager: all would open at (0, 0)) and
saves a screenshot of the whole screen to OUTDIR/screen.png (the last one taken while the coupled phase ran).
At the end it writes OUTDIR/gui.json. The example itself writes OUTDIR/run/summary.json.
"""
import json
import os
import sys
import time

from PyQt5.QtCore import QTimer
from PyQt5.QtWidgets import QApplication
from pfv_testing import paths
from yade import O, runtime

EXAMPLE = paths.example('oedometer.py')
out = sys.argv[1]
os.makedirs(out, exist_ok=True)
ticks = []


def tick():
    app = QApplication.instance()
    windows = [w for w in app.topLevelWidgets() if w.isVisible()]
    x, y, row = 0, 0, 0
    for w in sorted(windows, key=lambda w: w.width() * w.height()):  # tile left to right, wrap
        if x + w.width() > 1600:
            x, y, row = 0, y + row, 0
        w.move(x, y)
        x, row = x + w.width(), max(row, w.height())
    try:
        from yade import plot, qt

        points = len(plot.data.get('Tv', []))
        views = len(qt.views())
    except Exception:  # noqa: BLE001
        points, views = -1, -1
    ticks.append(
        dict(
            t=time.time(),
            iter=O.iter,
            running=bool(O.running),
            points=points,
            views=views,
            windows=sorted('%s:%s' % (type(w).__name__, w.windowTitle()) for w in windows),
        )
    )
    if O.running and points > 0:
        app.primaryScreen().grabWindow(0).save(os.path.join(out, 'screen.png'))


timer = QTimer()
timer.timeout.connect(tick)
timer.start(500)
sys.argv = [EXAMPLE, '--out=' + os.path.join(out, 'run')] + sys.argv[2:]
status = 'ok'
try:
    exec(compile(open(EXAMPLE).read(), EXAMPLE, 'exec'), {'__name__': 'oedometer_gui'})
except SystemExit as e:  # the example only exits by itself when headless
    status = 'exited headless (%s)' % e.code
except Exception as e:  # noqa: BLE001
    status = 'error: %r' % e
timer.stop()
with open(os.path.join(out, 'gui.json'), 'w') as f:
    json.dump(dict(status=status, hasDisplay=bool(runtime.hasDisplay), ticks=ticks), f, indent=1)
print('gui driver: %s, %d ticks' % (status, len(ticks)), flush=True)
