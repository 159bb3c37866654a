"""Frozen sphere packings in the unit cube for the Stokes comparison (thesis section 3.5).

A packing is a dict with ``centres`` (n x 3), ``radii`` (n) and a ``name``; lengths are in units
of the cube side l0 = 1. Touching spheres are separated by a uniform shrink of every radius
about its fixed centre (``shrunk``): the FEM mesh needs a gap at each contact, and PFV and YADE
are run on the same shrunk spheres, so that all three solve the same geometry.
"""
import json

import numpy as np
from scipy.optimize import minimize


def cubic8():
    """Eight equal spheres of radius l0/4 in a simple cubic arrangement, touching each other and the walls."""
    axis = np.array([0.25, 0.75])
    centres = np.array([[x, y, z] for x in axis for y in axis for z in axis])
    return {"name": "cubic8", "centres": centres, "radii": np.full(8, 0.25)}


def centred9(d_over_d):
    """The cubic 8 (diameter D = l0/2) plus a central sphere of diameter d = d_over_d * D.

    The central sphere touches the eight for d/D = sqrt(3) - 1 = 0.732; above that it overlaps them.
    """
    p = cubic8()
    return {
        "name": "centred9_%.2f" % d_over_d,
        "centres": np.vstack([p["centres"], [0.5, 0.5, 0.5]]),
        "radii": np.append(p["radii"], 0.25 * d_over_d),
    }


def shrunk(packing, shrink):
    """The packing with every radius multiplied by (1 - shrink), centres unchanged."""
    out = dict(packing)
    out["radii"] = np.asarray(packing["radii"]) * (1.0 - shrink)
    out["shrink"] = shrink
    return out


def _energy(flat, r):
    """Sum of squared overlaps (sphere pairs and walls) and its gradient in the centres."""
    x = flat.reshape(-1, 3)
    d = x[:, None, :] - x[None, :, :]
    dist = np.sqrt((d**2).sum(-1)) + np.eye(len(r))
    pair = np.triu(np.maximum(r[:, None] + r[None, :] - dist, 0.0), 1)
    pair = pair + pair.T
    low = np.maximum(r[:, None] - x, 0.0)
    high = np.maximum(x + r[:, None] - 1.0, 0.0)
    energy = 0.5 * (pair**2).sum() / 2 + 0.5 * ((low**2).sum() + (high**2).sum())
    grad = -((pair / dist)[:, :, None] * d).sum(1) * 1.0 - low + high
    return energy, grad.ravel()


def _minimise(x, r):
    res = minimize(
        _energy,
        x.ravel(),
        args=(r,),
        jac=True,
        method="L-BFGS-B",
        options={"maxiter": 5000, "ftol": 1e-30, "gtol": 1e-14},
    )
    return res.x.reshape(-1, 3), res.fun


def random_packing(n, ratio, seed, tolerance=1e-6):
    """Dense random packing of n spheres in the unit cube by radius growth.

    Radii are drawn uniformly in [ratio, 1] times a common scale. From a random cloud the scale
    grows and, at each trial scale, the centres are moved to minimise the squared overlaps
    (spheres against spheres and walls); the largest scale whose minimum has no overlap larger
    than ``tolerance`` times the mean radius is found by bisection (jamming). The radii are then
    reduced by the largest remaining relative overlap, so that no two spheres intersect.
    """
    rng = np.random.default_rng(seed)
    shape = rng.uniform(ratio, 1.0, n)
    x = rng.uniform(0.0, 1.0, (n, 3))
    low = 0.0
    high = (3.0 * 0.7 / (4.0 * np.pi * (shape**3).sum())) ** (1.0 / 3.0)  # solid fraction 0.7
    good = x
    for _ in range(40):
        scale = 0.5 * (low + high)
        trial, energy = _minimise(good, scale * shape)
        if np.sqrt(2.0 * energy) <= tolerance * scale * shape.mean():
            low, good = scale, trial
        else:
            high = scale
    x, r = good, low * shape
    d = np.sqrt(((x[:, None, :] - x[None, :, :]) ** 2).sum(-1)) + np.eye(n) * 1e9
    worst = max(0.0, ((r[:, None] + r[None, :] - d) / (r[:, None] + r[None, :])).max())
    r = r * (1.0 - worst)
    x = np.clip(x, r[:, None], 1.0 - r[:, None])
    return {"name": "random%d" % n, "centres": x, "radii": r, "seed": seed, "ratio": ratio}


def porosity(packing):
    """Void fraction of the unit cube (spheres inside the cube and not overlapping)."""
    return 1.0 - (4.0 / 3.0) * np.pi * (np.asarray(packing["radii"]) ** 3).sum()


def save(packing, path):
    with open(path, "w") as f:
        json.dump({k: (v.tolist() if isinstance(v, np.ndarray) else v) for k, v in packing.items()}, f, indent=1)


def load(path):
    with open(path) as f:
        p = json.load(f)
    p["centres"] = np.asarray(p["centres"], dtype=float)
    p["radii"] = np.asarray(p["radii"], dtype=float)
    return p


if __name__ == "__main__":
    # python3 -m validation.stokes.packings N RATIO SEED validation/stokes/data/NAME.json (from the repository's
    # root): a random packing for run.py's case NAME (random<N>, or random<N>s<SEED> for further seeds)
    import os
    import sys

    n, ratio, seed, path = int(sys.argv[1]), float(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
    packing = random_packing(n, ratio, seed)
    packing["name"] = os.path.splitext(os.path.basename(path))[0]
    save(packing, path)
