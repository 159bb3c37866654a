# Run one of YADE's own FlowEngine client scripts unchanged, with YADE's built-in FlowEngine
# or with pfv.FlowEngine substituted for it.
#
#   yade-double -n -x tests/pfv_testing/run_yade_script.py SCRIPT [--pfv [--thesis-wall-throats]]
#
# SCRIPT is a path, or one of the shortcuts
#   check       -> <yade libDir>/py/yade/tests/checks/DEM-PFV-check.py
#   oedometer   -> /usr/share/doc/yade/examples/FluidCouplingPFV/oedometer.py
# The script is exec'd in __main__'s own namespace (PyRunner commands such as 'history()' are evaluated there,
# so a copy would not do); `O`, `FlowEngine`, `aabbWalls`, ... are there already;
# `checksPath` and `YadeCheckError` are defined as `yade --check` does.  With --pfv the name `FlowEngine`
# in that namespace is bound to pfv.FlowEngine (with --thesis-wall-throats, to pfv.FlowEngine with
# yade_wall_throat_factor=False: the thesis' slip-wall formula without YADE's multiplier).  GUI plotting calls are
# made harmless.
# Exit code: 0 if the script ran to the end, 1 on any exception (including YadeCheckError) or if pfv is missing.
import os
import sys
import time
import traceback

import yade
from yade import O  # the same Omega as the `O` already in __main__'s namespace
import __main__

SHORTCUTS = {
    'check': os.path.join(yade.config.libDir, 'py/yade/tests/checks/DEM-PFV-check.py'),
    'oedometer': '/usr/share/doc/yade/examples/FluidCouplingPFV/oedometer.py',
}


class YadeCheckError(Exception):
    pass


def main(argv):
    args = [a for a in argv if not a.startswith('--')]
    usePfv = '--pfv' in argv
    if not args:
        print('usage: yade-double -n -x run_yade_script.py SCRIPT|check|oedometer [--pfv]')
        return 2
    path = SHORTCUTS.get(args[0], args[0])
    ns = vars(__main__)  # PyRunner commands run in __main__'s namespace: exec the script right there
    ns.update(checksPath=os.path.dirname(path), YadeCheckError=YadeCheckError)
    if usePfv:
        try:
            import pfv
        except Exception as e:
            print('PFV_IMPORT_FAILED: cannot import pfv (%s: %s)' % (type(e).__name__, e))
            return 1
        ns['FlowEngine'] = pfv.FlowEngine
        if '--thesis-wall-throats' in argv:
            import functools

            ns['FlowEngine'] = functools.partial(pfv.FlowEngine, yade_wall_throat_factor=False)
    try:  # no GUI: plot.plot() would try to open a window
        from yade import plot

        plot.plot = lambda *a, **k: None
    except Exception:
        pass
    print('running %s with %s' % (path, 'pfv.FlowEngine' if usePfv else "YADE's built-in FlowEngine"))
    t0 = time.time()
    try:
        exec(compile(open(path).read(), path, 'exec'), ns)
    except SystemExit as e:
        print('script called sys.exit(%r) after %.1f s' % (e.code, time.time() - t0))
        return int(e.code or 0)
    except Exception:
        traceback.print_exc()
        print('FAILED after %.1f s' % (time.time() - t0))
        return 1
    print('OK: %s finished in %.1f s (O.iter=%d)' % (os.path.basename(path), time.time() - t0, O.iter))
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
