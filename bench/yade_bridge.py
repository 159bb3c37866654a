"""Costs and semantics of moving data between YADE and a Python-driven engine (measurements for
doc/yade.md).

    yade-double -n -x bench/yade_bridge.py [N]        (N spheres, default 10000)

Prints ms per call for the ways to read positions/radii of all spheres and to apply one force per body, then
checks that a force added by a PyRunner placed before NewtonIntegrator acts in the same step and is reset at the
next one.  Exit code 1 if that semantic check fails; timings are only printed.
"""
import sys

import numpy as np
import yade
from yade import O, pack, utils
from yade.wrapper import ForceResetter, NewtonIntegrator, PyRunner, Sphere
from yade.minieigenHP import Vector3

from pfv_testing.timing import per_call_ms

N = int(sys.argv[1]) if len(sys.argv) > 1 and sys.argv[1].isdigit() else 10000


def scene():
    O.reset()
    O.bodies.append(utils.aabbWalls([(0, 0, 0), (1, 1, 1)], thickness=0))
    sp = pack.SpherePack()
    sp.makeCloud((0, 0, 0), (1, 1, 1), rMean=0.02 * (10000.0 / N) ** (1 / 3.0), rRelFuzz=0.3, num=N, seed=1)
    sp.toSimulation()


def bench_read():
    cad = yade._utils.coordsAndDisplacements
    n = len(O.bodies)

    def cad3():
        return np.array([cad(a)[0] for a in range(3)]).T

    def loop_fill():
        a = np.empty((n, 3))
        for i, b in enumerate(O.bodies):
            p = b.state.pos
            a[i, 0] = p[0]
            a[i, 1] = p[1]
            a[i, 2] = p[2]
        return a

    rows = [
        ('coordsAndDisplacements(axis) x3 -> (n,3) array', cad3),
        ('coordsAndDisplacements(0) one axis', lambda: cad(0)),
        ('loop: p=b.state.pos; a[i,k]=p[k]', loop_fill),
        ('[b.state.pos for b in O.bodies] (Vector3 list)', lambda: [b.state.pos for b in O.bodies]),
        ('np.array([b.state.pos for b in O.bodies])', lambda: np.array([b.state.pos for b in O.bodies])),
        ('np.array([tuple(b.state.pos) ...])', lambda: np.array([tuple(b.state.pos) for b in O.bodies])),
        (
            'radii+ids of spheres (isinstance Sphere)',
            lambda: [(b.id, b.shape.radius) for b in O.bodies if isinstance(b.shape, Sphere)],
        ),
        (
            'velocities: loop v=b.state.vel; (v[0],v[1],v[2])',
            lambda: np.array([(v[0], v[1], v[2]) for v in (b.state.vel for b in O.bodies)]),
        ),
    ]
    print('\nread, %d bodies (%d spheres + 6 walls):' % (n, N))
    for name, f in rows:
        print('  %-52s %7.2f ms' % (name, per_call_ms(f)))


def bench_write():
    n = len(O.bodies)
    ids = list(range(n))
    F = np.random.RandomState(0).rand(n, 3)
    tuples = [tuple(r) for r in F.tolist()]
    vecs = [Vector3(*r) for r in F.tolist()]
    addF = O.forces.addF
    rows = [
        ('addF(i, tuple), tuples made beforehand', lambda: [addF(i, f) for i, f in zip(ids, tuples)]),
        (
            'O.forces.addF(i, tuple) (attribute lookup each call)',
            lambda: [O.forces.addF(i, f) for i, f in zip(ids, tuples)],
        ),
        ('addF(i, Vector3), Vector3 made beforehand', lambda: [addF(i, f) for i, f in zip(ids, vecs)]),
        ('addF(i, Vector3(x,y,z)) made each call', lambda: [addF(i, Vector3(*f)) for i, f in zip(ids, tuples)]),
        ('from numpy: map(addF, ids, map(tuple, F.tolist()))', lambda: list(map(addF, ids, map(tuple, F.tolist())))),
        ('from numpy: addF(i, F[i]) (numpy row)', lambda: [addF(i, F[i]) for i in ids]),
        ('setPermF(i, tuple)', lambda: [O.forces.setPermF(i, f) for i, f in zip(ids, tuples)]),
    ]
    print('\nwrite one force per body, %d bodies:' % n)
    for name, f in rows:
        print('  %-52s %7.2f ms' % (name, per_call_ms(f)))
    O.forces.reset()


def check_same_step():
    """Force added before NewtonIntegrator acts in the same step; it is gone at the next step."""
    O.reset()
    O.bodies.append(utils.sphere((0, 0, 0), 1.0))
    m = O.bodies[0].state.mass
    O.dt = 1e-3
    import __main__

    __main__._bench_add = lambda: O.forces.addF(0, (m, 0, 0)) if O.iter == 0 else None
    O.engines = [
        ForceResetter(),
        PyRunner(command='_bench_add()', iterPeriod=1, initRun=True),
        NewtonIntegrator(damping=0, gravity=(0, 0, 0)),
    ]
    O.step()
    v1 = O.bodies[0].state.vel[0] / O.dt
    O.step()
    v2 = O.bodies[0].state.vel[0] / O.dt
    ok = abs(v1 - 1) < 1e-12 and abs(v2 - 1) < 1e-12
    print(
        '\naddF in a PyRunner before NewtonIntegrator: v/dt after step 1 = %g (expect 1: same step), '
        'after step 2 = %g (expect 1: reset by ForceResetter) -> %s' % (v1, v2, 'ok' if ok else 'UNEXPECTED')
    )
    return ok


scene()
print('yade threads (O.numThreads) = %d' % O.numThreads)
bench_read()
bench_write()
sys.exit(0 if check_same_step() else 1)
