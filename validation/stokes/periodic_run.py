"""The periodic Stokes reference on the cubic arrays of spheres: resolution sweeps, Zick & Homsy, contacts, CI.

From the repository's root (Debian's /usr/bin/python3, with python3-dolfinx, python3-dolfinx-mpc, python3-gmsh):

    /usr/bin/python3 -m validation.stokes.periodic_run --array=sc --c=0.216,0.343,0.45 [--shrink=0] [--levels=...]
    /usr/bin/python3 -m validation.stokes.periodic_run --convergence [--out=FILE]
    /usr/bin/python3 -m validation.stokes.periodic_run --contact [--out=FILE]
    /usr/bin/python3 -m validation.stokes.periodic_run --report [--detail] [--out=FILE]
    /usr/bin/python3 -m validation.stokes.periodic_run --quick [--write-reference]

Arrays (periodic_mesh.py): ``sc`` (one sphere at the centre of the unit cube), ``sc_corner`` (the same array with
the sphere at the origin, cut into eight pieces by the faces: the periodic images' check), ``bcc`` and ``fcc``.
For every array, solid fraction c, contact shrink and sphere-surface element size of --levels (default LEVELS) it
meshes and solves the flow driven by |G| = 1 along x (periodic_solve.py; --solver: LDL^T up to
periodic_solve.DIRECT_LIMIT DOFs, MINRES above) and appends a row to --out (JSON): kappa, Zick & Homsy's
K = 2 a^2 / (9 c kappa) with a the radius before any shrink (F = 6 pi mu a K U, the force on each sphere, balances
|G| V_cell / n), the force balance and the solver's figures. Then it prints the tables: one row per case with K
at every level, its Richardson limit in the element size (report.py's, through the last three levels) and that
limit's distance from Zick & Homsy's Table 2 (simple cubic only: no body- or face-centred value of theirs was
checked, so those arrays are shown through their convergence alone); the contact table; with --detail first
every level's row (DOFs, solver, force balance, section flux, folded cells, solve time).

--convergence runs the sweep of the reference (SWEEP x LEVELS); --contact the touching simple cubic array
(c = pi/6) through the shrinks of doc/validation.md section 7 (every radius times 1 - s, s = 1, 0.5, 0.25 %),
each converged in the element size, extrapolated to s = 0 by Richardson in s; --report prints the tables of
--out only. Rows already in --out are not recomputed. The default --out is
validation/stokes/data/periodic_reference.json, the stored reference.

--quick runs the CI case (simple cubic, c = 0.45, one coarse mesh, the sphere at the centre and at the origin,
LDL^T and MINRES) and compares it with tests/data/stokes_periodic_quick.json (--write-reference rewrites it).
"""
import argparse
import importlib.metadata
import json
import os
import resource
import sys
import time

import dolfinx
import gmsh
import numpy as np

from . import mesh as walled_mesh
from . import periodic_mesh, periodic_solve
from .report import MIN_SHRINK_ORDER, check_stored, richardson

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
RESULTS = os.path.join(HERE, "data", "periodic_reference.json")
QUICK_REFERENCE = os.path.join(ROOT, "tests", "data", "stokes_periodic_quick.json")

# Zick & Homsy (1982), Table 2, simple cubic array: c -> K (F = 6 pi mu a K U per sphere, U superficial)
ZICK_HOMSY_SC = {0.027: 2.008, 0.064: 2.810, 0.125: 4.292, 0.216: 7.442, 0.343: 15.4, 0.45: 28.1, 0.5236: 42.1}
TOUCHING_SC = np.pi / 6.0  # Zick & Homsy's 0.5236

LEVELS = (0.06, 0.045, 0.034, 0.025)
ARRAYS = ("sc", "sc_corner", "bcc", "fcc")
SWEEP = (
    [("sc", c) for c in (0.027, 0.064, 0.125, 0.216, 0.343, 0.45)]
    + [("sc_corner", 0.45)]
    + [("bcc", c) for c in (0.216, 0.343, 0.45, 0.6)]
    + [("fcc", c) for c in (0.216, 0.343, 0.45, 0.6)]
)
SHRINKS = (0.01, 0.005, 0.0025)
QUICK = {"c": 0.45, "surface": 0.07}


def packing(array, c, shrink=0.0):
    """The packing of one of ARRAYS."""
    if array == "sc":
        return periodic_mesh.simple_cubic(c, shrink)
    if array == "sc_corner":
        return periodic_mesh.simple_cubic(c, shrink, corner=True)
    if array == "bcc":
        return periodic_mesh.body_centred(c, shrink)
    if array == "fcc":
        return periodic_mesh.face_centred(c, shrink)
    raise ValueError("unknown array " + array)


def zick_homsy(array, c):
    """Zick & Homsy's K for the simple cubic array at c (either sphere placement), else None."""
    if array not in ("sc", "sc_corner"):
        return None
    for key, value in ZICK_HOMSY_SC.items():
        if abs(key - c) < 5e-5:
            return value
    return None


def run_one(array, c, shrink, surface, solver="auto"):
    """One mesh and solve: the row of the results file."""
    p = packing(array, c, shrink)
    start = time.perf_counter()
    msh, _, facets = periodic_mesh.build(p, surface)
    meshed = time.perf_counter() - start
    r = periodic_solve.solve(msh, facets, p, method=solver)
    a = p["radius_unshrunk"]
    flow = [{key: f[key][0] for key in ("pressure", "viscous", "gradient", "total")} for f in r.pop("forces").values()]
    return {
        "array": array,
        "c": c,
        "shrink": shrink,
        "surface": surface,
        "radius": a,
        "K": 2.0 * a**2 / (9.0 * c * r["kappa"]),
        "K_zick_homsy": zick_homsy(array, c),
        "folded_cells": walled_mesh.tangled_cells(msh),
        "seconds_mesh": meshed,
        # the process's peak so far: over a sweep, the largest case's (or the mesher's) up to this row
        "peak_rss_gb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2**20,
        "versions": versions(),
        "sphere_forces_x": flow,  # every sphere's force parts along the flow
        **r,
    }


def versions():
    """The versions of the Debian packages the row was computed with."""
    try:
        mpc = importlib.metadata.version("dolfinx_mpc")
    except importlib.metadata.PackageNotFoundError:
        mpc = "unknown"
    return {"dolfinx": dolfinx.__version__, "dolfinx_mpc": mpc, "gmsh": gmsh.__version__}


def key_of(row):
    return (row["array"], round(row["c"], 6), row["shrink"], row["surface"])


def run_cases(cases, levels, out, solver="auto", log=print):
    """Every (array, c, shrink) of `cases` at every level, appended to `out` as it goes; rows already there
    are kept, not recomputed."""
    rows = load(out)
    done = {key_of(r) for r in rows}
    for array, c, shrink in cases:
        for surface in levels:
            if (array, round(c, 6), shrink, surface) in done:
                continue
            row = run_one(array, c, shrink, surface, solver)
            rows.append(row)
            save(rows, out)
            log(
                "%-9s c %.4f shrink %.4f  h %.3f  dofs %8d  kappa %.6e  K %.4f  balance %.1e  %s %.0f s  %.1f GB"
                % (
                    array,
                    c,
                    shrink,
                    surface,
                    row["dofs"],
                    row["kappa"],
                    row["K"],
                    row["balance"],
                    row["solver"],
                    row["seconds_solve"],
                    row["peak_rss_gb"],
                ),
                flush=True,
            )
    return rows


def load(path):
    if not os.path.exists(path):
        return []
    with open(path) as f:
        return json.load(f)


def save(rows, path, indent=1):
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    with open(path, "w") as f:
        json.dump(rows, f, indent=indent)


def series(rows):
    """{(array, c, shrink): rows sorted from the coarsest level to the finest}."""
    out = {}
    for r in rows:
        out.setdefault((r["array"], round(r["c"], 6), r["shrink"]), []).append(r)
    order = sorted(out, key=lambda k: (ARRAYS.index(k[0]), k[1], -k[2]))
    return {k: sorted(out[k], key=lambda r: -r["surface"]) for k in order}


def reference_of(levels):
    """Zick & Homsy's K for a case's table rows; none for a shrunk geometry, which the contact table compares."""
    return levels[0]["K_zick_homsy"] if levels[0]["shrink"] == 0 else None


def limit(levels):
    """(K at h -> 0, observed order): Richardson through the last three levels, nan with fewer."""
    if len(levels) < 3:
        return float("nan"), float("nan")
    return richardson([r["surface"] for r in levels], [r["K"] for r in levels])


def percent(x):
    return "%+.2f %%" % (100 * x) if x is not None and np.isfinite(x) else ""


def convergence_table(rows):
    """Markdown: every level of every case, then its Richardson limit, against Zick & Homsy."""
    lines = [
        "| array | c | shrink | h | DOFs | solver | κ / l0² | K | change | K / K_Z&H − 1 | balance | "
        "section flux − 1 | folded | solve (s) |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for (array, c, shrink), levels in series(rows).items():
        previous = None
        ref = reference_of(levels)
        for r in levels:
            change = r["K"] / previous - 1 if previous else None
            previous = r["K"]
            lines.append(
                "| %s | %.4g | %g | %.3f | %d | %s | %.5e | %.4f | %s | %s | %.1e | %.1e | %d | %.0f |"
                % (
                    array,
                    c,
                    shrink,
                    r["surface"],
                    r["dofs"],
                    r["solver"],
                    r["kappa"],
                    r["K"],
                    percent(change),
                    percent(r["K"] / ref - 1 if ref else None),
                    r["balance"],
                    r["section_flux_error"],
                    r["folded_cells"],
                    r["seconds_solve"],
                )
            )
        k0, order = limit(levels)
        if np.isfinite(k0):
            lines.append(
                "| %s | %.4g | %g | → 0 | | | %.5e | %.4f | q = %.1f, finest %s | %s | | | | |"
                % (
                    array,
                    c,
                    shrink,
                    2.0 * levels[0]["radius"] ** 2 / (9.0 * c * k0),
                    k0,
                    order,
                    percent(levels[-1]["K"] / k0 - 1),
                    percent(k0 / ref - 1 if ref else None),
                )
            )
    return "\n".join(lines)


def summary_table(rows):
    """Markdown, one row per case: K at every level, its Richardson limit against Zick & Homsy, and the finest
    level's DOFs and force balance."""
    levels = sorted({r["surface"] for r in rows}, reverse=True)
    lines = [
        "| array | c | shrink | %s | K (h → 0) | order q | finest − limit | K_Z&H | limit / K_Z&H − 1 "
        "| κ (h → 0) / l0² | DOFs, finest | balance, finest |" % " | ".join("K, h = %g" % h for h in levels),
        "|---|---|---|%s---|---|---|---|---|---|---|---|" % ("---|" * len(levels)),
    ]
    for (array, c, shrink), case in series(rows).items():
        by_h = {r["surface"]: r["K"] for r in case}
        k0, order = limit(case)
        ref = reference_of(case)
        finest = case[-1]
        lines.append(
            "| %s | %.4g | %g | %s | %.4f | %.1f | %s | %s | %s | %.5e | %d | %.1e |"
            % (
                array,
                c,
                shrink,
                " | ".join("%.4f" % by_h[h] if h in by_h else "" for h in levels),
                k0,
                order,
                percent(finest["K"] / k0 - 1),
                ref or "",
                percent(k0 / ref - 1 if ref else None),
                2.0 * finest["radius"] ** 2 / (9.0 * c * k0),
                finest["dofs"],
                finest["balance"],
            )
        )
    return "\n".join(lines)


def contact_table(rows):
    """Markdown: the shrink series of every touching case, each shrink's Richardson limit in h, and the limit
    at zero shrink (Richardson in s through the three smallest shrinks) with its spread, the distance from the
    straight line through the two smallest shrinks (report.contact_rows's measure), and its kappa."""
    by_case, radius = {}, {}
    for (array, c, shrink), levels in series(rows).items():
        if shrink > 0:
            by_case.setdefault((array, c), {})[shrink] = limit(levels)[0]
            radius[(array, c)] = levels[0]["radius"]
    lines = [
        "| array | c | %s | touching (s → 0) | κ touching / l0² | K_Z&H | touching / K_Z&H − 1 |"
        % " | ".join("K at s = %g %%" % (100 * s) for s in SHRINKS),
        "|---|---|%s---|---|---|---|" % ("---|" * len(SHRINKS)),
    ]
    for (array, c), values in by_case.items():
        shrinks = sorted((s for s in values if np.isfinite(values[s])), reverse=True)
        cells = ["%.4f" % values[s] if s in values else "" for s in SHRINKS]
        touching, note = float("nan"), "fewer than three shrinks"
        if len(shrinks) >= 3:
            k = [values[s] for s in shrinks]
            touching, order = richardson(shrinks, k, MIN_SHRINK_ORDER)
            line = k[-1] - (k[-2] - k[-1]) * shrinks[-1] / (shrinks[-2] - shrinks[-1])
            note = "%.3f (q = %.2f, ± %.2f %%)" % (touching, order, 100 * abs(line / touching - 1))
        ref = zick_homsy(array, c)
        lines.append(
            "| %s | %.4f | %s | %s | %.5e | %s | %s |"
            % (
                array,
                c,
                " | ".join(cells),
                note,
                2.0 * radius[(array, c)] ** 2 / (9.0 * c * touching),
                ref or "",
                percent(touching / ref - 1 if ref else None),
            )
        )
    return "\n".join(lines)


def quick_numbers():
    """The CI case: simple cubic at c = 0.45 on one coarse mesh, centred (LDL^T and MINRES) and at the origin."""
    c, h = QUICK["c"], QUICK["surface"]
    out = {"c": c, "surface": h}
    for name, array, solver in (
        ("centre", "sc", "direct"),
        ("minres", "sc", "minres"),
        ("corner", "sc_corner", "direct"),
    ):
        r = run_one(array, c, 0.0, h, solver)
        keys = ("kappa", "K", "dofs", "balance", "balance_total", "volume_error", "section_flux_error", "folded_cells")
        out[name] = {key: r[key] for key in keys}
        out[name]["cells"] = r["cells"]
    return out


def compare_quick(now, ref):
    """Rows (what, value, expected, ok): each case's kappa against the stored value of the same mesh (1e-6) and
    against Zick & Homsy (2 %), the force balance (1 %), the two placements of the sphere against each other
    (0.5 %: different meshes of one geometry), MINRES against LDL^T (1e-8)."""
    k_zh = ZICK_HOMSY_SC[QUICK["c"]]
    rows = []
    for name in ("centre", "corner"):
        a, b = now[name], ref[name]
        rows.append(("DOFs, " + name, a["dofs"], b["dofs"], a["dofs"] == b["dofs"]))
        rows.append(("kappa, " + name, a["kappa"], b["kappa"], abs(a["kappa"] / b["kappa"] - 1) < 1e-6))
        rows.append(("K / K_Zick-Homsy - 1, " + name, a["K"] / k_zh - 1, 0.02, abs(a["K"] / k_zh - 1) < 0.02))
        rows.append(("|sum F + G V_cell| / (|G| V_cell), " + name, a["balance_total"], 0.01, a["balance_total"] < 0.01))
        rows.append(
            (
                "folded cells / cells, " + name,
                a["folded_cells"] / a["cells"],
                1e-3,
                a["folded_cells"] <= 1e-3 * a["cells"],
            )
        )
    corner = now["corner"]["kappa"] / now["centre"]["kappa"] - 1
    rows.append(("kappa corner / centre - 1", corner, 0.005, abs(corner) < 0.005))
    minres = now["minres"]["kappa"] / now["centre"]["kappa"] - 1
    rows.append(("kappa MINRES / LDL^T - 1", minres, 1e-8, abs(minres) < 1e-8))
    return rows


def quick(write_reference):
    return check_stored(quick_numbers(), QUICK_REFERENCE, compare_quick, write_reference)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--array", default="sc", help="sc, sc_corner, bcc or fcc")
    ap.add_argument("--c", default="0.216,0.343,0.45", help="solid fractions (before the shrink)")
    ap.add_argument("--shrink", default="0", help="contact shrinks s: every radius times 1 - s")
    ap.add_argument("--levels", default=",".join(str(h) for h in LEVELS), help="sphere-surface element sizes")
    ap.add_argument("--solver", choices=("auto", "direct", "minres"), default="auto")
    ap.add_argument("--out", default=RESULTS)
    ap.add_argument("--convergence", action="store_true", help="the reference's resolution sweep (SWEEP x LEVELS)")
    ap.add_argument("--contact", action="store_true", help="touching simple cubic array by shrink and extrapolation")
    ap.add_argument("--report", action="store_true", help="print the tables of --out only")
    ap.add_argument("--detail", action="store_true", help="also the table of every level")
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--write-reference", action="store_true")
    args = ap.parse_args()
    if args.quick:
        return quick(args.write_reference)
    levels = [float(x) for x in args.levels.split(",")]
    if args.convergence:
        cases = [(array, c, 0.0) for array, c in SWEEP]
    elif args.contact:
        cases = [("sc", TOUCHING_SC, s) for s in SHRINKS]
    else:
        cases = [(args.array, float(c), float(s)) for c in args.c.split(",") for s in args.shrink.split(",")]
    rows = load(args.out) if args.report else run_cases(cases, levels, args.out, args.solver)
    if args.detail:
        print(convergence_table(rows))
        print()
    print(summary_table(rows))
    print()
    print(contact_table(rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
