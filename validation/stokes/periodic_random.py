"""The periodic Stokes reference on the random packings of periodic_packings.py, and PFV's throats against it.

    export PYTHONPATH=$BUILD/python OMP_NUM_THREADS=1
    /usr/bin/python3 -m validation.stokes.periodic_random --packings=dense_mono_s1 [--levels=...] [--out=FILE]
    /usr/bin/python3 -m validation.stokes.periodic_random --report [--out=FILE]

For every packing, contact shrink and element size (sphere surface, periodic_mesh.py's `surface`) it meshes the
periodic cell, solves the Stokes flow driven by |G| = 1 along x (periodic_solve.py) and appends a row to --out:
kappa_xx, the solver's figures, and the flux through every throat of PFV's regular triangulation of the same
(shrunk) spheres (facet_flux.py), with PFV's own flux and geometry of that throat beside it (pfv_periodic.py).
Packings with contacts (gap 0) are solved at the shrinks of doc/validation.md section 7 and extrapolated to
touching; packings with a gap at every pair are solved as they are. Rows already in --out are not recomputed.
"""
import argparse
import os
import resource
import sys
import time

import numpy as np

from . import facet_flux, periodic_mesh, periodic_packings, periodic_run, periodic_solve, pfv_periodic
from .mesh import tangled_cells
from .packings import shrunk
from .report import MIN_SHRINK_ORDER, check_stored, richardson

HERE = os.path.dirname(os.path.abspath(__file__))
RESULTS = os.path.join(HERE, "data", "periodic_random.json")
SMALL_RESULTS = os.path.join(HERE, "data", "periodic_small.json")  # the 16-sphere cells
LEVELS = (0.045, 0.034, 0.025)
SHRINKS = (0.01, 0.005, 0.0025)
# Elements across a gap between two spheres (periodic_mesh's gap_elements): unfolded meshes at the contacts
GAP_ELEMENTS = 1.0
QUICK = {"packing": "small_mono_c40_s11", "surface": 0.1}
QUICK_REFERENCE = os.path.join(os.path.dirname(os.path.dirname(HERE)), "tests", "data", "stokes_random_quick.json")


def shrinks_of(packing):
    return SHRINKS if packing["gap"] == 0 else (0.0,)


def run_one(name, shrink, surface, solver="auto"):
    """One mesh, one solve, the throat fluxes: the row of the results file."""
    p = shrunk(periodic_packings.load(name), shrink) if shrink else periodic_packings.load(name)
    model = pfv_periodic.run(p)
    start = time.perf_counter()
    msh, _, facets = periodic_mesh.build(p, surface, gap_elements=GAP_ELEMENTS)
    meshed = time.perf_counter() - start
    keep = {}
    r = periodic_solve.solve(msh, facets, p, method=solver, keep=keep)
    print(
        "%s shrink %g h %g: kappa %.6e, %d DOFs, %s %d iterations, %.0f s"
        % (name, shrink, surface, r["kappa"], r["dofs"], r["solver"], r["iterations"], r["seconds_solve"]),
        flush=True,
    )
    t = model["throats"]
    area = np.linalg.norm(t["area_vector"], axis=1)
    normals = t["area_vector"] / area[:, None]
    start = time.perf_counter()
    q, missing = facet_flux.fluxes(msh, keep["u"], t["triangle"], normals, p["centres"], p["radii"], p["cell"], surface)
    r.pop("forces")
    pore_pressure = facet_flux.pressure_at(msh, keep["p"], model["power_centres"], (-1.0, 0.0, 0.0), p["cell"])
    return {
        "packing": name,
        "shrink": shrink,
        "surface": surface,
        "n_spheres": len(p["radii"]),
        "folded_cells": tangled_cells(msh),
        "seconds_mesh": meshed,
        "seconds_throats": time.perf_counter() - start,
        "peak_rss_gb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2**20,
        "kappa_pfv": model["kappa"],
        "n_pores": model["n_cells"],
        "throat_vertices": t["vertices"].tolist(),
        "throat_flux_fem": q.tolist(),
        "throat_flux_pfv": t["flux"].tolist(),
        "throat_points_missed": int(missing),
        "throat_imbalance": facet_flux.imbalance(t["cells"], q, model["n_cells"]),
        "pore_pressure_fem": pore_pressure.tolist(),  # at PFV's power centres, NaN where in no element
        "pore_pressure_pfv": model["pressure"].tolist(),
        **r,
    }


def quick_numbers():
    """The CI case: QUICK's packing on one coarse mesh, kappa and its throats."""
    row = run_one(QUICK["packing"], 0.0, QUICK["surface"])
    packing = periodic_packings.load(QUICK["packing"])
    model = pfv_periodic.run(packing)
    t = model["throats"]
    branch = t["power_centre_1"] - t["power_centre_0"]
    u = np.asarray(row["throat_flux_fem"]) @ branch / model["volume"]  # (1 / V) sum q d
    keys = ("kappa", "kappa_pfv", "dofs", "cells", "folded_cells", "throat_imbalance", "throat_points_missed")
    out = {key: row[key] for key in keys}
    out["kappa_from_throats"] = float(u[0])
    # PFV's own throat fluxes give its mean velocity exactly (the engine's definition of U)
    out["kappa_pfv_from_throats"] = float((t["flux"] @ branch)[0] / model["volume"])
    # every pair of spheres has a gap, so every throat has an open constriction (r_c > 0), no larger than the
    # spheres are apart
    r_c = t["constriction_radius"]
    edges = np.linalg.norm(t["triangle"] - np.roll(t["triangle"], 1, axis=1), axis=2).max(1)
    out["constriction_min_over_radius"] = float((r_c / t["radii"].mean(1)).min())
    out["constriction_max_over_edge"] = float((r_c / edges).max())
    out["packing_c"] = float(4.0 / 3.0 * np.pi * (packing["radii"] ** 3).sum())
    out["packing_min_gap"] = periodic_packings.min_gap(packing)
    return out


def compare_quick(now, ref):
    """Rows (what, value, expected, ok): the mesh and kappa as stored (DOFs exactly, kappa to 1e-6, PFV's
    kappa to 1e-9), the throat fluxes' mean velocity within 1 % of the FEM's (0.2-0.5 % measured), the fluxes out
    of each pore balanced to 1 % (their quadrature error), no fold, the packing's solid fraction and gap."""
    return [
        ("DOFs", now["dofs"], ref["dofs"], now["dofs"] == ref["dofs"]),
        ("kappa FEM", now["kappa"], ref["kappa"], abs(now["kappa"] / ref["kappa"] - 1) < 1e-6),
        ("kappa PFV", now["kappa_pfv"], ref["kappa_pfv"], abs(now["kappa_pfv"] / ref["kappa_pfv"] - 1) < 1e-9),
        (
            "kappa from the throat fluxes / kappa - 1",
            now["kappa_from_throats"] / now["kappa"] - 1,
            0.01,
            abs(now["kappa_from_throats"] / now["kappa"] - 1) < 0.01,
        ),
        ("pore flux imbalance", now["throat_imbalance"], 0.01, now["throat_imbalance"] < 0.01),
        (
            "PFV: kappa from its throat fluxes / kappa - 1",
            now["kappa_pfv_from_throats"] / now["kappa_pfv"] - 1,
            1e-12,
            abs(now["kappa_pfv_from_throats"] / now["kappa_pfv"] - 1) < 1e-12,
        ),
        (
            "min r_c / mean radius over the throats",
            now["constriction_min_over_radius"],
            0.0,
            now["constriction_min_over_radius"] > 0.0,
        ),
        ("max r_c / longest edge", now["constriction_max_over_edge"], 1.0, now["constriction_max_over_edge"] < 1.0),
        ("folded cells", now["folded_cells"], 0, now["folded_cells"] <= 1e-3 * now["cells"]),
        ("packing solid fraction", now["packing_c"], 0.4, abs(now["packing_c"] - 0.4) < 1e-6),
        ("packing min gap / (r_i + r_j)", now["packing_min_gap"], 0.03, now["packing_min_gap"] > 0.03 - 1e-6),
    ]


def key_of(row):
    return (row["packing"], row["shrink"], row["surface"])


def run_cases(names, levels, out, solver="auto", log=print):
    rows = load(out)
    done = {key_of(r) for r in rows}
    for name in names:
        packing = periodic_packings.load(name)
        for shrink in shrinks_of(packing):
            for surface in levels:
                if (name, shrink, surface) in done:
                    continue
                row = run_one(name, shrink, surface, solver)
                rows.append(row)
                save(rows, out)
                log(
                    "%-14s shrink %.4f h %.3f dofs %8d kappa %.5e pfv/fem %.3f imbalance %.1e %s %.0f s %.1f GB"
                    % (
                        name,
                        shrink,
                        surface,
                        row["dofs"],
                        row["kappa"],
                        row["kappa_pfv"] / row["kappa"],
                        row["throat_imbalance"],
                        row["solver"],
                        row["seconds_solve"],
                        row["peak_rss_gb"],
                    ),
                    flush=True,
                )
    return rows


def load(path):
    return periodic_run.load(path)


def save(rows, path):
    periodic_run.save(rows, path, indent=None)  # the throat arrays: one line each


def finest(rows):
    """{(packing, shrink): the row of its finest mesh}."""
    out = {}
    for r in rows:
        key = (r["packing"], r["shrink"])
        if key not in out or r["surface"] < out[key]["surface"]:
            out[key] = r
    return out


def touching(rows):
    """{packing: (kappa at zero shrink, observed order, spread)} for the packings with contacts computed at every
    shrink of SHRINKS, from each shrink's finest mesh: Richardson in the shrink as doc/validation.md section 7, the
    spread being the limit's distance from the straight line through the two smallest shrinks."""
    best = finest(rows)
    out = {}
    for name in sorted({n for n, s in best if s > 0}):
        if not all((name, s) in best for s in SHRINKS):
            continue
        k = [best[(name, s)]["kappa"] for s in SHRINKS]
        limit, order = richardson(list(SHRINKS), k, MIN_SHRINK_ORDER)
        line = k[-1] - (k[-2] - k[-1]) * SHRINKS[-1] / (SHRINKS[-2] - SHRINKS[-1])
        out[name] = (limit, order, abs(line / limit - 1))
    return out


def report(rows):
    """Markdown, one row per packing and shrink: kappa_FEM at every element size, the finest level's change from
    the one before, its Richardson limit where three levels exist, and PFV's kappa over the finest (or the
    limit)."""
    by = {}
    for r in rows:
        by.setdefault((r["packing"], r["shrink"]), []).append(r)
    lines = [
        "| packing | spheres | c | shrink | κ_FEM at h = … | last change | κ_FEM (h → 0) | DOFs, finest "
        "| κ_PFV / κ_FEM |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for (name, shrink), levels in by.items():
        levels.sort(key=lambda r: -r["surface"])
        packing = periodic_packings.load(name)
        change = levels[-1]["kappa"] / levels[-2]["kappa"] - 1 if len(levels) > 1 else float("nan")
        limit = (
            richardson([r["surface"] for r in levels[-3:]], [r["kappa"] for r in levels[-3:]])[0]
            if len(levels) >= 3
            else float("nan")
        )
        best = limit if np.isfinite(limit) else levels[-1]["kappa"]
        lines.append(
            "| %s | %d | %.2f | %g | %s | %s | %s | %d | %.3f |"
            % (
                name,
                len(packing["radii"]),
                packing["c"],
                shrink,
                ", ".join("%.4e (%g)" % (r["kappa"], r["surface"]) for r in levels),
                "%+.2f %%" % (100 * change) if np.isfinite(change) else "",
                "%.4e" % limit if np.isfinite(limit) else "",
                levels[-1]["dofs"],
                levels[-1]["kappa_pfv"] / best,
            )
        )
    for name, (limit, order, spread) in touching(rows).items():
        packing = periodic_packings.load(name)
        kappa_pfv = pfv_periodic.run(packing)["kappa"]  # on the touching spheres themselves
        lines.append(
            "| %s | %d | %.2f | → 0 | touching: q = %.2f, ± %.2f %% | | %.4e | | %.3f |"
            % (name, len(packing["radii"]), packing["c"], order, 100 * spread, limit, kappa_pfv / limit)
        )
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--packings", default=",".join(periodic_packings.PACKINGS))
    ap.add_argument("--levels", default=",".join(str(h) for h in LEVELS))
    ap.add_argument("--solver", choices=("auto", "direct", "minres"), default="auto")
    ap.add_argument("--out", default=RESULTS)
    ap.add_argument("--report", action="store_true")
    ap.add_argument("--quick", action="store_true", help="the CI case against " + QUICK_REFERENCE)
    ap.add_argument("--write-reference", action="store_true")
    args = ap.parse_args()
    if args.quick:
        return check_stored(quick_numbers(), QUICK_REFERENCE, compare_quick, args.write_reference)
    levels = [float(x) for x in args.levels.split(",")]
    rows = load(args.out) if args.report else run_cases(args.packings.split(","), levels, args.out, args.solver)
    print(report(rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
