"""Where a coupled step of pfv.FlowEngine goes in YADE, engine by engine, on bench/growth.py's lattice scene.

    yade-double -j1 -n -x bench/coupled_breakdown.py [--n=1000000]

The scene of bench/growth.py (N fixed spheres on the jittered lattice, aabbWalls, permeameter along y, multigrid):
a dry step before the flow engine is added, the first coupled step (wall time, the core's share, and cProfile's view
of the Python side), then a steady coupled step with every engine's execTime (O.timingEnabled) and the core's
step_times()['total'], and cProfile of one more steady step. The DEM engines' execTime beside the flow engine against
the dry step shows what the coupling costs the DEM itself (the flow's working set evicts the DEM's). No timing is
asserted anywhere.
"""
import cProfile
import io
import os
import pstats
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(sys.argv[0])))
from lattice import jittered_lattice  # noqa: E402


def option(name, default):
    for a in sys.argv[1:]:
        if a.startswith('--%s=' % name):
            return type(default)(float(a.split('=', 1)[1]))
    return default


def profile_step(label, rows=12):
    from yade import O
    pr = cProfile.Profile()
    t0 = time.perf_counter()
    pr.enable()
    O.step()
    pr.disable()
    wall = time.perf_counter() - t0
    s = io.StringIO()
    pstats.Stats(pr, stream=s).sort_stats('cumulative').print_stats(rows)
    print('%s: %.3f s of wall time; cProfile, by cumulative time:' % (label, wall))
    print('\n'.join(line for line in s.getvalue().splitlines() if 'pfv' in line or 'ncalls' in line))
    return wall


def main():
    from yade import O, utils
    from yade.wrapper import (Bo1_Box_Aabb, Bo1_Sphere_Aabb, ForceResetter, Ig2_Box_Sphere_ScGeom,
                              Ig2_Sphere_Sphere_ScGeom, InsertionSortCollider, InteractionLoop,
                              Ip2_FrictMat_FrictMat_FrictPhys, Law2_ScGeom_FrictPhys_CundallStrack, NewtonIntegrator)
    from pfv import FlowEngine
    n = option('n', 1000000)
    centres, radii = jittered_lattice(n, 1)
    lo, hi = (centres - radii[:, None]).min(axis=0), (centres + radii[:, None]).max(axis=0)
    O.bodies.append(utils.aabbWalls([tuple(lo), tuple(hi)], thickness=0))
    O.bodies.append([utils.sphere(tuple(c), float(r), fixed=True) for c, r in zip(centres, radii)])
    O.dt = 1e-5
    O.engines = [ForceResetter(), InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Box_Aabb()]),
                 InteractionLoop([Ig2_Sphere_Sphere_ScGeom(), Ig2_Box_Sphere_ScGeom()],
                                 [Ip2_FrictMat_FrictMat_FrictPhys()], [Law2_ScGeom_FrictPhys_CundallStrack()]),
                 NewtonIntegrator(damping=0.2)]
    for _ in range(2):  # the collider's first runs
        O.step()
    dry = []
    for _ in range(3):
        t0 = time.perf_counter()
        O.step()
        dry.append(time.perf_counter() - t0)
    print('N = %d: dry steps %s s' % (n, ', '.join('%.3f' % d for d in dry)))
    flow = FlowEngine(wallIds=[0, 1, 2, 3, 4, 5], bndCondIsPressure=[0, 0, 1, 1, 0, 0],
                      bndCondValue=[0, 0, 100.0, 0, 0, 0], boundaryUseMaxMin=[0] * 6, viscosity=1e-3,
                      slipBoundary=False, meshUpdateInterval=10 ** 9, defTolerance=0.0)
    flow.solver = 'multigrid'
    O.engines = O.engines[:-1] + [flow] + O.engines[-1:]
    profile_step('first coupled step')
    print('   of which the core step %.2f s' % flow.core.step_times()['total'])
    for _ in range(2):
        O.step()
    O.timingEnabled = True
    for e in O.engines:
        e.execTime = 0
    t0 = time.perf_counter()
    O.step()
    wall = time.perf_counter() - t0
    print('steady coupled step: %.3f s of wall time, the core step %.3f s; execTime by engine: %s'
          % (wall, flow.core.step_times()['total'],
             ', '.join('%s %.3f s' % (type(e).__name__, e.execTime * 1e-9) for e in O.engines)))
    profile_step('next steady coupled step')
    return 0


if __name__ == '__main__' and 'yade' in sys.modules:
    sys.exit(main())
