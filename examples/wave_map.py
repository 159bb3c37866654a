# -*- coding: utf-8 -*-
"""The liquefaction map (thesis Fig. 6.29): collects the summary.json of the wave_standing.py jobs
of a yade-batch table and draws amplitude against period, liquefied (grad H / i_c > 0.8) or not.

    yade-double -n -x examples/wave_map.py [--dir=wave-map] [--out=wave-map.png]

Claim 32 beside it: A = 50 and 100 Pa never liquefy, 200 and 400 Pa always, 125 and 150 Pa only at
the short periods (0.5 and 1 s). Prints the table, the agreement with the claim, and the cost of the
jobs found (wall seconds per simulated second), from which the full map's cost is projected.
"""
import glob
import json
import os
import sys

FULL_MAP = dict(
    amplitudes=(50, 100, 125, 150, 200, 400),
    periods=(0.25, 0.5, 0.75, 1.0, 1.2, 1.5, 1.7, 2.0),
    grains=5000,
    periods_per_job=10,
)


def thesis_liquefies(amplitude, period):
    """Claim 32, or None where the thesis says nothing (125-150 Pa at periods between its cases)."""
    if amplitude <= 100:
        return False
    if amplitude >= 200:
        return True
    if period in (0.5, 1.0):
        return True
    if period >= 1.2:
        return False
    return None


def collect(folder):
    runs = []
    for path in sorted(glob.glob(os.path.join(folder, "*", "summary.json"))):
        with open(path) as f:
            s = json.load(f)
        profile = s["profile"]
        amp = float(profile.split("amplitude=")[1].split(",")[0])
        period = float(profile.split("period=")[1].split(",")[0])
        runs.append(
            dict(
                amplitude=amp,
                period=period,
                liquefied=s["liquefied"],
                peak=s["peak_mean_ratio"],
                grains=s["grains"],
                duration=s["duration"],
                wall=s["wall_seconds"],
            )
        )
    return runs


def draw(runs, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 4.5))
    for r in runs:
        ax.scatter(
            r["period"], r["amplitude"], marker="o" if r["liquefied"] else "x", s=60, c="C3" if r["liquefied"] else "C0"
        )
        ax.annotate(
            f"{r['peak']:.2f}", (r["period"], r["amplitude"]), textcoords="offset points", xytext=(5, 4), fontsize=7
        )
    ax.scatter([], [], marker="o", c="C3", label="liquefied (grad H / i_c > 0.8)")
    ax.scatter([], [], marker="x", c="C0", label="stable")
    ax.set_xlabel("period T [s]")
    ax.set_ylabel("amplitude A [Pa]")
    ax.set_title(f"standing wave on the loose bed ({runs[0]['grains']} grains)")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv):
    folder = next((a.split("=", 1)[1] for a in argv if a.startswith("--dir=")), "wave-map")
    out = next((a.split("=", 1)[1] for a in argv if a.startswith("--out=")), folder + ".png")
    runs = collect(folder)
    if not runs:
        raise SystemExit(f"no summary.json under {folder}/*/: run the yade-batch table first")
    draw(runs, out)
    agree = known = 0
    print("| A [Pa] | T [s] | peak grad H / i_c | PFV | thesis |")
    print("|---|---|---|---|---|")
    for r in sorted(runs, key=lambda r: (r["amplitude"], r["period"])):
        th = thesis_liquefies(r["amplitude"], r["period"])
        if th is not None:
            known += 1
            agree += th == r["liquefied"]
        ours = "liquefied" if r["liquefied"] else "stable"
        theirs = "-" if th is None else ("liquefied" if th else "stable")
        print(f"| {r['amplitude']:g} | {r['period']:g} | {r['peak']:.3f} | {ours} | {theirs} |")
    print(f"agreement with claim 32: {agree} of {known} cells the thesis decides")
    cost = sum(r["wall"] for r in runs) / sum(r["duration"] for r in runs)  # wall s per simulated s
    grains = runs[0]["grains"]
    full_sim = sum(FULL_MAP["periods_per_job"] * T for T in FULL_MAP["periods"]) * len(FULL_MAP["amplitudes"])
    scale = FULL_MAP["grains"] / grains  # the step costs grow about linearly with the grains at this size
    print(
        f"cost: {cost:.1f} wall s per simulated s at {grains} grains; the full map ({full_sim:g} simulated s at "
        f"{FULL_MAP['grains']} grains) about {cost * scale * full_sim / 3600:.1f} h on one core"
    )
    print(f"map: {out}")


main(sys.argv[1:])
sys.exit(0)
