"""Random periodic sphere packings in the unit cube for the periodic Stokes reference and the conductance study.

A packing is a dict as packings.py's (``centres`` n x 3 in [0, 1), ``radii``, ``name``) with ``cell`` [1, 1, 1],
the target solid fraction ``c`` and the generator's parameters. Radii are drawn uniformly in [ratio, 1] times a
common scale chosen so that the solid fraction is c exactly; the centres, from a uniform random cloud, are moved
to minimise the sum of squared overlaps between the spheres with their radii inflated by (1 + gap) (minimum image
convention), by L-BFGS. With gap = 0 the minimum leaves the pairs that overlapped in contact, at gaps far below
any mesh size (the dense packings: contacts, handled by the shrink of doc/validation.md section 7); with gap > 0
every pair is at least gap (r_i + r_j) apart (the loose packings: no contact, no shrink needed).

Radius growth (packings.py's walled generator) finds the jamming fraction instead; here the fraction is the
input, so that the packings sample the states named by the study (dense, loose, a liquefying bed).

    /usr/bin/python3 -m validation.stokes.periodic_packings          # writes PACKINGS into DATA
"""
import json
import os

import numpy as np
from scipy.optimize import minimize

DATA = os.path.join(os.path.dirname(os.path.abspath(__file__)), "data", "periodic")

# name: (spheres, r_min / r_max, solid fraction, gap, seed). Two realisations of each state.
PACKINGS = {
    "dense_mono_s1": (100, 1.0, 0.62, 0.0, 1),
    "dense_mono_s2": (100, 1.0, 0.62, 0.0, 2),
    "dense_poly_s1": (100, 0.5, 0.62, 0.0, 1),
    "dense_poly_s2": (100, 0.5, 0.62, 0.0, 2),
    "loose_mono_s1": (100, 1.0, 0.55, 0.02, 1),
    "loose_mono_s2": (100, 1.0, 0.55, 0.02, 2),
    "loose_poly_s1": (100, 0.5, 0.55, 0.02, 1),
    "loose_poly_s2": (100, 0.5, 0.55, 0.02, 2),
    "bed_mono_s1": (100, 1.0, 0.45, 0.05, 1),
    "bed_mono_s2": (100, 1.0, 0.45, 0.05, 2),
}
# Small cells of 16 spheres: many geometries at a small cost, for fitting throat-level models that the packings
# of 100 spheres then test.
SMALL = {
    "small_%s_c%02d_s%d" % (kind, round(100 * c), seed): (16, ratio, c, gap, seed)
    for kind, ratio in (("mono", 1.0), ("poly", 0.5))
    for c, gap in ((0.40, 0.03), (0.50, 0.03), (0.58, 0.01), (0.60, 0.0))
    for seed in (11, 12)
}
PACKINGS.update(SMALL)

# A sphere this close to tangency with a face of the cell is moved off it (periodic_mesh refuses it).
FACE_CLEARANCE = 2e-3
# Overlap left by the minimisation, relative to the mean radius, that is still taken as a contact.
CONTACT_TOLERANCE = 1e-6


def _pair_terms(x, reach):
    """Minimum-image separations d (n, n, 3), distances and the overlaps of the inflated radii."""
    d = x[:, None, :] - x[None, :, :]
    d -= np.round(d)
    dist = np.sqrt((d**2).sum(-1)) + np.eye(len(x))
    overlap = np.triu(np.maximum(reach - dist, 0.0), 1)
    return d, dist, overlap + overlap.T


def _energy(flat, reach):
    """Half the sum of squared overlaps over the pairs, and its gradient in the centres."""
    d, dist, overlap = _pair_terms(flat.reshape(-1, 3), reach)
    energy = 0.25 * (overlap**2).sum()
    grad = -((overlap / dist)[:, :, None] * d).sum(1)
    return energy, grad.ravel()


def generate(n, ratio, c, gap, seed):
    """The packing of n spheres at solid fraction c (module docstring)."""
    rng = np.random.default_rng(seed)
    shape = rng.uniform(ratio, 1.0, n)
    scale = (3.0 * c / (4.0 * np.pi * (shape**3).sum())) ** (1.0 / 3.0)
    r = scale * shape
    reach = (r[:, None] + r[None, :]) * (1.0 + gap)
    x = rng.uniform(0.0, 1.0, (n, 3))
    for _ in range(20):
        res = minimize(
            _energy,
            x.ravel(),
            args=(reach,),
            jac=True,
            method="L-BFGS-B",
            options={"maxiter": 20000, "ftol": 1e-30, "gtol": 1e-16},
        )
        x = np.mod(res.x.reshape(-1, 3), 1.0)
        worst = _pair_terms(x, reach)[2].max()
        if worst <= CONTACT_TOLERANCE * r.mean():
            break
    else:
        raise RuntimeError("no overlap-free packing of %d spheres at c = %g (jammed?)" % (n, c))
    # the residual overlaps (below CONTACT_TOLERANCE) removed by a common shrink of the radii
    _, dist, _ = _pair_terms(x, reach)
    relative = ((r[:, None] + r[None, :]) * (1.0 + gap) - dist) / (r[:, None] + r[None, :])
    np.fill_diagonal(relative, -np.inf)
    r = r * (1.0 - max(0.0, relative.max()))
    x = _clear_faces(x, r, rng)
    return {
        "centres": x,
        "radii": r,
        "cell": [1.0, 1.0, 1.0],
        "c": float(4.0 / 3.0 * np.pi * (r**3).sum()),
        "ratio": ratio,
        "gap": gap,
        "seed": seed,
    }


def _clear_faces(x, r, rng, tries=1000):
    """The packing translated (periodically) so that no sphere is within FACE_CLEARANCE of tangency with a face."""
    for _ in range(tries):
        y = np.mod(x + rng.uniform(0.0, 1.0, 3), 1.0)
        near = np.abs(np.abs(np.concatenate([y, y - 1.0])) - np.concatenate([r, r])[:, None])
        if near.min() > FACE_CLEARANCE:
            return y
    raise RuntimeError("no translation keeps every sphere off tangency with the faces")


def contacts(packing, tolerance=1e-4):
    """Pairs (i, j) whose gap is below tolerance times r_i + r_j (minimum image)."""
    x, r = np.asarray(packing["centres"]), np.asarray(packing["radii"])
    _, dist, _ = _pair_terms(x, 0.0)
    gap = dist / (r[:, None] + r[None, :]) - 1.0
    i, j = np.nonzero(np.triu(gap < tolerance, 1))
    return list(zip(i.tolist(), j.tolist()))


def min_gap(packing):
    """The smallest gap over r_i + r_j of any pair (minimum image)."""
    x, r = np.asarray(packing["centres"]), np.asarray(packing["radii"])
    _, dist, _ = _pair_terms(x, 0.0)
    gap = dist / (r[:, None] + r[None, :]) - 1.0
    np.fill_diagonal(gap, np.inf)
    return float(gap.min())


def path_of(name):
    return os.path.join(DATA, name + ".json")


def save(packing, path):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w") as f:
        json.dump({k: (v.tolist() if isinstance(v, np.ndarray) else v) for k, v in packing.items()}, f, indent=1)


def load(name):
    with open(path_of(name)) as f:
        p = json.load(f)
    p["centres"] = np.asarray(p["centres"], dtype=float)
    p["radii"] = np.asarray(p["radii"], dtype=float)
    return p


def main():
    for name, (n, ratio, c, gap, seed) in PACKINGS.items():
        p = generate(n, ratio, c, gap, seed)
        p["name"] = name
        save(p, path_of(name))
        print("%-14s n %d  c %.4f  contacts %3d  min gap %.2e" % (name, n, p["c"], len(contacts(p)), min_gap(p)))


if __name__ == "__main__":
    main()
