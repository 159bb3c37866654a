"""Stokes (FEM) against PFV and YADE on the thesis' frozen packings (section 3.5): the driver.

From the repository's root:

    /usr/bin/python3 -m validation.stokes.run [--cases=a,b] [--levels=0.048,0.034,0.024] [--out=FILE]
    /usr/bin/python3 -m validation.stokes.run --quick [--write-reference]
    /usr/bin/python3 -m validation.stokes.run --models-only --cases=cubic8@0,random25@0 --out=FILE

Needs the pfv package on PYTHONPATH (a build tree's python/ folder) and, for the YADE column,
yade-double on PATH. For every case and every sphere-surface element size of --levels (mesh.py)
it solves Stokes flow with symmetry and with no-slip lateral faces (solve.py), then runs PFV
(no-slip walls, slip walls with the thesis' formula, slip walls with YADE's factor;
pfv_model.py) and YADE's engine (yade_model.py) on the same spheres. Results are appended case by case to --out (JSON,
by default in validation/stokes/results/, which is not tracked: report.py reads them from there).

--quick runs the CI case: the 8-sphere packing on one coarse mesh, solved directly and (symmetry faces)
by MINRES; with --write-reference it writes tests/data/stokes_fem_quick.json, else it compares with
that file and exits 1 on a difference larger than its tolerances.

--models-only runs PFV and YADE without the FEM: on the touching spheres themselves (shrink 0, "@0"),
which the models take as they come and the FEM reaches only as the limit of its shrink series
(report.py).
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

from . import mesh as fem_mesh
from . import packings, pfv_model, solve
from .report import check_stored

HERE = os.path.dirname(os.path.abspath(__file__))

ROOT = os.path.dirname(os.path.dirname(HERE))
REFERENCE = os.path.join(ROOT, "tests", "data", "stokes_fem_quick.json")
SHRINK = 0.01
QUICK_SURFACE = 0.048
D_OVER_D = (0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.72, 0.8)


def case_packing(name):
    """The shrunk packing of a case: cubic8, centred9_<d/D>, random<N> (validation/stokes/data), each
    optionally with @<shrink> (default SHRINK)."""
    base, _, shrink = name.partition("@")
    if base == "cubic8":
        p = packings.cubic8()
    elif base.startswith("centred9_"):
        p = packings.centred9(float(base.split("_")[1]))
    elif base.startswith("random"):
        p = packings.load(os.path.join(HERE, "data", base + ".json"))
    else:
        raise ValueError("unknown case " + name)
    return packings.shrunk(p, float(shrink) if shrink else SHRINK)


def all_cases():
    return (
        ["cubic8", "centred9_0.72", "random25", "random54"]
        + ["centred9_%.2f" % x for x in D_OVER_D if x != 0.72]
        + ["cubic8@0.005", "centred9_0.72@0.005"]
    )


YADE_JITTER = 1e-6


def jittered(packing, amplitude=YADE_JITTER, seed=1):
    """The packing with every centre moved by up to `amplitude` l0 along each axis (fixed seed).
    YADE's engine returns NaN on the cubic and 9-sphere packings: their cells come in groups that
    share one power centre, so some throats have length 0, and YADE's k ~ 1/L divides by it
    (PFV bounds such throats by its clamp). Moving the centres by 1e-6 l0 separates the power
    centres; on the cubic 8 YADE's kappa changes by 3e-5 between 1e-6 and 1e-5 l0."""
    out = dict(packing)
    rng = np.random.default_rng(seed)
    out["centres"] = np.asarray(packing["centres"]) + amplitude * rng.uniform(-1, 1, np.shape(packing["centres"]))
    out["jitter"] = amplitude
    return out


def run_yade(packing):
    with tempfile.TemporaryDirectory() as tmp:
        src, dst = os.path.join(tmp, "packing.json"), os.path.join(tmp, "yade.json")
        packings.save(jittered(packing), src)
        env = dict(os.environ, OMP_NUM_THREADS="1")
        done = subprocess.run(
            ["yade-double", "-n", "-x", os.path.join(HERE, "yade_model.py"), src, dst],
            env=env,
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
        )
        if done.returncode != 0 or not os.path.exists(dst):
            return {"error": done.stdout[-2000:]}
        with open(dst) as f:
            return json.load(f)


def fem_case(packing, surface, laterals=("symmetry", "noslip"), method="direct", also_minres=False):
    start = time.perf_counter()
    msh, _, facets = fem_mesh.build(packing, surface)
    meshed = time.perf_counter() - start
    out = {"surface": surface, "seconds_mesh": meshed, "tangled_cells": fem_mesh.tangled_cells(msh)}
    for lateral in laterals:
        out[lateral] = solve.solve(msh, facets, len(packing["radii"]), lateral, method=method)
    if also_minres:
        out["symmetry_minres"] = solve.solve(msh, facets, len(packing["radii"]), "symmetry", method="minres")
    return out


def run_case(name, levels, with_yade=True, log=print, save=lambda r: None, method="direct", also_minres=False):
    packing = case_packing(name)
    result = {
        "case": name,
        "n": len(packing["radii"]),
        "shrink": packing["shrink"],
        "porosity": packings.porosity(packing),
        "fem": [],
        "pfv": {},
        "yade": None,
    }
    for variant in pfv_model.VARIANTS:
        result["pfv"][variant] = pfv_model.run(packing, variant)
    if with_yade:
        result["yade"] = run_yade(packing)
    for surface in levels:
        level = fem_case(packing, surface, method=method, also_minres=also_minres)
        result["fem"].append(level)
        save(result)
        log(
            "%-22s surface %.3f  dofs %8d  kappa sym %.5e  noslip %.5e  mesh %.0f s  solve %.0f + %.0f s"
            % (
                name,
                surface,
                level["symmetry"]["dofs"],
                level["symmetry"]["kappa"],
                level["noslip"]["kappa"],
                level["seconds_mesh"],
                level["symmetry"]["seconds_solve"],
                level["noslip"]["seconds_solve"],
            )
        )
    return result


def quick_numbers():
    """The CI case: 8 spheres, one coarse mesh, both lateral conditions; FEM and PFV."""
    r = run_case("cubic8", [QUICK_SURFACE], with_yade=False, log=lambda *a: None, also_minres=True)
    fem = r["fem"][0]
    out = {"surface": QUICK_SURFACE, "shrink": SHRINK, "kappa_minres": fem["symmetry_minres"]["kappa"]}
    for lateral in ("symmetry", "noslip"):
        s = fem[lateral]
        fy = [s["forces"]["sphere%d" % k]["pressure"][1] + s["forces"]["sphere%d" % k]["viscous"][1] for k in range(8)]
        balance = abs(s["flux_in"] - s["flux_out"]) / s["flux_in"]
        out[lateral] = {
            "kappa": s["kappa"],
            "dofs": s["dofs"],
            "flux_balance": balance,
            "sphere_force_y": float(np.mean(fy)),
            "sphere_force_spread": float(np.ptp(fy)),
        }
    out["cells"] = fem["symmetry"]["cells"]
    out["tangled_cells"] = fem["tangled_cells"]
    out["pfv"] = {v: r["pfv"][v]["kappa"] for v in pfv_model.VARIANTS}
    return out


def compare_quick(now, ref):
    """Rows (what, value, reference, ok). The FEM on the same mesh and solver: kappa and the mean
    sphere force to 1e-6 relative; the flux balance between the two pressure faces below 1e-4 (a mesh
    with folded curved cells misses it by 30x); at most 0.1 % of the cells folded; PFV's kappa to 1e-9."""
    rows = [
        (
            "FEM folded cells / cells",
            now["tangled_cells"] / now["cells"],
            1e-3,
            now["tangled_cells"] <= 1e-3 * now["cells"],
        )
    ]
    for lateral in ("symmetry", "noslip"):
        a, b = now[lateral], ref[lateral]
        rows.append(("FEM dofs, " + lateral, a["dofs"], b["dofs"], a["dofs"] == b["dofs"]))
        rows.append(("FEM kappa, " + lateral, a["kappa"], b["kappa"], abs(a["kappa"] / b["kappa"] - 1) < 1e-6))
        rows.append(
            (
                "FEM mean sphere force, " + lateral,
                a["sphere_force_y"],
                b["sphere_force_y"],
                abs(a["sphere_force_y"] / b["sphere_force_y"] - 1) < 1e-6,
            )
        )
        rows.append(("FEM |Q_in - Q_out| / Q_in, " + lateral, a["flux_balance"], 1e-4, a["flux_balance"] < 1e-4))
    rows.append(
        (
            "FEM kappa by MINRES / by LDL^T - 1, symmetry",
            now["kappa_minres"] / now["symmetry"]["kappa"] - 1,
            1e-8,
            abs(now["kappa_minres"] / now["symmetry"]["kappa"] - 1) < 1e-8,
        )
    )
    for v, k in now["pfv"].items():
        rows.append(("PFV kappa, " + v, k, ref["pfv"][v], abs(k / ref["pfv"][v] - 1) < 1e-9))
    return rows


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--cases", default=",".join(all_cases()))
    ap.add_argument("--levels", default="0.048,0.034,0.024")
    ap.add_argument("--out", default=os.path.join(HERE, "results", "stokes_results.json"))
    ap.add_argument("--no-yade", action="store_true")
    ap.add_argument(
        "--solver",
        choices=("direct", "minres"),
        default="direct",
        help="MUMPS' LDL^T, or MINRES with a block AMG preconditioner (memory O(DOFs); solve.py)",
    )
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--write-reference", action="store_true")
    ap.add_argument(
        "--models-only",
        action="store_true",
        help="PFV and YADE only, no FEM (for the touching spheres, cases <name>@0)",
    )
    ap.add_argument(
        "--yade-only",
        action="store_true",
        help="rerun YADE's engine only, into the cases already in --out (--cases=all: every one)",
    )
    ap.add_argument(
        "--pfv-only",
        action="store_true",
        help="rerun PFV only, into the cases already in --out (--cases=all: every one)",
    )
    args = ap.parse_args()
    if args.quick:
        return check_stored(quick_numbers(), REFERENCE, compare_quick, args.write_reference)

    if args.yade_only or args.pfv_only:
        with open(args.out) as f:
            results = json.load(f)
        chosen = args.cases.split(",") if args.cases != "all" else [r["case"] for r in results]
        for r in results:
            if r["case"] not in chosen:
                continue
            if args.yade_only:
                r["yade"] = run_yade(case_packing(r["case"]))
                print(r["case"], "YADE kappa", {k: v.get("kappa") for k, v in r["yade"].items()}, flush=True)
            else:
                packing = case_packing(r["case"])
                r["pfv"] = {variant: pfv_model.run(packing, variant) for variant in pfv_model.VARIANTS}
                print(r["case"], "PFV kappa", {k: v["kappa"] for k, v in r["pfv"].items()}, flush=True)
        with open(args.out, "w") as f:
            json.dump(results, f, indent=1)
        return 0

    levels = [] if args.models_only else [float(x) for x in args.levels.split(",")]
    os.makedirs(os.path.dirname(args.out), exist_ok=True)
    results = []
    if os.path.exists(args.out):
        with open(args.out) as f:
            results = json.load(f)
    for name in args.cases.split(","):
        start = time.perf_counter()

        def save(r):
            r["seconds"] = time.perf_counter() - start
            with open(args.out, "w") as f:
                json.dump([x for x in results if x["case"] != name] + [r], f, indent=1)

        r = run_case(name, levels, with_yade=not args.no_yade, save=save, method=args.solver)
        save(r)
        results = [x for x in results if x["case"] != name] + [r]
        print("%s done in %.0f s" % (name, r["seconds"]), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
