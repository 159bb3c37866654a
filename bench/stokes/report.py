"""Tables and figure of the Stokes comparison from run.py's JSON (doc/validation.md section 7).

    /usr/bin/python3 bench/stokes/report.py [--results=FILE] [--figure=doc/figures/stokes-kappa.png]

Prints Markdown: the mesh-convergence table of every case, the permeability table (FEM at the
finest mesh, its Richardson estimate, PFV's three wall variants and YADE's engine, with the
ratios to FEM), and the force table of the 9-sphere packing at d/D = 0.72 beside thesis
Table 3.2. The figure plots kappa_PFV / kappa_FEM against d/D and per packing.
"""
import argparse
import json
import os

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))

# thesis Table 3.2 (no-slip lateral faces, forces / (S dP)): FEM, PFV
THESIS_TABLE_3_2 = {
    "big sphere, viscous y": (1.51e-2, 1.06e-2), "big sphere, pressure y": (9.09e-2, 9.64e-2),
    "big sphere, total y": (1.06e-1, 1.07e-1), "small sphere, viscous y": (9.38e-3, 5.83e-3),
    "small sphere, pressure y": (5.17e-2, 5.72e-2), "small sphere, total y": (6.04e-2, 6.30e-2),
    "boundary x=0, viscous y": (2.27e-2, 2.03e-2), "boundary x=0, pressure x": (4.98e-1, 5.00e-1),
    "solid phase, total y": (1 - 5.56e-4, 1 + 1.18e-4),
}


# (model key, FEM key, label) of the ratios kappa_model / kappa_FEM reported, same lateral condition
RATIOS = (("pfv_slip", "fem_sym", "PFV slip, thesis formula"), ("pfv_slip_yade", "fem_sym", "PFV slip, YADE factor"),
          ("yade_slip", "fem_sym", "YADE slip"), ("pfv_noslip", "fem_noslip", "PFV no-slip"),
          ("yade_noslip", "fem_noslip", "YADE no-slip"))

# the thesis' mean kappa_HR / kappa_FEM over its packings (section 3.5.3, Fig. 3.12)
THESIS_MEAN = {"symmetry": 1.01, "noslip": 0.78}


def observed_order(s, k):
    """The order q of kappa(s) = kappa_inf - C s^q through three levels (any refinement ratios):
    the root of (k3 - k2) / (k2 - k1) = (s2^q - s3^q) / (s1^q - s2^q), by bisection on
    [0.1, 8]; nan when the changes do not shrink monotonically."""
    ratio = (k[2] - k[1]) / (k[1] - k[0])
    if not 0 < ratio < 1:
        return float("nan")

    def g(q):
        return (s[1] ** q - s[2] ** q) / (s[0] ** q - s[1] ** q) - ratio

    lo, hi = 0.1, 8.0
    if g(lo) * g(hi) > 0:
        return float("nan")
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if g(lo) * g(mid) > 0 else (lo, mid)
    return 0.5 * (lo + hi)


MIN_ORDER = 1.0  # observed convergence order below which no Richardson estimate is made (fem_estimate)


def fem_estimate(levels, lateral):
    """(finest kappa, change from the previous level, Richardson estimate with the observed
    order of the last three levels, that order). No estimate below MIN_ORDER: Taylor-Hood gives
    kappa at order 2 or more once the throats are resolved, and a lower observed order means the
    meshes are not yet in that range, where the extrapolation would be a guess."""
    k = [lv[lateral]["kappa"] for lv in levels]
    s = [lv["surface"] for lv in levels]
    if len(k) < 2:
        return k[-1], float("nan"), float("nan"), float("nan")
    change = k[-1] / k[-2] - 1
    extrapolated, order = richardson(s, k) if len(k) >= 3 else (float("nan"), float("nan"))
    return k[-1], change, extrapolated, order


def richardson(s, k, min_order=MIN_ORDER):
    """(value at s = 0, observed order) through the last three of k(s); no value (nan) below
    min_order or when the changes do not shrink monotonically."""
    order = observed_order(s[-3:], k[-3:])
    if not (np.isfinite(order) and order >= min_order):
        return float("nan"), order
    c = (k[-1] - k[-2]) / (s[-2] ** order - s[-1] ** order)
    return k[-1] + c * s[-1] ** order, order


def balance(solution):
    """|Q_in - Q_out| / Q of one FEM solution: Taylor-Hood is not locally conservative, and a mesh
    too coarse for the throats shows it first here."""
    return abs(solution["flux_in"] - solution["flux_out"]) / abs(solution["kappa"])


def convergence_table(results):
    lines = ["| case | surface size | DOFs | folded cells | κ_FEM sym | change | κ_FEM no-slip | change "
             "| solve (s) sym / no-slip | \\|Q_in − Q_out\\| / Q sym / no-slip |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for r in results:
        prev = None
        for lv in r["fem"]:
            s, n = lv["symmetry"], lv["noslip"]
            cs = "" if prev is None else "%+.2f %%" % (100 * (s["kappa"] / prev[0] - 1))
            cn = "" if prev is None else "%+.2f %%" % (100 * (n["kappa"] / prev[1] - 1))
            folded = "%d of %s" % (lv["tangled_cells"], "{:,}".format(s["cells"]).replace(",", " ")) \
                if "tangled_cells" in lv else "–"
            lines.append("| %s | %.3f | %s | %s | %.4e | %s | %.4e | %s | %.0f / %.0f | %.1e / %.1e |" % (
                r["case"], lv["surface"], "{:,}".format(s["dofs"]).replace(",", " "), folded, s["kappa"], cs,
                n["kappa"], cn, s["seconds_solve"], n["seconds_solve"], balance(s), balance(n)))
            prev = (s["kappa"], n["kappa"])
        if len(r["fem"]) >= 3:
            cells = []
            for lateral in ("symmetry", "noslip"):
                finest, _, estimate, order = fem_estimate(r["fem"], lateral)
                if np.isfinite(estimate):
                    cells += ["%.4e" % estimate, "q = %.1f, finest %+.2f %%" % (order, 100 * (finest / estimate - 1))]
                elif np.isfinite(order):
                    cells += ["–", "q = %.2f, pre-asymptotic" % order]
                else:
                    cells += ["–", "no monotone order"]
            lines.append("| %s | → 0 (Richardson) | | | %s | %s | %s | %s | | |" % ((r["case"],) + tuple(cells)))
    return "\n".join(lines)


def yade_kappa(r, variant):
    y = r.get("yade") or {}
    v = (y.get(variant) or {}).get("kappa")
    return float("nan") if v is None else v


RESOLVED = 0.01  # |Q_in - Q_out| / Q of the finest mesh below which a case enters the comparison


def unresolved(results):
    return [r["case"] for r in results if max(balance(r["fem"][-1][lat]) for lat in ("symmetry", "noslip")) > RESOLVED]


def kappa_rows(results):
    rows = []
    for r in results:
        if r["case"] in unresolved(results):
            continue
        ks, _, es, _ = fem_estimate(r["fem"], "symmetry")
        kn, _, en, _ = fem_estimate(r["fem"], "noslip")
        rows.append({
            "case": r["case"], "n": r["n"], "porosity": r["porosity"], "shrink": r["shrink"],
            # the reference: the Richardson estimate where three levels give one, else the finest mesh
            "fem_sym": es if np.isfinite(es) else ks, "fem_noslip": en if np.isfinite(en) else kn,
            "fem_sym_finest": ks, "fem_noslip_finest": kn,
            "pfv_noslip": r["pfv"]["noslip"]["kappa"], "pfv_slip": r["pfv"]["slip"]["kappa"],
            "pfv_slip_yade": r["pfv"]["slip_yade"]["kappa"],
            "yade_noslip": yade_kappa(r, "noslip"), "yade_slip": yade_kappa(r, "slip")})
    return rows


def kappa_table(rows):
    lines = ["| case | porosity | κ_FEM sym | PFV slip, thesis / FEM | PFV slip, YADE factor / FEM "
             "| YADE slip / FEM | κ_FEM no-slip | PFV no-slip / FEM | YADE no-slip / FEM |",
             "|---|---|---|---|---|---|---|---|---|"]
    for w in rows:
        sym, ns = w["fem_sym"], w["fem_noslip"]
        lines.append("| %s | %.3f | %.4e | **%.3f** | %.3f | %.3f | %.4e | %.3f | %.3f |" % (
            w["case"], w["porosity"], sym, w["pfv_slip"] / sym, w["pfv_slip_yade"] / sym, w["yade_slip"] / sym,
            ns, w["pfv_noslip"] / ns, w["yade_noslip"] / ns))
    return "\n".join(lines)


def summary(rows):
    """kappa / kappa_FEM per model over the regular packings (cubic and 9-sphere: cospherical, every
    cell's power centre shared) and over the random ones, the shrink variants left out."""
    groups = (("regular", lambda c: not c.startswith("random")), ("random", lambda c: c.startswith("random")))
    out = []
    for key, ref, label in RATIOS:
        for group, member in groups:
            q = np.array([w[key] / w[ref] for w in rows if "@" not in w["case"] and member(w["case"])])
            q = q[np.isfinite(q)]
            if len(q):
                worst = q[np.argmax(np.abs(q - 1))]
                out.append("| %s | %s | %.3f | %.1f %% | %.3f | %d |" % (
                    label, group, q.mean(), 100 * np.mean(np.abs(q - 1)), worst, len(q)))
    return "\n".join(["| κ / κ_FEM | packings | mean | mean \\|κ/κ_FEM − 1\\| | furthest from 1 | cases |",
                      "|---|---|---|---|---|---|"] + out)


def forces_072(results):
    r = next((x for x in results if x["case"] == "centred9_0.72"), None)
    if r is None:
        return ""
    fem = r["fem"][-1]["noslip"]["forces"]
    pfv = r["pfv"]["noslip"]["forces"]

    def parts(f, name, part, axis):
        if part == "total":
            return f[name]["pressure"][axis] + f[name]["viscous"][axis]
        return f[name][part][axis]

    def big(f, part):
        return np.mean([parts(f, "sphere%d" % k, part, 1) for k in range(8)])

    def solid(f):
        solids = [k for k in f if k.startswith("sphere") or k in ("xmin", "xmax", "zmin", "zmax")]
        return sum(parts(f, k, "total", 1) for k in solids)

    ours = {
        "big sphere, viscous y": (big(fem, "viscous"), big(pfv, "viscous")),
        "big sphere, pressure y": (big(fem, "pressure"), big(pfv, "pressure")),
        "big sphere, total y": (big(fem, "total"), big(pfv, "total")),
        "small sphere, viscous y": (parts(fem, "sphere8", "viscous", 1), parts(pfv, "sphere8", "viscous", 1)),
        "small sphere, pressure y": (parts(fem, "sphere8", "pressure", 1), parts(pfv, "sphere8", "pressure", 1)),
        "small sphere, total y": (parts(fem, "sphere8", "total", 1), parts(pfv, "sphere8", "total", 1)),
        "boundary x=0, viscous y": (parts(fem, "xmin", "viscous", 1), parts(pfv, "xmin", "viscous", 1)),
        "boundary x=0, pressure x": (-parts(fem, "xmin", "pressure", 0), -parts(pfv, "xmin", "pressure", 0)),
        "solid phase, total y": (solid(fem), solid(pfv)),
    }
    lines = ["| force / (S ΔP) | FEM (here) | PFV (here) | PFV / FEM | thesis FEM | thesis PFV "
             "| thesis PFV / FEM |",
             "|---|---|---|---|---|---|---|"]
    for name, (f, p) in ours.items():
        tf, tp = THESIS_TABLE_3_2[name]
        lines.append("| %s | %.4g | %.4g | %.3f | %.4g | %.4g | %.3f |" % (name, f, p, p / f, tf, tp, tp / tf))
    return "\n".join(lines)


def figure(rows, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4.2))
    series = sorted([w for w in rows if w["case"].startswith("centred9_") and "@" not in w["case"]],
                    key=lambda w: float(w["case"].split("_")[1]))
    x = [float(w["case"].split("_")[1]) for w in series]
    styles = (("pfv_slip", "fem_sym", "PFV slip, thesis formula", "o-"),
              ("pfv_slip_yade", "fem_sym", "PFV slip, YADE factor", "s--"),
              ("yade_slip", "fem_sym", "YADE slip", "x:"),
              ("pfv_noslip", "fem_noslip", "PFV no-slip", "^-"),
              ("yade_noslip", "fem_noslip", "YADE no-slip", "+:"))
    for key, ref, label, style in styles:
        a.plot(x, [w[key] / w[ref] for w in series], style, label=label)
    a.axhline(1, color="k", lw=0.5)
    a.set_xlabel("d/D (9-sphere packing)")
    a.set_ylabel("κ / κ_FEM (same lateral condition)")
    a.legend(fontsize=8)
    packs = [w for w in rows if not w["case"].startswith("centred9_") and "@" not in w["case"]]
    packs.append(next(w for w in rows if w["case"] == "centred9_0.72"))
    names = [w["case"].replace("centred9_0.72", "9 (d/D 0.72)").replace("cubic8", "8").replace("random", "")
             for w in packs]
    pos = np.arange(len(packs))
    for i, (key, ref, label, style) in enumerate(styles):
        b.plot(pos + (i - 2) * 0.06, [w[key] / w[ref] for w in packs], style[0], label=label)
    b.axhline(1, color="k", lw=0.5)
    for ax in (a, b):  # the thesis' means over its cases (section 3.5.3, Fig. 3.12)
        ax.axhline(THESIS_MEAN["symmetry"], color="tab:blue", lw=0.8, ls=(0, (1, 3)))
        ax.axhline(THESIS_MEAN["noslip"], color="tab:red", lw=0.8, ls=(0, (1, 3)))
    b.text(pos[-1] + 0.3, THESIS_MEAN["symmetry"], "thesis, symmetry", fontsize=7, va="bottom", ha="right")
    b.text(pos[-1] + 0.3, THESIS_MEAN["noslip"], "thesis, no-slip", fontsize=7, va="bottom", ha="right")
    b.set_xticks(pos)
    b.set_xticklabels(names)
    b.set_xlabel("packing (number of spheres)")
    b.set_ylabel("κ / κ_FEM")
    fig.tight_layout()
    fig.savefig(path, dpi=110)


# Observed order in the shrink below which no limit at zero shrink is made: kappa is a smooth
# function of the radii while the spheres do not touch, so order 1 is expected; well below it the
# three shrinks are not in that range (the 9-sphere packing's cells degenerate as it closes).
MIN_SHRINK_ORDER = 0.5


def shrink_limit(shrinks, values):
    """(value at zero shrink, how it was found) from one quantity at decreasing shrinks: Richardson
    through the last three (no value below MIN_SHRINK_ORDER), or with two shrinks only the straight
    line through them, which assumes order 1 and is labelled so."""
    if len(values) >= 3:
        limit, q = richardson(shrinks, values, MIN_SHRINK_ORDER)
        return limit, ("q = %.1f" % q if np.isfinite(limit) else "none: q = %.1f" % q)
    s1, s2 = shrinks[-2:]
    v1, v2 = values[-2:]
    return v2 - (v1 - v2) * s2 / (s1 - s2), "linear"


def shrink_table(rows):
    """The shrink's effect: each ratio kappa_model / kappa_FEM of a packing at every shrink computed
    for it (the default, and cases named <case>@<shrink>), and its limit at zero shrink, the touching
    spheres that the shrink stands in for."""
    by_base = {}
    for w in rows:
        by_base.setdefault(w["case"].partition("@")[0], {})[w["shrink"]] = w
    series = {base: v for base, v in by_base.items() if len(v) > 1}
    if not series:
        return ""
    columns = sorted({s for v in series.values() for s in v}, reverse=True)
    lines = ["| case | ratio | %s | → 0 | at %g %% / at 0 |" % (
        " | ".join("shrink %g %%" % (100 * s) for s in columns), 100 * columns[0]),
        "|---|---|%s---|---|" % ("---|" * len(columns))]
    for base, v in series.items():
        shrinks = sorted(v, reverse=True)
        for key, ref, label in RATIOS + (("fem_sym", None, "κ_FEM sym"), ("fem_noslip", None, "κ_FEM no-slip")):
            values = [v[s][key] / (v[s][ref] if ref else 1) for s in shrinks]
            limit, how = shrink_limit(shrinks, values)
            fmt = "%.3f" if ref else "%.4e"
            cells = [fmt % values[shrinks.index(s)] if s in v else "" for s in columns]
            lines.append("| %s | %s | %s | %s (%s) | %s |" % (
                base, label, " | ".join(cells), fmt % limit if np.isfinite(limit) else "–", how,
                "%+.1f %%" % (100 * (values[0] / limit - 1)) if np.isfinite(limit) else "–"))
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--results", default=",".join(os.path.join(HERE, "results", f)
                                                  for f in ("stokes_results.json", "stokes_series.json",
                                                            "stokes_shrink.json", "stokes_random200.json",
                                                            "stokes_random54.json", "stokes_random_more.json")))
    ap.add_argument("--figure", default=os.path.join(ROOT, "doc", "figures", "stokes-kappa.png"))
    args = ap.parse_args()
    results = {}
    for path in args.results.split(","):
        if os.path.exists(path):
            with open(path) as f:
                results.update({r["case"]: r for r in json.load(f)})
    order = ["cubic8", "centred9_0.72", "random25", "random25s2", "random25s3", "random54", "random54s2", "random200"]
    results = sorted(results.values(), key=lambda r: (order.index(r["case"]) if r["case"] in order else 9, r["case"]))
    rows = kappa_rows(results)
    print("## convergence\n\n" + convergence_table(results))
    print("\n## permeability\n\n" + kappa_table(rows))
    left_out = ", ".join(unresolved(results)) or "none"
    print("\nleft out, the finest mesh's flux balance above %g: %s" % (RESOLVED, left_out))
    print("\n## summary\n\n" + summary(rows))
    print("\n## shrink\n\n" + shrink_table(rows))
    print("\n## forces, 9 spheres, d/D = 0.72, no-slip\n\n" + forces_072(results))
    if any(w["case"].startswith("centred9_") for w in rows):
        figure(rows, args.figure)
        print("\nfigure:", args.figure)


if __name__ == "__main__":
    main()
