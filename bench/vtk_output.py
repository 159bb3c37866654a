"""Cost of saveVtk: YADE's FlowEngine against pfv.FlowEngine writing the same scene.

    nice -n 10 yade-double -j1 -n -x bench/vtk_output.py [--sizes=10000,50000] [--rounds=5] [--dir=/tmp/bench-vtk]
                                                          [--profile]

Scene: N spheres on a jittered cubic lattice (spacing 1, centres moved by up to 0.03, radii 0.42 +- 10 %, seed 1;
no two spheres touch), made in a second (no DEM compaction), in a box whose walls touch the lattice's outer spheres
(aabbWalls), spheres frozen, pressure drop along y. Both engines are in O.engines together and run one step; then
each round calls, in an order rotated every round,
    YADE   saveVtk(dir)                  (legacy ASCII .vtk: YADE's only format)
    PFV    saveVtk(dir)                  (VTK XML, appended raw binary)
    PFV    saveVtk(dir, compress=True)   (zlib)
    YADE   saveVtk(dir, True), PFV saveVtk(dir, True)   (withBoundaries)
and times each call (wall clock, the files land in the page cache); the files of a round are deleted after it.
Reported: the median over rounds, the ratio PFV / YADE and the bytes written. --profile splits PFV's call into
reading the engine (under its lock), building the VTK grids and writing them. No timing is asserted.
"""
from __future__ import annotations

import os
import shutil
import statistics
import sys
import time


from pfv_testing.lattice import jittered_lattice
from yade import O, utils  # noqa: E402
from yade.wrapper import FlowEngine as YadeFlowEngine, ForceResetter, FrictMat, NewtonIntegrator  # noqa: E402

import pfv  # noqa: E402
from pfv import FlowEngine as PfvFlowEngine, _vtk_output  # noqa: E402

SEED = 1


def log(*args: object) -> None:
    print("vtk_output:", *args, flush=True)


def parse_args(argv: list[str]) -> dict:
    opts = dict(sizes=[10000, 50000], rounds=5, dir="/tmp/bench-vtk", profile=False)
    for a in argv:
        if a == "--profile":
            opts["profile"] = True
            continue
        if not a.startswith("--") or "=" not in a:
            raise SystemExit(f"vtk_output: unknown argument {a!r} (see the docstring)")
        key, value = a[2:].split("=", 1)
        if key == "sizes":
            opts["sizes"] = [int(v) for v in value.split(",") if v]
        elif key == "rounds":
            opts["rounds"] = int(value)
        elif key == "dir":
            opts["dir"] = value
        else:
            raise SystemExit(f"vtk_output: unknown option --{key}")
    return opts


def build_scene(n: int) -> tuple[YadeFlowEngine, PfvFlowEngine]:
    centres, radii = jittered_lattice(n, SEED)
    O.reset()
    O.materials.append(FrictMat(young=1e6, poisson=0.5, frictionAngle=0.5, density=2600, label="spheres"))
    lo = (centres - radii[:, None]).min(axis=0)
    hi = (centres + radii[:, None]).max(axis=0)
    walls = O.bodies.append(utils.aabbWalls([tuple(lo), tuple(hi)], thickness=0, material="spheres"))
    assert walls == list(range(6)), walls
    spheres = [utils.sphere(tuple(c), float(r), material="spheres") for c, r in zip(centres, radii)]
    for b in spheres:
        b.state.blockedDOFs = "xyzXYZ"
    O.bodies.append(spheres)
    engines = []
    for flow in (YadeFlowEngine(), PfvFlowEngine()):
        flow.wallIds = [0, 1, 2, 3, 4, 5]
        flow.bndCondIsPressure = [False, False, True, True, False, False]
        flow.bndCondValue = [0, 0, 1, 0, 0, 0]
        flow.boundaryUseMaxMin = [False] * 6
        flow.useSolver = 3
        engines.append(flow)
    O.engines = [ForceResetter()] + engines + [NewtonIntegrator(damping=0.2)]
    O.dt = 1e-6
    O.run(1, True)
    return engines[0], engines[1]


def folder_bytes(path: str) -> int:
    return sum(os.path.getsize(os.path.join(path, f)) for f in os.listdir(path)) if os.path.isdir(path) else 0


def profile(flow: PfvFlowEngine, folder: str, with_boundaries: bool) -> dict[str, float]:
    """PFV's saveVtk in its three parts (the same calls as FlowEngine.saveVtk)."""
    t0 = time.perf_counter()
    with flow._lock:
        scan = flow._bodies.stepped
        state = _vtk_output.read_state(flow.core, scan.ids, scan.radii, scan.wall_ids, O.time)
    t1 = time.perf_counter()
    pores, spheres = _vtk_output.pore_grid(state, with_boundaries), _vtk_output.sphere_grid(state)
    t2 = time.perf_counter()
    os.makedirs(folder, exist_ok=True)
    _vtk_output.write_grid(pores, os.path.join(folder, "profile_out.vtu"), False)
    _vtk_output.write_grid(spheres, os.path.join(folder, "profile_spheres.vtu"), False)
    t3 = time.perf_counter()
    return dict(read=t1 - t0, build=t2 - t1, write=t3 - t2)


def run_size(n: int, opts: dict) -> dict:
    t0 = time.perf_counter()
    yade_flow, pfv_flow = build_scene(n)
    log(
        f"n={n}: scene and first step in {time.perf_counter() - t0:.1f} s, {pfv_flow.nCells()} PFV cells, "
        f"{yade_flow.nCells()} YADE cells"
    )
    root = os.path.join(opts["dir"], f"n{n}")
    os.makedirs(root, exist_ok=True)  # YADE makes the last level of a folder only
    cases = {
        "yade": lambda d: yade_flow.saveVtk(d),
        "pfv": lambda d: pfv_flow.saveVtk(d),
        "pfv-zlib": lambda d: pfv_flow.saveVtk(d, compress=True),
        "yade-boundaries": lambda d: yade_flow.saveVtk(d, True),
        "pfv-boundaries": lambda d: pfv_flow.saveVtk(d, True),
    }
    names = list(cases)
    times = {k: [] for k in names}
    sizes = {}
    parts = []
    for r in range(opts["rounds"]):
        order = names[r % len(names) :] + names[: r % len(names)]
        for name in order:
            folder = os.path.join(root, f"{name}-{r}")
            start = time.perf_counter()
            cases[name](folder)
            times[name].append(time.perf_counter() - start)
            sizes[name] = folder_bytes(folder)
            shutil.rmtree(folder)
        if opts["profile"]:
            parts.append(profile(pfv_flow, os.path.join(root, "profile"), False))
            shutil.rmtree(os.path.join(root, "profile"))
        log(f"n={n} round {r}: " + ", ".join(f"{k} {times[k][-1]:.3f} s" for k in names))
    result = dict(
        n=n,
        cells=pfv_flow.nCells(),
        yade_cells=yade_flow.nCells(),
        median={k: statistics.median(v) for k, v in times.items()},
        bytes=sizes,
        times=times,
    )
    if parts:
        result["parts"] = {k: statistics.median(p[k] for p in parts) for k in parts[0]}
    return result


def report(results: list[dict], opts: dict) -> str:
    command = (
        f"nice -n 10 yade-double -j1 -n -x bench/vtk_output.py --sizes={','.join(map(str, opts['sizes']))} "
        f"--rounds={opts['rounds']}{' --profile' if opts['profile'] else ''}"
    )
    lines = [
        f"`{command}`, median of {opts['rounds']} rounds (wall clock of the call, files in the page cache):",
        "",
        "| N | cells (PFV / YADE) | call | YADE [s] | PFV [s] | PFV / YADE | written (YADE / PFV) |",
        "|---|---|---|---|---|---|---|",
    ]
    for res in results:
        m, b = res["median"], res["bytes"]
        rows = (
            ("saveVtk(dir)", "yade", "pfv"),
            ("saveVtk(dir, compress=True)", "yade", "pfv-zlib"),
            ("saveVtk(dir, True)", "yade-boundaries", "pfv-boundaries"),
        )
        for label, y, p in rows:
            yade_text = f"{m[y]:.3f}" if label != "saveVtk(dir, compress=True)" else f"({m[y]:.3f})"
            lines.append(
                f"| {res['n']:,} | {res['cells']:,} / {res['yade_cells']:,} | `{label}` | {yade_text} | "
                f"{m[p]:.3f} | {m[p] / m[y]:.2f} | {b[y] / 1e6:.1f} MB / {b[p] / 1e6:.1f} MB |"
            )
    if any("parts" in r for r in results):
        lines += [
            "",
            "PFV's `saveVtk(dir)` in parts (median): "
            + "; ".join(
                f"N = {r['n']:,}: read {r['parts']['read']:.3f} s, build {r['parts']['build']:.3f} s, "
                f"write {r['parts']['write']:.3f} s"
                for r in results
                if "parts" in r
            ),
        ]
    return "\n".join(lines)


def main() -> None:
    opts = parse_args(sys.argv[1:])
    log(f"pfv from {os.path.dirname(pfv.__file__)}, sizes {opts['sizes']}, {opts['rounds']} rounds")
    results = [run_size(n, opts) for n in opts["sizes"]]
    shutil.rmtree(opts["dir"], ignore_errors=True)
    print(report(results, opts), flush=True)


main()
