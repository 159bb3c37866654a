"""The packing the benchmarks share: a jittered cubic lattice, built in well under a second at any
size the machine holds (no DEM compaction), the same for every run with the same seed."""
import math

import numpy as np


def jittered_lattice(n: int, seed: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """Centres and radii of n spheres on a unit cubic lattice (the first n sites, layer by layer in y),
    centres moved by up to 0.03 and radii 0.42 +- 10 %: no two spheres overlap."""
    side = round(n ** (1 / 3))
    layers = math.ceil(n / side**2)
    i, j, k = np.meshgrid(np.arange(side), np.arange(layers), np.arange(side), indexing="ij")
    sites = np.column_stack([i.ravel(), j.ravel(), k.ravel()])[:n].astype(float) + 0.5
    rng = np.random.default_rng(seed)
    centres = sites + rng.uniform(-0.03, 0.03, size=sites.shape)
    radii = 0.42 * (1 + rng.uniform(-0.1, 0.1, size=n))
    return centres, radii


def walls_around(pos, rad, margin=0.0):
    """The six wall coordinates (xmin, xmax, ymin, ...) `margin` beyond the spheres' extent."""
    lo, hi = (pos - rad[:, None]).min(0) - margin, (pos + rad[:, None]).max(0) + margin
    return [lo[0], hi[0], lo[1], hi[1], lo[2], hi[2]]


def permeameter_engine(solver='auto'):
    """The C++ engine (pfv.Engine, not yet stepped) of the benchmarks' permeameter: flow along y (p = 100 on ymin, 0
    on ymax), viscosity 1e-3, no automatic remesh, `solver`."""
    import pfv

    e = pfv.Engine()
    e.bnd_is_pressure = [False, False, True, True, False, False]
    e.bnd_value = [0, 0, 100.0, 0, 0, 0]
    e.viscosity = 1e-3
    e.mesh_update_interval = 10**9
    e.solver = solver
    return e


def lattice_permeameter(n):
    """The engine (permeameter_engine, multigrid), centres, radii and walls of the benchmarks' lattice permeameter:
    jittered_lattice(n), the walls at the spheres' extent."""
    pos, rad = jittered_lattice(n)
    return permeameter_engine('multigrid'), pos, rad, walls_around(pos, rad)
