"""The lattice permeameter in YADE: N spheres on the jittered lattice (pfv_testing.lattice) in the box of aabbWalls,
flow along y, and the flow engines the benchmarks compare on it (YADE's, pfv at its defaults, pfv with the multigrid
solver). The spheres are not dynamic: they stay where they are, or move at velocities set once (MOTIONS)."""
import gc

import numpy as np

from pfv_testing.lattice import jittered_lattice

DP = 100.0
VISCOSITY = 1e-3
DT = 1e-5
# Kinematic motions: "drift", every sphere at its own constant velocity in a random direction, 0.2 spacing per 1000
# steps (the outermost layers pointed inwards, so no sphere leaves the box); "compression", a slow oedometric
# compression along y, the ymax wall moving in and the spheres' velocities affine with it, strain 1e-6 per step.
MOTIONS = ("static", "drift", "compression")
DRIFT_PER_STEP = 2e-4
STRAIN_PER_STEP = 1e-6


def velocities(centres, motion, seed=2):
    """Per sphere, its velocity under `motion`, and the velocity of the ymax wall (id 3)."""
    if motion == "static":
        return np.zeros_like(centres), 0.0
    lo, hi = centres.min(axis=0), centres.max(axis=0)
    if motion == "drift":
        v = np.random.default_rng(seed).normal(size=centres.shape)
        v *= DRIFT_PER_STEP / DT / np.linalg.norm(v, axis=1)[:, None]
        first, last = centres < lo + 0.5, centres > hi - 0.5
        v[first] = np.abs(v[first])
        v[last] = -np.abs(v[last])
        return v, 0.0
    if motion == "compression":
        rate = STRAIN_PER_STEP / DT
        v = np.zeros_like(centres)
        v[:, 1] = -rate * (centres[:, 1] - lo[1])
        return v, -rate * (hi[1] - lo[1])
    raise ValueError(f"unknown motion {motion!r}: one of {', '.join(MOTIONS)}")


class Motion:
    """The velocities of a kinematic motion, set on the scene's bodies (resume) or taken off them (pause): a benchmark
    pauses the motion while it times the DEM without the flow engine, which then finds the spheres where it left
    them instead of a jump of several steps in one."""

    def __init__(self, spheres, wall):
        self.spheres, self.wall = spheres, wall
        self.moving = bool(wall) or bool(spheres.any())

    def _set(self, scale):
        from yade import O, Vector3

        if not self.moving:
            return
        for i, v in enumerate((scale * self.spheres).tolist()):
            O.bodies[6 + i].state.vel = Vector3(*v)
        O.bodies[3].state.vel = Vector3(0.0, scale * self.wall, 0.0)

    def resume(self):
        self._set(1.0)

    def pause(self):
        self._set(0.0)


def build_scene(n, motion="static"):
    """The scene of N spheres moving by `motion` (one of MOTIONS); returns its Motion."""
    from yade import O, utils
    from yade.wrapper import (
        Bo1_Box_Aabb,
        Bo1_Sphere_Aabb,
        ForceResetter,
        Ig2_Box_Sphere_ScGeom,
        Ig2_Sphere_Sphere_ScGeom,
        InsertionSortCollider,
        InteractionLoop,
        Ip2_FrictMat_FrictMat_FrictPhys,
        Law2_ScGeom_FrictPhys_CundallStrack,
        NewtonIntegrator,
    )

    centres, radii = jittered_lattice(n, 1)
    lo, hi = (centres - radii[:, None]).min(axis=0), (centres + radii[:, None]).max(axis=0)
    O.reset()
    O.bodies.append(utils.aabbWalls([tuple(lo), tuple(hi)], thickness=0))
    O.bodies.append([utils.sphere(tuple(c), float(r), fixed=True) for c, r in zip(centres, radii)])
    motion = Motion(*velocities(centres, motion))
    motion.resume()
    O.dt = DT
    O.engines = [
        ForceResetter(),
        InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Box_Aabb()]),
        InteractionLoop(
            [Ig2_Sphere_Sphere_ScGeom(), Ig2_Box_Sphere_ScGeom()],
            [Ip2_FrictMat_FrictMat_FrictPhys()],
            [Law2_ScGeom_FrictPhys_CundallStrack()],
        ),
        NewtonIntegrator(damping=0.2),
    ]
    for _ in range(2):  # the collider's first runs, before any engine is timed
        O.step()
    return motion


def make_flow(kind):
    if kind == "yade":
        from yade.wrapper import FlowEngine as Flow
    else:
        from pfv import FlowEngine as Flow
    flow = Flow()
    flow.wallIds = [0, 1, 2, 3, 4, 5]
    flow.bndCondIsPressure = [False, False, True, True, False, False]
    flow.bndCondValue = [0, 0, DP, 0, 0, 0]
    flow.boundaryUseMaxMin = [False] * 6
    flow.viscosity = VISCOSITY
    flow.slipBoundary = False
    flow.meshUpdateInterval = 10**9
    flow.defTolerance = 0.0
    if kind == "yade":
        flow.useSolver = 3
    elif kind == "pfv-multigrid":
        flow.solver = "multigrid"
    elif kind == "pfv-multigrid-jacobi":  # not in the default plan: --child=time --kinds=pfv-multigrid-jacobi
        flow.solver = "multigrid"
        flow.multigrid_smoother = "jacobi"
    return flow


def insert(flow):
    from yade import O
    from yade.wrapper import NewtonIntegrator

    engines = [e for e in O.engines]
    i = [k for k, e in enumerate(engines) if isinstance(e, NewtonIntegrator)][0]
    O.engines = engines[:i] + [flow] + engines[i:]


def dry_steps(flow, motion, count):
    """Seconds of each of `count` dry steps: `flow` taken out of O.engines for them and the spheres held still (else
    the engine would see the motion of count + 1 steps in one), then both put back."""
    from pfv_testing.timing import yade_step

    remove_flows()
    motion.pause()
    steps = [yade_step() for _ in range(count)]
    motion.resume()
    insert(flow)
    return steps


def remove_flows():
    from yade import O

    O.engines = [e for e in O.engines if "FlowEngine" not in type(e).__name__]
    gc.collect()


def build_box(n, engines=1, plain=False):
    """A new scene in the current one (not reset here) for the tests of scene ends: N spheres of the lattice, fixed,
    between six walls, `engines` pfv engines with a pressure drop along y (all but the first decoupled), a plain
    PyRunner if `plain`, and no collider. Bodies are appended one by one: YADE's O.bodies.append(list) keeps a
    reference to every body, a leak of its own. Returns the pfv engines."""
    from pfv import FlowEngine
    from yade import O, utils
    from yade.wrapper import ForceResetter, NewtonIntegrator, PyRunner

    centres, radii = jittered_lattice(n, 1)
    lo, hi = (centres - radii[:, None]).min(axis=0), (centres + radii[:, None]).max(axis=0)
    for wall in utils.aabbWalls([tuple(lo), tuple(hi)], thickness=0):
        O.bodies.append(wall)
    for c, r in zip(centres, radii):
        O.bodies.append(utils.sphere(tuple(c), float(r), fixed=True))
    flows = []
    for k in range(engines):
        flow = FlowEngine(decoupleForces=k > 0)
        flow.wallIds = [0, 1, 2, 3, 4, 5]
        flow.bndCondIsPressure = [False, False, True, True, False, False]
        flow.bndCondValue = [0.0, 0.0, 1.0, 0.0, 0.0, 0.0]
        flow.boundaryUseMaxMin = [False] * 6
        flows.append(flow)
    runners = [PyRunner(command="pass", iterPeriod=1)] if plain else []
    O.engines = [ForceResetter()] + flows + runners + [NewtonIntegrator()]
    O.dt = DT
    return flows
