"""Cost of a time-dependent boundary pressure (set_boundary_pressure, pfv.waves) per flow step.

    nice -n 10 yade-double -j1 -n -x bench/wave_cost.py [--spheres=10000] [--rounds=8] [--steps=40]

Scene: N static spheres on a jittered cubic lattice (as bench/vtk_output.py: spacing 1, centres moved by up to
0.03, radii 0.42 +- 10 %, seed 1) in the box of aabbWalls, ymax a pressure wall, the rest impermeable; engines
ForceResetter, pfv.FlowEngine, NewtonIntegrator. After a first step (the mesh and the factor), each round runs
`steps` steps with the load pfv.waves.StandingWave on ymax and `steps` without (the order alternates between
rounds), timing each block of O.run (wall clock) and the engine's own step (flow.core.step_times total, the C++
step, which holds the call of the load). Reported: the median over rounds of the time per step with and without,
their ratio less one, the time of the load's Python call alone (measured inside it) and the core's
pressure_field stage (taking the GIL, the position array, the call, the checks) as a share of the C++ step: the
interleaved ratio is at the mercy of the machine's load, the stage is the cost itself. No mesh or system is
built during the timed blocks (checked). No timing is asserted.
"""
from __future__ import annotations

import statistics
import sys
import time


from pfv_testing.lattice import jittered_lattice
from yade import O, utils  # noqa: E402
from yade.wrapper import ForceResetter, FrictMat, NewtonIntegrator  # noqa: E402

from pfv import FlowEngine, waves  # noqa: E402

SEED = 1
STAGES = ("volumes", "pressure_field", "solve", "forces")


def parse_args(argv: list[str]) -> dict:
    opts = dict(spheres=10000, rounds=8, steps=40)
    for a in argv:
        if not a.startswith("--") or "=" not in a:
            raise SystemExit(f"wave_cost: unknown argument {a!r} (see the docstring)")
        key, value = a[2:].split("=", 1)
        if key not in opts:
            raise SystemExit(f"wave_cost: unknown option --{key}")
        opts[key] = int(value)
    return opts


class Timed:
    """The load, with the time of its calls."""

    def __init__(self, load) -> None:
        self.load, self.seconds, self.calls = load, 0.0, 0

    def __call__(self, x, y, z, t):
        t0 = time.perf_counter()
        p = self.load(x, y, z, t)
        self.seconds += time.perf_counter() - t0
        self.calls += 1
        return p


def main() -> None:
    opts = parse_args(sys.argv[1:])
    centres, radii = jittered_lattice(opts["spheres"], SEED)
    O.reset()
    O.materials.append(FrictMat(young=1e6, poisson=0.5, frictionAngle=0.5, density=2600, label="spheres"))
    lo, hi = (centres - radii[:, None]).min(axis=0), (centres + radii[:, None]).max(axis=0)
    O.bodies.append(utils.aabbWalls([tuple(lo), tuple(hi)], thickness=0, material="spheres"))
    spheres = [utils.sphere(tuple(c), float(r), material="spheres") for c, r in zip(centres, radii)]
    for b in spheres:
        b.state.blockedDOFs = "xyzXYZ"
    O.bodies.append(spheres)
    flow = FlowEngine(
        wallIds=list(range(6)),
        boundaryUseMaxMin=[False] * 6,
        useSolver=3,
        bndCondIsPressure=[False, False, False, True, False, False],
        meshUpdateInterval=10**9,
    )
    O.engines = [ForceResetter(), flow, NewtonIntegrator(damping=0)]
    O.dt = 1e-4
    load = Timed(waves.StandingWave(amplitude=150.0, period=1.0, length=float(hi[0] - lo[0]), origin=float(lo[0])))
    flow.set_boundary_pressure(flow.ymax, load)
    O.run(1, True)
    n_top = sum(1 for c in range(flow.nCells()) if flow.getCellPImposed(c))
    builds = (flow.core.remesh_count, flow.core.system_builds)
    per_step = {True: [], False: []}
    engine = {True: [], False: []}
    stages = {True: {k: [] for k in STAGES}, False: {k: [] for k in STAGES}}
    load_seconds, field_share = [], []
    for r in range(opts["rounds"]):
        for on in (True, False) if r % 2 == 0 else (False, True):
            if on:
                flow.set_boundary_pressure(flow.ymax, load)
            else:
                flow.clear_boundary_pressure()
            seconds, calls = load.seconds, load.calls
            inner = field = 0.0
            parts = dict.fromkeys(STAGES, 0.0)
            t0 = time.perf_counter()
            for _ in range(opts["steps"]):
                O.run(1, True)
                times = flow.core.step_times()
                inner += times["total"]
                field += times["pressure_field"]
                for k in STAGES:
                    parts[k] += times[k]
            per_step[on].append((time.perf_counter() - t0) / opts["steps"])
            engine[on].append(inner / opts["steps"])
            for k in STAGES:
                stages[on][k].append(parts[k] / opts["steps"])
            if on:
                assert load.calls - calls == opts["steps"], "one call of the load per step"
                load_seconds.append((load.seconds - seconds) / opts["steps"])
                field_share.append(field / inner)
    assert (flow.core.remesh_count, flow.core.system_builds) == builds, "no mesh or system built while timed"
    without, with_load = statistics.median(per_step[False]), statistics.median(per_step[True])
    core_without, core_with = statistics.median(engine[False]), statistics.median(engine[True])
    call = statistics.median(load_seconds)
    print(
        f"wave_cost: {opts['spheres']} spheres, {flow.nCells()} cells, {n_top} cells on ymax; "
        f"{opts['rounds']} rounds of {opts['steps']} steps with and without the load"
    )
    print(
        f"wave_cost: O.run per step      without {without * 1e3:.3f} ms, with {with_load * 1e3:.3f} ms, "
        f"ratio - 1 = {with_load / without - 1:+.2%}"
    )
    print(
        f"wave_cost: C++ step per step   without {core_without * 1e3:.3f} ms, with {core_with * 1e3:.3f} ms, "
        f"ratio - 1 = {core_with / core_without - 1:+.2%}"
    )
    print(f"wave_cost: the load's Python call {call * 1e6:.1f} us = {call / core_without:.2%} of the C++ step")
    for on in (False, True):
        print(
            f"wave_cost: stages {'with   ' if on else 'without'} "
            + ", ".join(f"{k} {statistics.median(stages[on][k]) * 1e3:.3f} ms" for k in STAGES)
        )
    print(
        f"wave_cost: the core's pressure_field stage (GIL, arrays, the call, checks) = "
        f"{statistics.median(field_share):.2%} of the C++ step"
    )


main()
