"""YADE's own FlowEngine on a frozen packing: run by yade-double, not imported.

    yade-double -n -x validation/stokes/yade_model.py PACKING.json OUT.json

The unit cube as six aabbWalls, the spheres fixed, pressure dp = 1 on ymin and 0 on ymax, mu = 1,
the engine's defaults otherwise; one step for slipBoundary False and one for True. Writes
kappa = mu Q l0 / (dp S) from getBoundaryFlux of the outlet wall, and fluidForce of every sphere
and wall (YADE does not split it into pressure and viscous parts). NaN where YADE returns NaN.
"""
import json
import math
import sys

from yade import O, utils
from yade.wrapper import (
    Bo1_Box_Aabb,
    Bo1_Sphere_Aabb,
    FlowEngine,
    ForceResetter,
    InsertionSortCollider,
    InteractionLoop,
    NewtonIntegrator,
)

FACES = ("xmin", "xmax", "ymin", "ymax", "zmin", "zmax")


def run(packing, slip):
    O.reset()
    walls = O.bodies.append(utils.aabbWalls([(0, 0, 0), (1, 1, 1)], thickness=0))
    spheres = [O.bodies.append(utils.sphere(c, r, fixed=True)) for c, r in zip(packing["centres"], packing["radii"])]
    flow = FlowEngine(label="flow")
    flow.wallIds = list(walls)
    flow.boundaryUseMaxMin = [False] * 6
    flow.bndCondIsPressure = [False, False, True, True, False, False]
    flow.bndCondValue = [0, 0, 1.0, 0, 0, 0]
    flow.viscosity = 1.0
    flow.slipBoundary = slip
    O.engines = [
        ForceResetter(),
        InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Box_Aabb()]),
        InteractionLoop([], [], []),
        flow,
        NewtonIntegrator(),
    ]
    O.dt = 1e-6
    O.step()
    q = float(flow.getBoundaryFlux(walls[3]))
    forces = {"sphere%d" % k: list(flow.fluidForce(b)) for k, b in enumerate(spheres)}
    forces.update({name: list(flow.fluidForce(b)) for name, b in zip(FACES, walls)})
    clean = {k: [x if math.isfinite(x) else None for x in v] for k, v in forces.items()}
    return {
        "variant": "slip" if slip else "noslip",
        "kappa": q if math.isfinite(q) else None,
        "cells": int(flow.nCells()),
        "forces": clean,
    }


def main(argv):
    with open(argv[1]) as f:
        packing = json.load(f)
    out = {"noslip": run(packing, False), "slip": run(packing, True)}
    with open(argv[2], "w") as f:
        json.dump(out, f, indent=1)
    return 0


sys.exit(main(sys.argv))
