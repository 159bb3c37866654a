"""The first step of the C++ engine alone, by stage, for several solvers, on bench/growth.py's jittered lattice.

    OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 PYTHONPATH=build/python /usr/bin/python3 bench/first_step_stages.py \
        [N] [--solvers=auto,multigrid]

Scene as bench/core_steady.py (permeameter along y, static spheres, `pfv.Engine` without YADE). For each solver in
turn, one fresh engine in a fresh process (so that no engine runs in memory another has just freed): the wall time of
its first step, the stages of its first mesh (`remesh_times()`), the first
solve (`step_times()`), and the engine's report of its choice (`solver_choice`). Under `solver="auto"` the
"analysis" stage is the fill-reducing ordering and CHOLMOD's symbolic factorisation that project the factor's size
against the budget (half the available memory) and against CHOLMOD's 32-bit index range, which it pays whichever
solver it then takes. No timing is asserted.
"""
import os
import subprocess
import sys
import time

from pfv_testing.lattice import lattice_permeameter

STAGES = ('triangulation', 'geometry', 'conductance', 'force_cache', 'assembly', 'analysis', 'factorization')


def first_step(n, solver):
    e, pos, rad, walls = lattice_permeameter(n)
    e.solver = solver
    t0 = time.perf_counter()
    e.step(pos, rad, walls, 1e-4)
    wall = time.perf_counter() - t0
    return wall, dict(e.remesh_times()), e.step_times()['solve'], e.solver_choice


def main(argv):
    n = next((int(float(a)) for a in argv if not a.startswith('--')), 500000)
    child = next((a.split('=', 1)[1] for a in argv if a.startswith('--child=')), '')
    if child:
        wall, stages, solve, choice = first_step(n, child)
        cells = ' | '.join('%.2f' % stages[k] for k in STAGES)
        print('| %d | %s | %.1f | %s | %.2f | %s |' % (n, child, wall, cells, solve, choice), flush=True)
        return 0
    solvers = next((a.split('=', 1)[1] for a in argv if a.startswith('--solvers=')), 'auto,multigrid').split(',')
    print('| N | solver | first step [s] | %s | first solve [s] | choice |' % ' | '.join(STAGES))
    print('|---|---|---|%s---|---|' % ('---|' * len(STAGES)), flush=True)
    for solver in solvers:
        subprocess.run([sys.executable, os.path.abspath(__file__), str(n), '--child=' + solver], check=True)
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
