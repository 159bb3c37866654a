"""Candidate throat conductances, evaluated on the pore network of PFV's triangulation against the Stokes reference.

    export PYTHONPATH=$BUILD/python
    /usr/bin/python3 -m validation.stokes.conductance_candidates     # the table of doc/validation.md section 7.7

Every candidate maps the throat's own geometry (pfv_periodic.run's throats and throat_study.features) to mu k, the
conductance times the viscosity (a volume): no per-packing input. The network with those conductances is solved by
pfv_periodic.network_kappa, the same periodic system as the engine's, so a candidate is tried without rebuilding
the engine.
"""
import sys
import warnings

import numpy as np

from . import periodic_mesh, periodic_packings, periodic_random, periodic_run, pfv_periodic, throat_study


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
    """Thesis eq. 3.5-3.6: A_f R_h^2 / (2 L), infinite for a flat pair of pores (L = 0: the clamp bounds it)."""
    with np.errstate(divide="ignore"):
        return 0.5 * g["fluid_area"] * g["hydraulic_radius"] ** 2 / g["length"]


def constriction(t, g):
    """Poiseuille through a tube of the constriction's radius: pi r_c^4 / (8 L)."""
    return np.pi * g["constriction"] ** 4 / (8.0 * g["length"])


def facet_radius(t, g):
    """The thesis' form with the facet's own hydraulic radius A_f / P (cross-section at the constriction)."""
    r2 = g["fluid_area"] / facet_perimeter(t)
    return 0.5 * g["fluid_area"] * r2**2 / g["length"]


def entrance(t, g, beta=3.0 * np.pi / 8.0, radius="area"):
    """The thesis' duct in series with an orifice (Dagan, Weinberg & Tamir 1982: a tube of radius a and length L
    conducts pi a^4 / (8 mu L) / (1 + 3 pi a / (8 L)), Poiseuille's duct and Sampson's orifice in series): the
    thesis' conductance divided by 1 + beta a / L, a the facet's equivalent radius sqrt(A_f / pi) ("area") or
    2 R_h ("hydraulic"). A short, wide throat is no longer conducting without bound as L / a falls."""
    a = np.sqrt(g["fluid_area"] / np.pi) if radius == "area" else 2.0 * g["hydraulic_radius"]
    return 0.5 * g["fluid_area"] * g["hydraulic_radius"] ** 2 / (g["length"] + beta * a)


def orifice(t, g, gamma=3.0):
    """The thesis' duct and Sampson's orifice in series as resistances: mu / k = mu L / (A_f R_h^2 / 2) +
    gamma mu / a^3, a = sqrt(A_f / pi) (Sampson: gamma = 3 for a circular hole in a thin wall)."""
    a3 = (g["fluid_area"] / np.pi) ** 1.5
    return 1.0 / (g["length"] / (0.5 * g["fluid_area"] * g["hydraulic_radius"] ** 2) + gamma / a3)


def clamped(k, low=1e-4, high=100.0):
    """The engine's clamp: k within [low, high] times the median (of the finite ones: a cospherical array has
    many flat pores, L = 0)."""
    m = np.median(k[np.isfinite(k)])
    return np.clip(k, low * m, high * m)


# The candidates: (short name, description, mu k of (throats, geometry)); phi = A_f / A.
TABLE = [
    ("thesis", "the thesis' A_f R_h^2 / (2 L)", thesis),
    ("r_c", "Poiseuille through the constriction", constriction),
    ("A_f/P", "the thesis' form with the facet's own hydraulic radius", facet_radius),
    ("Dagan", "entrance, beta = 3 pi / 8", entrance),
    ("β = 1", "entrance, beta = 1", lambda t, g: entrance(t, g, beta=1.0)),
    ("γ = 2", "orifice, gamma = 2", lambda t, g: orifice(t, g, gamma=2.0)),
    ("(1 − φ)", "thesis x (1 - A_f / A)", lambda t, g: thesis(t, g) * (1.0 - g["fluid_area"] / g["area"])),
    (
        "(1 − φ)^1.5",
        "thesis x (1 - A_f / A)^1.5",
        lambda t, g: thesis(t, g) * (1.0 - g["fluid_area"] / g["area"]) ** 1.5,
    ),
    (
        "β = 0.2, (1 − φ)",
        "entrance, beta = 0.2, x (1 - A_f / A)",
        lambda t, g: entrance(t, g, 0.2) * (1.0 - g["fluid_area"] / g["area"]),
    ),
]
# Regular arrays: (array, c) with the periodic reference's mesh limit (periodic_run's stored rows); the touching
# simple cubic array against Zick & Homsy's K = 42.1.
ARRAYS = [("sc", 0.45), ("bcc", 0.45), ("bcc", 0.6), ("fcc", 0.45), ("fcc", 0.6)]


def regular_cases():
    """(name, PFV run, geometry, kappa_ref) of the regular arrays (the unit cube of the lattice, which
    pfv_periodic.run tiles)."""
    make = {"sc": periodic_mesh.simple_cubic, "bcc": periodic_mesh.body_centred, "fcc": periodic_mesh.face_centred}
    rows = periodic_run.load(periodic_run.RESULTS)
    series = periodic_run.series(rows)
    out = []
    for array, c in ARRAYS:
        kappa = (
            2.0 * make[array](c)["radius_unshrunk"] ** 2 / (9.0 * c * periodic_run.limit(series[(array, c, 0.0)])[0])
        )
        out.append((array, c, kappa))
    touching = periodic_run.TOUCHING_SC
    out.append(("sc", touching, 2.0 * 0.25 / (9.0 * touching * periodic_run.ZICK_HOMSY_SC[0.5236])))
    cases = []
    for array, c, kappa in out:
        packing = make[array](c)
        model = pfv_periodic.run(packing)
        cases.append(("%s %.2f" % (array, c), model, throat_study.features(model, packing), kappa))
    return cases


def random_cases(paths):
    """(name, PFV run, geometry, kappa_FEM on the finest mesh) of the stored random packings."""
    rows = [r for path in paths for r in periodic_random.load(path)]
    cases = []
    for (name, shrink), row in periodic_random.finest(rows).items():
        d = throat_study.throat_data(row)
        label = name + ("@%g" % shrink if shrink else "")
        cases.append((label, d["model"], d["geometry"], row["kappa"]))
    for name, (limit, _, _) in periodic_random.touching(rows).items():
        packing = periodic_packings.load(name)
        model = pfv_periodic.run(packing)
        cases.append((name + " touching", model, throat_study.features(model, packing), limit))
    return cases


def ratios(cases):
    """{candidate: [kappa / kappa_ref per case]}."""
    out = {}
    for name, _, fn in TABLE:
        for _, model, geometry, kappa in cases:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                k = clamped(fn(model["throats"], geometry))
            value = pfv_periodic.network_kappa(model["throats"], k, model["n_cells"], model["volume"])[0] / kappa
            out.setdefault(name, []).append(value)
    return out


def table(cases, values):
    """Markdown: kappa / kappa_ref, one row per case, one column per candidate."""
    lines = ["| case | %s |" % " | ".join(name for name, _, _ in TABLE), "|---|%s" % ("---|" * len(TABLE))]
    for i, (case, _, _, _) in enumerate(cases):
        lines.append("| %s | %s |" % (case, " | ".join("%.3f" % values[name][i] for name, _, _ in TABLE)))
    return "\n".join(lines)


def summary(cases, values, n_regular):
    """Markdown: per candidate, the range of kappa / kappa_ref on the regular arrays and on the random cells."""
    lines = ["| candidate | regular arrays | random cells | max \\|ln κ / κ_ref\\| |", "|---|---|---|---|"]
    for name, description, _ in TABLE:
        v = np.array(values[name])
        lines.append(
            "| %s (%s) | %.3f – %.3f | %.3f – %.3f | %.3f |"
            % (
                name,
                description,
                v[:n_regular].min(),
                v[:n_regular].max(),
                v[n_regular:].min(),
                v[n_regular:].max(),
                np.abs(np.log(v)).max(),
            )
        )
    return "\n".join(lines)


def main():
    regular = regular_cases()
    cases = regular + random_cases([periodic_random.RESULTS, periodic_random.SMALL_RESULTS])
    values = ratios(cases)
    print(summary(cases, values, len(regular)))
    print()
    print(table(cases, values))
    return 0


if __name__ == "__main__":
    sys.exit(main())
