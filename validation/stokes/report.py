"""Tables and figure of the Stokes comparison from run.py's JSON (doc/validation.md section 7).

    /usr/bin/python3 -m validation.stokes.report [--results=FILE] [--figure=doc/figures/stokes-kappa.png]

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
    "big sphere, viscous y": (1.51e-2, 1.06e-2),
    "big sphere, pressure y": (9.09e-2, 9.64e-2),
    "big sphere, total y": (1.06e-1, 1.07e-1),
    "small sphere, viscous y": (9.38e-3, 5.83e-3),
    "small sphere, pressure y": (5.17e-2, 5.72e-2),
    "small sphere, total y": (6.04e-2, 6.30e-2),
    "boundary x=0, viscous y": (2.27e-2, 2.03e-2),
    "boundary x=0, pressure x": (4.98e-1, 5.00e-1),
    "solid phase, total y": (1 - 5.56e-4, 1 + 1.18e-4),
}


# (model key, FEM key, label) of the ratios kappa_model / kappa_FEM reported, same lateral condition
RATIOS = (
    ("pfv_slip", "fem_sym", "PFV slip, thesis formula"),
    ("pfv_slip_yade", "fem_sym", "PFV slip, YADE factor"),
    ("yade_slip", "fem_sym", "YADE slip"),
    ("pfv_noslip", "fem_noslip", "PFV no-slip"),
    ("yade_noslip", "fem_noslip", "YADE no-slip"),
)

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
    lines = [
        "| case | surface size | DOFs | folded cells | κ_FEM sym | change | κ_FEM no-slip | change "
        "| solve (s) sym / no-slip | \\|Q_in − Q_out\\| / Q sym / no-slip |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in results:
        prev = None
        for lv in r["fem"]:
            s, n = lv["symmetry"], lv["noslip"]
            cs = "" if prev is None else "%+.2f %%" % (100 * (s["kappa"] / prev[0] - 1))
            cn = "" if prev is None else "%+.2f %%" % (100 * (n["kappa"] / prev[1] - 1))
            folded = (
                "%d of %s" % (lv["tangled_cells"], "{:,}".format(s["cells"]).replace(",", " "))
                if "tangled_cells" in lv
                else "–"
            )
            lines.append(
                "| %s | %.3f | %s | %s | %.4e | %s | %.4e | %s | %.0f / %.0f | %.1e / %.1e |"
                % (
                    r["case"],
                    lv["surface"],
                    "{:,}".format(s["dofs"]).replace(",", " "),
                    folded,
                    s["kappa"],
                    cs,
                    n["kappa"],
                    cn,
                    s["seconds_solve"],
                    n["seconds_solve"],
                    balance(s),
                    balance(n),
                )
            )
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
    return [
        r["case"]
        for r in results
        if r["fem"] and max(balance(r["fem"][-1][lat]) for lat in ("symmetry", "noslip")) > RESOLVED
    ]


def model_kappas(r):
    """kappa of PFV's three wall variants and YADE's two, keyed as in RATIOS."""
    return {
        "pfv_noslip": r["pfv"]["noslip"]["kappa"],
        "pfv_slip": r["pfv"]["slip"]["kappa"],
        "pfv_slip_yade": r["pfv"]["slip_yade"]["kappa"],
        "yade_noslip": yade_kappa(r, "noslip"),
        "yade_slip": yade_kappa(r, "slip"),
    }


def kappa_rows(results):
    rows = []
    for r in results:
        if not r["fem"] or r["case"] in unresolved(results):
            continue
        ks, _, es, _ = fem_estimate(r["fem"], "symmetry")
        kn, _, en, _ = fem_estimate(r["fem"], "noslip")
        rows.append(
            {
                "case": r["case"],
                "n": r["n"],
                "porosity": r["porosity"],
                "shrink": r["shrink"],
                # the reference: the Richardson estimate where three levels give one, else the finest mesh
                "fem_sym": es if np.isfinite(es) else ks,
                "fem_noslip": en if np.isfinite(en) else kn,
                "fem_sym_finest": ks,
                "fem_noslip_finest": kn,
                **model_kappas(r),
            }
        )
    return rows


def kappa_table(rows):
    """kappa_FEM and each model's ratio to it, per case; the FEM's extrapolation spread beside it
    where the rows carry one (contact_rows)."""

    def fem(w, key):
        spread = w.get(key + "_spread")
        return "%.4e" % w[key] + ("" if spread is None else " ± %.1f %%" % (100 * abs(spread)))

    lines = [
        "| case | porosity | κ_FEM sym | PFV slip, thesis / FEM | PFV slip, YADE factor / FEM "
        "| YADE slip / FEM | κ_FEM no-slip | PFV no-slip / FEM | YADE no-slip / FEM |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for w in rows:
        sym, ns = w["fem_sym"], w["fem_noslip"]
        lines.append(
            "| %s | %.3f | %s | **%.3f** | %.3f | %.3f | %s | %.3f | %.3f |"
            % (
                w["case"],
                w["porosity"],
                fem(w, "fem_sym"),
                w["pfv_slip"] / sym,
                w["pfv_slip_yade"] / sym,
                w["yade_slip"] / sym,
                fem(w, "fem_noslip"),
                w["pfv_noslip"] / ns,
                w["yade_noslip"] / ns,
            )
        )
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
                out.append(
                    "| %s | %s | %.3f | %.1f %% | %.3f | %d |"
                    % (label, group, q.mean(), 100 * np.mean(np.abs(q - 1)), worst, len(q))
                )
    return "\n".join(
        [
            "| κ / κ_FEM | packings | mean | mean \\|κ/κ_FEM − 1\\| | furthest from 1 | cases |",
            "|---|---|---|---|---|---|",
        ]
        + out
    )


def force_quantities(f):
    """The quantities of thesis Table 3.2 from one force dictionary (pfv_model / solve.py), / (S dP)."""

    def part(name, which, axis):
        if which == "total":
            return f[name]["pressure"][axis] + f[name]["viscous"][axis]
        return f[name][which][axis]

    def big(which):
        return np.mean([part("sphere%d" % k, which, 1) for k in range(8)])

    solids = [k for k in f if k.startswith("sphere") or k in ("xmin", "xmax", "zmin", "zmax")]
    return {
        "big sphere, viscous y": big("viscous"),
        "big sphere, pressure y": big("pressure"),
        "big sphere, total y": big("total"),
        "small sphere, viscous y": part("sphere8", "viscous", 1),
        "small sphere, pressure y": part("sphere8", "pressure", 1),
        "small sphere, total y": part("sphere8", "total", 1),
        "boundary x=0, viscous y": part("xmin", "viscous", 1),
        "boundary x=0, pressure x": -part("xmin", "pressure", 0),
        "solid phase, total y": sum(part(k, "total", 1) for k in solids),
    }


def forces_072(results):
    """Thesis Table 3.2: FEM (finest mesh) and PFV on the 9 spheres at d/D = 0.72, no-slip lateral
    faces, at the 1 % shrink; and at the touching spheres where the shrink series exists: PFV on
    the packing itself, the FEM forces extrapolated in the shrink like kappa (contact_rows)."""
    by_case = {r["case"]: r for r in results}
    r = by_case.get("centred9_0.72")
    if r is None or not r["fem"]:
        return ""
    fem = force_quantities(r["fem"][-1]["noslip"]["forces"])
    pfv = force_quantities(r["pfv"]["noslip"]["forces"])
    shrinks = sorted((x["shrink"], x) for x in results if x["case"].partition("@")[0] == "centred9_0.72" and x["fem"])[
        ::-1
    ]
    touching = by_case.get("centred9_0.72@0")
    contact = None
    if len(shrinks) >= 3 and touching is not None:
        series = [force_quantities(x["fem"][-1]["noslip"]["forces"]) for _, x in shrinks]
        fem0 = {k: richardson([s for s, _ in shrinks], [q[k] for q in series], MIN_SHRINK_ORDER)[0] for k in fem}
        contact = (fem0, force_quantities(touching["pfv"]["noslip"]["forces"]), series[-1])
    head = "| force / (S ΔP) | FEM (here) | PFV (here) | PFV / FEM |"
    rule = "|---|---|---|---|"
    if contact:
        head += " FEM touching | PFV touching | PFV / FEM touching |"
        rule += "---|---|---|"
    lines = [head + " thesis FEM | thesis PFV | thesis PFV / FEM |", rule + "---|---|---|"]
    for name in fem:
        tf, tp = THESIS_TABLE_3_2[name]
        cells = "| %s | %.4g | %.4g | %.3f |" % (name, fem[name], pfv[name], pfv[name] / fem[name])
        if contact:
            f0, p0 = contact[0][name], contact[1][name]
            if np.isfinite(f0):
                cells += " %.4g | %.4g | %.3f |" % (f0, p0, p0 / f0)
            else:  # no monotone change with the shrink: the smallest shrink's value, marked
                f0 = contact[2][name]
                cells += " %.4g (at %g %%) | %.4g | %.3f |" % (f0, 100 * shrinks[-1][0], p0, p0 / f0)
        lines.append(cells + " %.4g | %.4g | %.3f |" % (tf, tp, tp / tf))
    return "\n".join(lines)


def centre_sphere_table(results):
    """The centre sphere of the 9-sphere series against d/D (thesis Fig. 3.15): its force along the
    flow, total and viscous part, FEM (finest mesh) and PFV, both lateral conditions (PFV's slip walls
    with YADE's factor), at the 1 % shrink."""
    series = sorted(
        (float(r["case"].split("_")[1]), r)
        for r in results
        if r["case"].startswith("centred9_") and "@" not in r["case"] and r["fem"]
    )
    if not series:
        return ""
    lines = [
        "| d/D | FEM total, sym [10⁻³ S ΔP] | PFV / FEM, sym | FEM total, no-slip [10⁻³ S ΔP] "
        "| PFV / FEM, no-slip | viscous part FEM / PFV, no-slip [10⁻³ S ΔP] |",
        "|---|---|---|---|---|---|",
    ]
    for x, r in series:
        cells = []
        for lateral, variant in (("symmetry", "slip_yade"), ("noslip", "noslip")):
            f = r["fem"][-1][lateral]["forces"]["sphere8"]
            p = r["pfv"][variant]["forces"]["sphere8"]
            fem, pfv = f["pressure"][1] + f["viscous"][1], p["pressure"][1] + p["viscous"][1]
            cells += ["%.4g" % (1e3 * fem), "%.3f" % (pfv / fem)]
        viscous = (1e3 * f["viscous"][1], 1e3 * p["viscous"][1])
        lines.append("| %.2f | %s | %.4g / %.4g |" % ((x, " | ".join(cells)) + viscous))
    return "\n".join(lines)


def figure(rows, contact, path):
    """kappa_model / kappa_FEM against d/D (9 spheres) and per packing, at the touching spheres
    (contact_rows, filled markers) where the packing's shrink series exists, else at the 1 % shrink
    (open markers)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    touching = {w["case"]: w for w in contact}
    shrunk = {w["case"]: w for w in rows if "@" not in w["case"]}
    chosen = {c: touching.get(c, w) for c, w in shrunk.items()}
    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4.2))
    styles = (
        ("pfv_slip", "fem_sym", "PFV slip, thesis formula", "o", "-"),
        ("pfv_slip_yade", "fem_sym", "PFV slip, YADE factor", "s", "--"),
        ("yade_slip", "fem_sym", "YADE slip", "x", ":"),
        ("pfv_noslip", "fem_noslip", "PFV no-slip", "^", "-"),
        ("yade_noslip", "fem_noslip", "YADE no-slip", "+", ":"),
    )
    series = sorted([c for c in chosen if c.startswith("centred9_")], key=lambda c: float(c.split("_")[1]))
    x = np.array([float(c.split("_")[1]) for c in series])
    filled = np.array([c in touching for c in series], dtype=bool)
    packs = [c for c in chosen if not c.startswith("centred9_")] + ["centred9_0.72"]
    pos = np.arange(len(packs))
    names = [c.replace("centred9_0.72", "9 (d/D 0.72)").replace("cubic8", "8").replace("random", "") for c in packs]
    for i, (key, ref, label, marker, line) in enumerate(styles):
        colour = "C%d" % i
        y = np.array([chosen[c][key] / chosen[c][ref] for c in series])
        a.plot(x, y, line, color=colour, label=label)
        a.plot(x[filled], y[filled], marker, color=colour, ls="none")
        a.plot(x[~filled], y[~filled], marker, color=colour, ls="none", mfc="none")
        for p, c in zip(pos, packs):
            b.plot(
                p + (i - 2) * 0.06,
                chosen[c][key] / chosen[c][ref],
                marker,
                color=colour,
                mfc=colour if c in touching else "none",
            )
    a.axhline(1, color="k", lw=0.5)
    a.set_xlabel("d/D (9-sphere packing)")
    a.set_ylabel("κ / κ_FEM (same lateral condition)")
    a.legend(fontsize=8)
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
    if not filled.all() or any(c not in touching for c in packs):
        fig.suptitle(
            "filled: touching spheres (FEM extrapolated in the shrink); open: spheres shrunk by 1 %", fontsize=9
        )
    fig.tight_layout()
    fig.savefig(path, dpi=110)


# Observed order in the shrink below which the FEM gets no limit at zero shrink: kappa is a smooth
# function of the radii while the spheres do not touch, and order 1 is what the series show; well
# below it the three shrinks are not in that range.
MIN_SHRINK_ORDER = 0.5


def shrink_series(rows):
    """{packing: {shrink: row}} of the packings computed at three shrinks or more."""
    by_base = {}
    for w in rows:
        by_base.setdefault(w["case"].partition("@")[0], {})[w["shrink"]] = w
    return {base: v for base, v in by_base.items() if len(v) >= 3}


def contact_rows(rows, results):
    """The touching spheres that the shrink stands in for: PFV and YADE on the packing itself
    (run.py --models-only, case <name>@0), against the FEM's limit at zero shrink, Richardson in the
    shrink through its three smallest shrinks. `<fem>_spread` is the distance of that limit from the
    straight line through the two smallest shrinks: the extrapolation's own uncertainty."""
    models = {r["case"].partition("@")[0]: r for r in results if not r["fem"] and r["shrink"] == 0}
    out = []
    for base, v in shrink_series(rows).items():
        if base not in models:
            continue
        shrinks = sorted(v, reverse=True)
        row = {
            "case": base,
            "n": models[base]["n"],
            "porosity": models[base]["porosity"],
            "shrink": 0.0,
            **model_kappas(models[base]),
        }
        for key in ("fem_sym", "fem_noslip"):
            values = [v[x][key] for x in shrinks]
            limit, order = richardson(shrinks, values, MIN_SHRINK_ORDER)
            line = values[-1] - (values[-2] - values[-1]) * shrinks[-1] / (shrinks[-2] - shrinks[-1])
            row.update({key: limit, key + "_order": order, key + "_spread": line / limit - 1})
        if np.isfinite(row["fem_sym"]) and np.isfinite(row["fem_noslip"]):
            out.append(row)
    return out


def shrink_table(rows, contact):
    """The shrink's effect on each ratio kappa_model / kappa_FEM: its value at every shrink computed
    (the default, and cases named <case>@<shrink>) and at the touching spheres (contact_rows)."""
    series = shrink_series(rows)
    at_contact = {w["case"]: w for w in contact}
    if not series:
        return ""
    columns = sorted({s for v in series.values() for s in v}, reverse=True)
    lines = [
        "| case | quantity | %s | touching | at %g %% / touching |"
        % (" | ".join("shrink %g %%" % (100 * s) for s in columns), 100 * columns[0]),
        "|---|---|%s---|---|" % ("---|" * len(columns)),
    ]
    for base, v in series.items():
        touch = at_contact.get(base)
        for key, ref, label in (("fem_sym", None, "κ_FEM sym"), ("fem_noslip", None, "κ_FEM no-slip")) + RATIOS:
            fmt = "%.3f" if ref else "%.4e"
            cells = [fmt % (v[s][key] / (v[s][ref] if ref else 1)) if s in v else "" for s in columns]
            if touch is None:
                limit, how = float("nan"), "–"
            elif ref:
                limit, how = touch[key] / touch[ref], fmt % (touch[key] / touch[ref])
            else:
                limit = touch[key]
                how = "%.4e (q = %.1f, ± %.2f %%)" % (limit, touch[key + "_order"], 100 * abs(touch[key + "_spread"]))
            first = v[columns[0]][key] / (v[columns[0]][ref] if ref else 1) if columns[0] in v else float("nan")
            lines.append(
                "| %s | %s | %s | %s | %s |"
                % (
                    base,
                    label,
                    " | ".join(cells),
                    how,
                    "%+.1f %%" % (100 * (first / limit - 1)) if np.isfinite(limit) and np.isfinite(first) else "–",
                )
            )
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument(
        "--results",
        default=",".join(
            os.path.join(HERE, "results", f)
            for f in (
                "stokes_results.json",
                "stokes_series.json",
                "stokes_shrink.json",
                "stokes_random200.json",
                "stokes_random54.json",
                "stokes_random_more.json",
                "stokes_random54s2.json",
                "stokes_shrink_random.json",
                "stokes_shrink_random54.json",
                "stokes_shrink_series.json",
                "stokes_shrink_series2.json",
                "stokes_contact.json",
            )
        ),
    )
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
    contact = contact_rows(rows, list(results))
    print("\n## shrink\n\n" + shrink_table(rows, contact))
    print("\n## touching spheres\n\n" + kappa_table(contact))
    print("\n## summary, touching spheres\n\n" + summary(contact))
    print("\n## forces, 9 spheres, d/D = 0.72, no-slip\n\n" + forces_072(results))
    print("\n## centre sphere against d/D\n\n" + centre_sphere_table(results))
    if any(w["case"].startswith("centred9_") for w in rows):
        figure(rows, contact, args.figure)
        print("\nfigure:", args.figure)


if __name__ == "__main__":
    main()


def check_stored(numbers, path, compare, write_reference):
    """A quick run's `numbers` against those stored in `path` (or stored there with `write_reference`): prints
    compare(numbers, stored)'s rows (what, value, expected, ok) and returns the exit status, 1 if any failed."""
    if write_reference:
        with open(path, "w") as f:
            json.dump(numbers, f, indent=1)
        print("wrote", path)
        return 0
    with open(path) as f:
        stored = json.load(f)
    rows = compare(numbers, stored)
    for what, value, expected, ok in rows:
        print("%-45s %14.8g %14.8g  %s" % (what, value, expected, "ok" if ok else "FAIL"))
    failed = sum(1 for r in rows if not r[3])
    print("%d passed, %d failed" % (len(rows) - failed, failed))
    return 1 if failed else 0
