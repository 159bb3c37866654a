"""The periodic scenes of the tests and benchmarks of pfv.PeriodicFlowEngine: a simple cubic array of spheres in a
periodic YADE cell (centres optionally jittered: YADE's PeriodicFlowEngine gives NaN on the exact, cospherical array),
the DEM engines around a flow engine, and the cell's vectors as a numpy matrix."""
import numpy as np

RADIUS = 0.4995  # nearly touching on the lattice of spacing 1


def cubic_array(side, jitter=0.0, seed=5):
    """The centres of side^3 spheres on the lattice of spacing 1 (cell [0, side)^3), each moved by up to `jitter`."""
    grid = np.array([[i + 0.5, j + 0.5, k + 0.5] for i in range(side) for j in range(side) for k in range(side)])
    if jitter:
        grid += np.random.default_rng(seed).uniform(-jitter, jitter, grid.shape)
    return grid


def build(side, jitter=0.0, seed=5, periodic=True):
    """A new scene: the array's spheres (fixed), in a periodic cell of side `side` unless `periodic` is False; no
    engines; O.dt = 1e-5. Returns the centres."""
    from yade import O, utils
    from yade.minieigenHP import Matrix3

    O.reset()
    O.periodic = periodic
    if periodic:
        O.cell.hSize = Matrix3(side, 0, 0, 0, side, 0, 0, 0, side)
    centres = cubic_array(side, jitter, seed)
    for c in centres:
        O.bodies.append(utils.sphere(tuple(c), RADIUS, fixed=True))
    O.dt = 1e-5
    return centres


def dem_engines(flow=None):
    """YADE's engines of a periodic sphere packing, with `flow` (if any) before the integrator."""
    from yade.wrapper import (
        Bo1_Sphere_Aabb,
        ForceResetter,
        Ig2_Sphere_Sphere_ScGeom,
        InsertionSortCollider,
        InteractionLoop,
        Ip2_FrictMat_FrictMat_FrictPhys,
        Law2_ScGeom_FrictPhys_CundallStrack,
        NewtonIntegrator,
    )

    return [
        ForceResetter(),
        InsertionSortCollider([Bo1_Sphere_Aabb()], allowBiggerThanPeriod=True),
        InteractionLoop(
            [Ig2_Sphere_Sphere_ScGeom()], [Ip2_FrictMat_FrictMat_FrictPhys()], [Law2_ScGeom_FrictPhys_CundallStrack()]
        ),
        *([flow] if flow is not None else []),
        NewtonIntegrator(),
    ]


def cell_matrix():
    """O.cell.hSize as a 3 x 3 numpy array (columns: the cell's vectors)."""
    from yade import O

    return np.array([[O.cell.hSize[i, j] for j in range(3)] for i in range(3)])
