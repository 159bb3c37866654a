"""Where the hydraulic-radius conductance goes wrong: PFV's throats against the periodic Stokes reference.

    export PYTHONPATH=$BUILD/python
    /usr/bin/python3 -m validation.stokes.throat_study [--results=FILE,...] [--figure=PNG]

For every packing and shrink of periodic_random.py's results (its finest mesh), PFV's triangulation of the same
spheres is rebuilt (it is a function of the spheres) and every throat gets:

* the reference's flux q_FEM through its triangle and PFV's q_PFV (both from pore 0 to pore 1);
* the reference's pressure drop between the two power centres, and so its effective conductance
  k_FEM = q_FEM / dp_FEM, against PFV's k: the local error, free of the network's;
* its geometry: facet area A, fluid area A_f, hydraulic radius R_h, length L between the power centres, the
  constriction radius r_c, where the power centres lie (the signed distances L_0, L_1 from the facet's plane; a
  negative one is a power centre beyond the facet, outside its own tetrahedron), the two pores' fluid volumes and
  the smallest gap between the facet's spheres.

It prints the permeability of each case and tables of k_PFV / k_FEM binned by each feature, flux-weighted (the
throats that carry the flow decide the permeability).
"""
import argparse
import sys

import numpy as np

from . import periodic_packings, periodic_random, pfv_periodic
from .packings import shrunk

# Throats whose reference pressure drop is below this fraction of the mean drop are left out of k_FEM's
# statistics (their ratio q / dp is noise); they carry little flux.
MIN_DROP = 0.05


def features(model, packing):
    """Per-throat geometry of pfv_periodic.run's throats (module docstring)."""
    t = model["throats"]
    area = np.linalg.norm(t["area_vector"], axis=1)
    normal = t["area_vector"] / area[:, None]
    on_facet = t["triangle"].mean(1)
    l0 = np.einsum("ij,ij->i", on_facet - t["power_centre_0"], normal)
    l1 = np.einsum("ij,ij->i", t["power_centre_1"] - on_facet, normal)
    tri, r = t["triangle"], t["radii"]
    gaps = []
    for a, b in ((0, 1), (1, 2), (0, 2)):
        gaps.append(np.linalg.norm(tri[:, a] - tri[:, b], axis=1) / (r[:, a] + r[:, b]) - 1.0)
    return {
        "area": area,
        "fluid_area": t["fluid_area"],
        "hydraulic_radius": t["hydraulic_radius"],
        "length": t["length"],
        "constriction": t["constriction_radius"],
        "l0": l0,
        "l1": l1,
        "volume_ratio": np.maximum(t["fluid_volume_0"], t["fluid_volume_1"])
        / np.maximum(np.minimum(t["fluid_volume_0"], t["fluid_volume_1"]), 1e-300),
        "min_gap": np.min(gaps, axis=0),
    }


def throat_data(row):
    """The model, geometry and reference numbers of every throat of one results row."""
    p = periodic_packings.load(row["packing"])
    if row["shrink"]:
        p = shrunk(p, row["shrink"])
    model = pfv_periodic.run(p)
    t = model["throats"]
    if t["vertices"].tolist() != row["throat_vertices"]:
        raise RuntimeError("%s: the triangulation differs from the stored one" % row["packing"])
    q_fem = np.asarray(row["throat_flux_fem"])
    p_fem = np.asarray(row["pore_pressure_fem"])
    i, j = t["cells"][:, 0], t["cells"][:, 1]
    drop = p_fem[i] - p_fem[j] - t["translation"] @ np.array([-1.0, 0.0, 0.0])
    return {"model": model, "geometry": features(model, p), "q_fem": q_fem, "drop_fem": drop, "packing": p}


def binned(values, ratio, weight, edges):
    """Rows (range, throats, flux share, weighted mean ratio) of `ratio` binned by `values`."""
    rows = []
    total = weight.sum()
    for lo, hi in zip(edges[:-1], edges[1:]):
        sel = (values >= lo) & (values < hi) & np.isfinite(ratio)
        if sel.sum() == 0:
            continue
        w = weight[sel]
        rows.append((lo, hi, int(sel.sum()), w.sum() / total, float((ratio[sel] * w).sum() / w.sum())))
    return rows


def summary(rows):
    lines = []
    for (name, shrink), row in periodic_random.finest(rows).items():
        d = throat_data(row)
        g, t = d["geometry"], d["model"]["throats"]
        k_fem = d["q_fem"] / d["drop_fem"]
        drop = np.abs(d["drop_fem"])
        ok = drop > MIN_DROP * drop.mean()
        ratio = np.where(ok, t["conductance"] / k_fem, np.nan)
        weight = np.abs(d["q_fem"])
        lines.append(
            "%s shrink %g: kappa FEM %.4e (h %.3f) PFV %.4e, ratio %.3f; flux imbalance %.1e; throats %d"
            % (
                name,
                shrink,
                row["kappa"],
                row["surface"],
                row["kappa_pfv"],
                row["kappa_pfv"] / row["kappa"],
                row["throat_imbalance"],
                len(ratio),
            )
        )
        lines.append("  q_PFV / q_FEM, flux-weighted: %.3f" % ((t["flux"] / d["q_fem"] * weight).sum() / weight.sum()))
        for label, values, edges in (
            ("R_h / r_c", g["hydraulic_radius"] / np.maximum(g["constriction"], 1e-300), [0, 1, 1.5, 2, 3, 5, np.inf]),
            ("min(L0, L1) / L", np.minimum(g["l0"], g["l1"]) / g["length"], [-np.inf, 0, 0.1, 0.2, 0.3, 0.4, 0.51]),
            ("A_f / A", g["fluid_area"] / g["area"], [0, 0.1, 0.2, 0.3, 0.4, 0.6, 1.0]),
            ("min gap / (r_i + r_j)", g["min_gap"], [-1, 0.001, 0.01, 0.05, 0.1, 0.3, np.inf]),
            ("pore volume ratio", g["volume_ratio"], [1, 1.5, 2, 3, 5, 10, np.inf]),
        ):
            lines.append("  k_PFV / k_FEM by %s (range, throats, flux share, mean):" % label)
            for lo, hi, n, share, mean in binned(values, ratio, weight, edges):
                lines.append("    [%6.3g, %6.3g)  %4d  %5.1f %%  %.3f" % (lo, hi, n, 100 * share, mean))
    return "\n".join(lines)


def figure(rows, path):
    """Per throat, k_PFV / k_FEM against the facet's open fraction A_f / A and against min(L_0, L_1) / L, every
    case of the results, markers sized by the throat's share of its cell's flux and coloured by the cell's solid
    fraction."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(12.5, 4.4), sharey=True)
    for (name, shrink), row in periodic_random.finest(rows).items():
        d = throat_data(row)
        g, t = d["geometry"], d["model"]["throats"]
        drop = np.abs(d["drop_fem"])
        ok = drop > MIN_DROP * drop.mean()
        ratio = t["conductance"][ok] / (d["q_fem"][ok] / d["drop_fem"][ok])
        size = 2000.0 * np.abs(d["q_fem"][ok]) / np.abs(d["q_fem"]).sum()
        colour = np.full(ok.sum(), d["packing"]["c"])
        style = dict(s=size, alpha=0.35, c=colour, cmap="viridis", vmin=0.4, vmax=0.62)
        points = axes[0].scatter((g["fluid_area"] / g["area"])[ok], ratio, **style)
        axes[1].scatter((np.minimum(g["l0"], g["l1"]) / g["length"])[ok], ratio, **style)
    for ax, xlabel in zip(
        axes, ("A_f / A (open fraction of the facet)", "min(L_0, L_1) / L (< 0: power centre beyond")
    ):
        ax.set_xlabel(xlabel + (" the facet)" if "L_0" in xlabel else ""))
        ax.axhline(1.0, color="k", lw=0.8)
        ax.set_yscale("log")
        ax.grid(True, which="both", alpha=0.3)
    axes[1].set_xlim(-1.5, 0.55)
    axes[0].set_ylabel("k_PFV / k_FEM  (k_FEM = q_FEM / dp_FEM)")
    fig.tight_layout()
    fig.colorbar(points, ax=axes, label="solid fraction c of the cell", fraction=0.03)
    fig.savefig(path, dpi=110, bbox_inches="tight")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--results", default=periodic_random.RESULTS + "," + periodic_random.SMALL_RESULTS)
    ap.add_argument("--figure", help="also draw the per-throat figure into this PNG")
    args = ap.parse_args()
    rows = [r for path in args.results.split(",") for r in periodic_random.load(path)]
    print(summary(rows))
    if args.figure:
        figure(rows, args.figure)
    return 0


if __name__ == "__main__":
    sys.exit(main())
