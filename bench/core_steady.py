"""The steady step of the C++ engine alone (pfv.Engine, no YADE) on bench/growth.py's jittered lattice.

    /usr/bin/python3 bench/core_steady.py [N ...]        (default 250000 500000 1000000; PYTHONPATH=build/python)

Multigrid, permeameter along y (p = 100 on ymin, 0 on ymax, viscosity 1e-3), the walls at the spheres' extent, static
spheres: a first step, then five steady steps, each with its stages from step_times() (dV/dt, solve, forces, total)
and its conjugate-gradient iterations (the range over the steady steps); then the time-step guard's certified bound on
the collective viscous limit (`viscous_stability_bound`, spheres of density 2600, one multigrid solve from zero), what
the guard pays on every new mesh.
Set beside bench/growth.py's flow step of pfv.FlowEngine in YADE on the same lattice, the difference is what the step
costs outside the core (reading positions, writing forces, the time-step guard). No timing is asserted anywhere.
"""
import sys
import time

import numpy as np

from pfv_testing.lattice import lattice_permeameter

KEYS = ('volumes', 'solve', 'forces', 'total')


def measure(n, steady=5):
    e, pos, rad, walls = lattice_permeameter(n)
    t0 = time.perf_counter()
    e.step(pos, rad, walls, 1e-4)
    first = time.perf_counter() - t0
    walls_s, stages, iterations = [], [], []
    for _ in range(steady):
        t0 = time.perf_counter()
        e.step(pos, rad, walls, 1e-4)
        walls_s.append(time.perf_counter() - t0)
        stages.append(dict(e.step_times()))
        iterations.append(e.cg_iterations)
    med = {k: float(np.median([s[k] for s in stages])) for k in KEYS}
    t0 = time.perf_counter()
    e.viscous_stability_bound(2600 * 4 / 3 * np.pi * rad**3)
    bound = time.perf_counter() - t0
    return dict(n=n, cells=e.n_cells(), first=first, steady=walls_s, median=med, iterations=iterations, bound=bound)


def main(argv):
    sizes = [int(float(a)) for a in argv] or [250000, 500000, 1000000]
    print(
        '| N | cells | first step [s] | steady step [s] | dV/dt [ms] | solve [ms] | CG iterations | forces [ms] '
        '| per sphere [µs] | guard bound [s] |'
    )
    print('|---|---|---|---|---|---|---|---|---|---|')
    for n in sizes:
        r = measure(n)
        m = r['median']
        lo, hi = min(r['iterations']), max(r['iterations'])
        its = f"{lo}" if lo == hi else f"{lo}–{hi}"
        row = (
            f"| {n:,} | {r['cells']:,} | {r['first']:.1f} | {m['total']:.3f} | {1e3 * m['volumes']:.0f} | "
            f"{1e3 * m['solve']:.0f} | {its} | {1e3 * m['forces']:.0f} | {1e6 * m['total'] / n:.2f} | "
            f"{r['bound']:.2f} |"
        )
        print(row.replace(',', '\u202f'), flush=True)
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
