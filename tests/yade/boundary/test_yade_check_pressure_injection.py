"""YADE's own check checkDEM-PFVPressureInjection.py, run from YADE's install location with
pfv.FlowEngine bound to the name FlowEngine (the only change), then its imbibition loop.

The script compacts 1000 spheres, drives water in through ymin (1000 Pa) into a sample whose cells
above a third of its height are imposed at p = 0 (dry), and appends PyRunners that follow the water:
each cell's absorbed volume is summed from getCellFluxFromId, a cell whose void volume
(1 / getCellInvVoidVolume) has filled is freed with setCellPImposed(id, False), and `fluxtest`
raises YadeCheckError when the water that came in through ymin exceeds the water the dry cells took
in by more than 1e-6, and `equilibriumtest` raises when, 1.5 s after the start, the fluid and contact
forces on the ymin and ymax walls differ by more than 1 % of the injection pressure. After the
script, this test runs the loop for --steps steps (1500: past those 1.5 s) and checks the volume
balance both ways, that the force check ran, that water came in, and that cells filled and were
freed.

The script's saveVtk calls write into a temporary directory.

    yade-double -n -x tests/yade/boundary/test_yade_check_pressure_injection.py [--steps=N]   (exit 0 = pass)
"""
import os
import sys
import tempfile
import time
import traceback

import __main__
import yade
from yade import O

import pfv
from pfv_testing import checks

SCRIPT = os.path.join(yade.config.libDir, "py/yade/tests/checks/checkDEM-PFVPressureInjection.py")
VOLUME_TOLERANCE = 1e-6  # the script's own toleranceCritical


class YadeCheckError(Exception):
    pass


def main(argv):
    steps = 1500
    for a in argv:
        if a.startswith("--steps="):
            steps = int(a.split("=", 1)[1])
    if not os.path.exists(SCRIPT):
        checks.skip(f"{SCRIPT} not found")
    os.chdir(tempfile.mkdtemp(prefix="pfv-injection-"))  # the script writes ./vtk and Test.txt
    ns = vars(__main__)  # its PyRunner commands are evaluated in __main__
    ns.update(checksPath=os.path.dirname(SCRIPT), YadeCheckError=YadeCheckError, FlowEngine=pfv.FlowEngine)
    from yade import plot

    plot.plot = lambda *a, **k: None  # no GUI
    source = open(SCRIPT).read()
    if "FlowEngine(" not in source:
        checks.fail("the script no longer creates a FlowEngine")
        return
    t0 = time.time()
    try:
        exec(compile(source, SCRIPT, "exec"), ns)
    except Exception:
        traceback.print_exc()
        checks.fail(f"the script raised after {time.time() - t0:.0f} s")
        return
    engines = [e for e in O.engines if isinstance(e, pfv.FlowEngine)]
    if len(engines) != 1:
        checks.fail(f"the script's engines hold {len(engines)} pfv.FlowEngine")
        return
    flow = engines[0]
    nvoids, bar, level = ns["nvoids"], ns["bar"], ns["initiallevel"]
    dry = [ii for ii in range(nvoids) if bar[ii] >= level]
    print(
        f"script done in {time.time() - t0:.0f} s: O.iter {O.iter}, {nvoids} cells, {len(dry)} dry, " f"O.dt {O.dt:.4g}"
    )
    t0 = time.time()
    try:
        O.run(steps, True)
    except Exception:
        traceback.print_exc()
        checks.fail(f"the imbibition loop raised after {time.time() - t0:.0f} s (O.iter {O.iter})")
        return
    q_in = -ns["Qin"] - ns["deltabubble"]
    total = ns["total"]
    still_dry = sum(1 for ii in dry if flow.getCellPImposed(ii))
    print(
        f"{steps} loop steps in {time.time() - t0:.0f} s: water in through ymin {q_in:.6g}, taken in by the "
        f"dry cells {total:.6g}, difference {q_in - total:.3g}; {len(dry) - still_dry} of {len(dry)} dry cells "
        f"filled and freed, {ns['bubble']} bubbles"
    )
    rows = [
        (
            "inflow balances the water taken in by the dry cells (|difference| <= 1e-6)",
            abs(q_in - total) <= VOLUME_TOLERANCE,
        ),
        ("water came in through ymin", q_in > 0),
        ("the wall-force balance was checked (1.5 s reached)", steps < 1500 or ns["checkdifference"] == 1),
        ("dry cells filled and were freed", 0 < len(dry) - still_dry < len(dry)),
        (
            "every freed cell had taken in its void volume",
            all(
                -ns["totalflux"][ii] >= ns["initialvol"][ii] * (1 - 1e-12) for ii in dry if not flow.getCellPImposed(ii)
            ),
        ),
    ]
    for name, ok in rows:
        checks.check(name, ok)


main(sys.argv[1:])
checks.report("pressure injection")
