"""The lattice permeameter in YADE: N fixed spheres on the jittered lattice (pfv_testing.lattice) in the box of
aabbWalls, flow along y, and the flow engines the benchmarks compare on it (YADE's, pfv at its defaults, pfv with the
multigrid solver)."""
import gc

from pfv_testing.lattice import jittered_lattice

DP = 100.0
VISCOSITY = 1e-3


def build_scene(n):
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
    O.dt = 1e-5
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
    return tuple(hi - lo)


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


def remove_flows():
    from yade import O

    O.engines = [e for e in O.engines if "FlowEngine" not in type(e).__name__]
    gc.collect()
