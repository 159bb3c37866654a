"""PFV's periodic engine (pfv._core.PeriodicFlow) on a periodic packing: the permeability and every throat.

The flow is driven as periodic_solve.py's, |G| = 1 along `direction`, viscosity 1, so that kappa = U . d is the
permeability in units of the cell side squared. The throats are those of the regular triangulation of the
infinite periodic packing, each with its geometry (pfv._core.PeriodicFlow.throats) and, for the comparison with the
Stokes reference, its triangle: the three sphere centres as seen from the pore on side 0, and the two power
centres (side 1 translated into that frame).
"""
import itertools

import numpy as np

from pfv import _core


def tiled(packing):
    """(centres, radii, cell side lengths) of the packing repeated n times along each axis, n the smallest count
    that makes the cell two diameters of its largest sphere thick (the engine's minimum; a cell of 16 unequal
    spheres can be thinner). The tiled cell holds the same infinite periodic packing: same pores, same kappa."""
    side = np.asarray(packing.get("cell", (1.0, 1.0, 1.0)), dtype=float)
    centres, radii = np.asarray(packing["centres"], dtype=float), np.asarray(packing["radii"], dtype=float)
    n = int(np.ceil(4.0 * radii.max() / side.min() * (1.0 + 1e-9)))
    shifts = np.array(list(itertools.product(range(n), repeat=3)), dtype=float) * side
    return (centres[None, :, :] + shifts[:, None, :]).reshape(-1, 3), np.tile(radii, n**3), side * n


def run(packing, direction=(1.0, 0.0, 0.0)):
    """{kappa, U, n_cells, volume, throats: dict of per-facet arrays} of PFV on the packing (centres, radii, cell),
    tiled where the engine needs a thicker cell (tiled)."""
    centres, radii, side = tiled(packing)
    direction = np.asarray(direction, dtype=float) / np.linalg.norm(direction)
    flow = _core.PeriodicFlow()
    flow.set_settings(viscosity=1.0, permeability_factor=1.0, gradient=-direction, bulk_modulus=0.0)
    flow.step(centres, radii, np.diag(side), 1.0)
    u = np.asarray(flow.mean_velocity())
    t = flow.throats()
    images = np.asarray(flow.image_positions())
    centres = np.asarray(flow.power_centres())
    t["triangle"] = images[t["vertices"]]  # (m, 3 vertices, 3)
    t["radii"] = radii[np.asarray(flow.image_spheres())[t["vertices"]]]
    t["power_centre_0"] = centres[t["cells"][:, 0]]
    t["power_centre_1"] = centres[t["cells"][:, 1]] + t["translation"]
    volumes = np.asarray(flow.fluid_volumes())
    t["fluid_volume_0"], t["fluid_volume_1"] = volumes[t["cells"][:, 0]], volumes[t["cells"][:, 1]]
    return {
        "kappa": float(u @ direction),
        "U": u.tolist(),
        "n_cells": int(flow.n_cells),
        "volume": float(np.prod(side)),
        "power_centres": centres,
        "pressure": np.asarray(flow.pressure()),
        "throats": t,
    }


def network_kappa(throats, conductance, n_cells, volume=1.0, direction=(1.0, 0.0, 0.0)):
    """kappa of the pore network of `throats` with other conductances: the periodic system of PFV's engine,
    solved here (scipy), so that a conductance model can be tried without rebuilding the engine. Returns
    (kappa, fluxes)."""
    import scipy.sparse as sp
    import scipy.sparse.linalg as spla

    direction = np.asarray(direction, dtype=float) / np.linalg.norm(direction)
    gradient = -direction
    i, j = throats["cells"][:, 0], throats["cells"][:, 1]
    branch = throats["power_centre_1"] - throats["power_centre_0"]
    k = np.asarray(conductance, dtype=float)
    drop = -branch @ gradient  # p_0 - p_1 of the mean gradient alone
    g = sp.coo_matrix(
        (np.concatenate([k, k, -k, -k]), (np.concatenate([i, j, i, j]), np.concatenate([i, j, j, i]))),
        shape=(n_cells, n_cells),
    ).tocsr()
    rhs = -np.bincount(i, k * drop, n_cells) + np.bincount(j, k * drop, n_cells)
    # p~ is fixed to 0 in pore 0, the constant being the system's only null mode
    p = np.zeros(n_cells)
    p[1:] = spla.spsolve(g[1:, 1:].tocsc(), rhs[1:])
    q = k * (p[i] - p[j] + drop)
    u = (q[:, None] * branch).sum(0) / volume
    return float(u @ direction), q
