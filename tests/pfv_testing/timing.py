"""Timing helpers of the benchmarks: wall time of a call, medians that ignore missing values."""
import statistics
import time


def wall(action):
    """Seconds of wall time of action()."""
    t0 = time.perf_counter()
    action()
    return time.perf_counter() - t0


def per_call_ms(action, repeats=20):
    """Milliseconds per call of action(), after one untimed call (caches, first-touch)."""
    action()
    t0 = time.perf_counter()
    for _ in range(repeats):
        action()
    return (time.perf_counter() - t0) / repeats * 1e3


def median(xs):
    """Median of the values that are not None nor NaN; NaN if none is left."""
    xs = [x for x in xs if x is not None and x == x]
    return statistics.median(xs) if xs else float('nan')


def yade_step():
    """Seconds of wall time of one O.step()."""
    from yade import O

    return wall(O.step)
