"""Candidate throat conductances, evaluated on the pore network of PFV's triangulation against the Stokes reference.

Every candidate maps the throat's own geometry (pfv_periodic.run's throats and throat_study.features) to mu k, the
conductance times the viscosity (a volume): no per-packing input. The network with those conductances is solved by
pfv_periodic.network_kappa, the same periodic system as the engine's, so a candidate is tried without rebuilding
the engine.
"""
import numpy as np


def facet_perimeter(throats):
    """The solid perimeter of each facet: the arcs r_k theta_k of the three great circles inside the triangle
    (theta_k the triangle's angle at vertex k), overlaps between the arcs not removed."""
    tri, r = throats["triangle"], throats["radii"]
    out = np.zeros(len(tri))
    for k in range(3):
        a = tri[:, (k + 1) % 3] - tri[:, k]
        b = tri[:, (k + 2) % 3] - tri[:, k]
        cos = np.einsum("ij,ij->i", a, b) / (np.linalg.norm(a, axis=1) * np.linalg.norm(b, axis=1))
        out += r[:, k] * np.arccos(np.clip(cos, -1.0, 1.0))
    return out


def thesis(t, g):
    """Thesis eq. 3.5-3.6: A_f R_h^2 / (2 L)."""
    return 0.5 * g["fluid_area"] * g["hydraulic_radius"] ** 2 / g["length"]


def constriction(t, g):
    """Poiseuille through a tube of the constriction's radius: pi r_c^4 / (8 L)."""
    return np.pi * g["constriction"] ** 4 / (8.0 * g["length"])


def facet_radius(t, g):
    """The thesis' form with the facet's own hydraulic radius A_f / P (cross-section at the constriction)."""
    r2 = g["fluid_area"] / facet_perimeter(t)
    return 0.5 * g["fluid_area"] * r2**2 / g["length"]


CANDIDATES = {"thesis": thesis, "constriction": constriction, "facet_radius": facet_radius}


def clamped(k, low=1e-4, high=100.0):
    """The engine's clamp: k within [low, high] times the median."""
    m = np.median(k)
    return np.clip(k, low * m, high * m)
