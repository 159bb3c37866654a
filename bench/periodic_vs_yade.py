"""PFV's PeriodicFlowEngine against YADE's on the same periodic scenes: first step and flow step, interleaved.

    yade-double -n -x bench/periodic_vs_yade.py [--sides=6,10,16] [--rounds=5]

Scene: a simple cubic array of side^3 spheres (radius 0.4995, spacing 1, centres jittered by up to 1e-4 with seed
5: YADE's engine gives NaN on the exact, cospherical array) in a periodic cell of side `side`, gradP = (0, 1, 0),
viscosity 1, the spheres fixed (a static skeleton: both engines keep their mesh), O.dt = 1e-5, one thread.

Per side, both engines in one process. In each of `rounds` rounds a fresh engine of each kind takes the scene in
turn for its first step (the wall time of that O.step() minus the median of 3 dry steps: triangulation, system,
factorisation, first solve and forces), the order of the two engines alternating; the first step is the median over
the rounds. Then `rounds` rounds, each running 3 dry steps (no flow engine), 3 steps with YADE's engine and 3 with
PFV's, alternating again; the flow step of an engine is the median over the rounds of its block's median minus the
dry block's median. Printed: the times, their ratio PFV / YADE, and both engines'
permeability (-averageVelocity_y). No time is asserted anywhere.
"""
import statistics
import sys

from pfv_testing import periodic_scene
from pfv_testing.cli import option
from pfv_testing.timing import yade_step

JITTER = 1e-4


def build(side):
    from yade import O

    periodic_scene.build(side, JITTER)
    O.engines = periodic_scene.dem_engines()
    O.step()
    O.step()


def make(kind):
    from yade.minieigenHP import Vector3

    if kind == "yade":
        from yade.wrapper import PeriodicFlowEngine
    else:
        from pfv import PeriodicFlowEngine
    flow = PeriodicFlowEngine(gradP=Vector3(0, 1, 0), viscosity=1.0, useSolver=3)
    flow.meshUpdateInterval = 10**9
    return flow


def with_flow(flow, action):
    from yade import O

    dry = list(O.engines)
    O.engines = dry[:-1] + [flow] + dry[-1:]
    try:
        return action()
    finally:
        O.engines = dry


def block():
    return statistics.median(yade_step() for _ in range(3))


def order(r):
    return ("yade", "pfv") if r % 2 == 0 else ("pfv", "yade")


def measure(side, rounds):
    build(side)
    engines, first = {}, {"yade": [], "pfv": []}
    for r in range(rounds):
        dry = block()
        for kind in order(r):
            engines[kind] = make(kind)
            first[kind].append(with_flow(engines[kind], yade_step) - dry)
    coupled = {"yade": [], "pfv": []}
    for r in range(rounds):
        dry = block()
        for kind in order(r):
            coupled[kind].append(with_flow(engines[kind], block) - dry)
    out = {}
    for kind, flow in engines.items():
        out[kind] = dict(
            first=statistics.median(first[kind]),
            step=statistics.median(coupled[kind]),
            kappa=-float(flow.averageVelocity()[1]),
        )
    return out


def main(argv):
    sides = [int(s) for s in option(argv, "sides", "6,10,16").split(",")]
    rounds = int(option(argv, "rounds", "5"))
    print("| spheres | engine | first step [ms] | flow step [ms] | kappa |")
    print("|---|---|---|---|---|")
    ratios = []
    for side in sides:
        r = measure(side, rounds)
        for kind in ("yade", "pfv"):
            m = r[kind]
            print(f"| {side ** 3} | {kind} | {1e3 * m['first']:.1f} | {1e3 * m['step']:.2f} | {m['kappa']:.5g} |")
        ratios.append((side**3, r["pfv"]["first"] / r["yade"]["first"], r["pfv"]["step"] / r["yade"]["step"]))
        sys.stdout.flush()
    print()
    print("| spheres | PFV / YADE first step | PFV / YADE flow step |")
    print("|---|---|---|")
    for n, first, step in ratios:
        print(f"| {n} | {first:.2f} | {step:.2f} |")


main(sys.argv[1:])
