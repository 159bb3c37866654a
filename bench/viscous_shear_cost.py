"""Cost of the optional viscous shear term (viscousShear): remesh and step time with it off and on.

    OMP_NUM_THREADS=1 PYTHONPATH=build/python /usr/bin/python3.11 bench/viscous_shear_cost.py
        [--n=20] [--rounds=3] [--steps=20] [--modes=off,on]

Scene: n^3 equal-size spheres (radius 0.4 a) on a jittered simple cubic lattice of spacing a (jitter 0.15 a, seeded:
no cospherical groups) in the unit box, permeameter along y, every sphere moving with a small random velocity.
Drives the C++ engine (pfv._core.Engine) directly: no YADE. Per round and mode: one step that remeshes, then --steps
steady steps, then a forced remesh; reports medians over rounds of the remesh wall time (engine.step with a remesh)
and of the steady step wall time, and the engine's own stage times for the shear term.

Mode 'off' runs with viscous_shear left alone, so the same script measures a build without the term (the code before
it existed) when PYTHONPATH points there. Timing only: nothing is asserted.
"""
import argparse
import json
import statistics

import numpy as np

from pfv._core import Engine
from pfv_testing.timing import wall

parser = argparse.ArgumentParser()
parser.add_argument("--n", type=int, default=20)
parser.add_argument("--rounds", type=int, default=3)
parser.add_argument("--steps", type=int, default=20)
parser.add_argument("--modes", default="off,on")
parser.add_argument("--label", default="")
args = parser.parse_args()

rng = np.random.default_rng(1)
a = 1.0 / args.n
grid = (np.stack(np.meshgrid(*[np.arange(args.n)] * 3, indexing="ij"), -1).reshape(-1, 3) + 0.5) * a
centres0 = grid + rng.uniform(-0.15 * a, 0.15 * a, grid.shape)
radii = np.full(len(centres0), 0.4 * a)
velocity = rng.normal(0, 1e-3, centres0.shape)
walls = [0.0, 1.0, 0.0, 1.0, 0.0, 1.0]
dt = 1e-3


def engine(mode):
    e = Engine()
    e.bnd_is_pressure = [False, False, True, True, False, False]
    e.bnd_value = [0, 0, 1, 0, 0, 0]
    if mode == "on":
        e.viscous_shear = True
    return e


def timed_step(e, x):
    return wall(lambda: e.step(x, radii, walls, dt))


results = {}
for mode in args.modes.split(","):
    remesh, steady, shear_geometry, shear_forces = [], [], [], []
    for _ in range(args.rounds):
        e = engine(mode)
        x = centres0.copy()
        timed_step(e, x)  # first mesh
        steps = []
        for _ in range(args.steps):
            x = x + dt * velocity
            steps.append(timed_step(e, x))
        steady.append(statistics.median(steps))
        e.request_remesh()
        x = x + dt * velocity
        remesh.append(timed_step(e, x))
        rt, st = e.remesh_times(), e.step_times()
        shear_geometry.append(rt.get("shear_geometry", 0.0))
        shear_forces.append(st.get("shear_forces", 0.0))
    results[mode] = dict(
        remesh_ms=1e3 * statistics.median(remesh),
        step_ms=1e3 * statistics.median(steady),
        shear_geometry_ms=1e3 * statistics.median(shear_geometry),
        shear_forces_ms=1e3 * statistics.median(shear_forces),
        cells=e.n_cells(),
    )
    if mode == "on":
        results[mode]["pairs"] = int(len(e.shear_pairs()["a"]))
print(json.dumps(dict(label=args.label, spheres=len(centres0), rounds=args.rounds, steps=args.steps, results=results)))
