"""The packing the benchmarks share: a jittered cubic lattice, built in well under a second at any
size the machine holds (no DEM compaction), the same for every run with the same seed."""
import math

import numpy as np


def jittered_lattice(n: int, seed: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """Centres and radii of n spheres on a unit cubic lattice (the first n sites, layer by layer in y),
    centres moved by up to 0.03 and radii 0.42 +- 10 %: no two spheres overlap."""
    side = round(n ** (1 / 3))
    layers = math.ceil(n / side ** 2)
    i, j, k = np.meshgrid(np.arange(side), np.arange(layers), np.arange(side), indexing="ij")
    sites = np.column_stack([i.ravel(), j.ravel(), k.ravel()])[:n].astype(float) + 0.5
    rng = np.random.default_rng(seed)
    centres = sites + rng.uniform(-0.03, 0.03, size=sites.shape)
    radii = 0.42 * (1 + rng.uniform(-0.1, 0.1, size=n))
    return centres, radii
