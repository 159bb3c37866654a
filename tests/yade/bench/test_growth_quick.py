"""bench/growth.py --quick runs every engine at every quick size and writes its report (no timing is asserted), on
the static lattice and in a moving one (--motion=drift at one and two threads).

    yade-double -n -x tests/yade/bench/test_growth_quick.py      (exit 0 = pass)

Runs the growth benchmark's quick mode (3 000 and 6 000 spheres with YADE, PFV and PFV multigrid; 12 000 PFV only) in
a subprocess into a temporary folder and checks: exit 0; no child failed; one row per (size, engine, threads) with
positive, finite first-step, remesh and dry-step times, and peak RSS at one thread; PFV's rows name the solver it used
(CHOLMOD for 'auto' at these sizes, multigrid when asked) and count its unscheduled remeshes (none: cells inside out
are run on until the 2 % rule, which this drift does not reach); in the moving packing multigrid's steady steps need
fewer CG iterations than its first step from zero (the start extrapolated from the history); the report holds the
PFV / YADE ratio table and the fitted exponents; the figure exists.
"""
import json
import math
import os
import subprocess
import sys
import tempfile

from pfv_testing import checks, paths

HERE = os.path.dirname(os.path.abspath(sys.argv[0] if sys.argv and sys.argv[0].endswith(".py") else __file__))
BENCH = paths.BENCH


def positive(x):
    return isinstance(x, (int, float)) and math.isfinite(x) and x > 0


def table_rows(text):
    """The report's main table: | N | engine | threads | first | remesh | flow | dry | coupled/dry | peak | solver |
    unscheduled |, by (N, engine, threads)."""
    rows = {}
    for line in text.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        digits = cells[0].replace("\u202f", "")
        if len(cells) == 11 and digits.isdigit():
            rows[(int(digits), cells[1], int(cells[2]))] = cells
    return rows


def check_row(tag, n, kind, threads, cells, moving):
    numbers = [float(c) for c in (cells[3], cells[4], cells[6])]  # first, remesh, dry
    if threads == 1:
        numbers.append(float(cells[8]))  # peak RSS: measured at one thread
    checks.check(
        f"{tag} N={n} {kind} -j{threads}: positive first step, remesh, dry step (and peak RSS)",
        all(map(positive, numbers)),
        str(cells),
    )
    ratio, spread = cells[7].split(" ", 1)
    low, high = (float(x) for x in spread.strip("()").split("\u2013"))
    checks.check(
        f"{tag} N={n} {kind} -j{threads}: coupled / dry, the median of the blocks, within their range",
        0 < low <= float(ratio) <= high,
        cells[7],
    )
    if kind == "pfv":
        checks.check(f"{tag} N={n} pfv: auto chose CHOLMOD", cells[9].startswith("cholesky"), cells[9])
    if kind == "pfv-multigrid":
        checks.check(f"{tag} N={n} pfv-multigrid: multigrid", cells[9].startswith("multigrid"), cells[9])
        if moving:  # "multigrid, CG iterations S per steady step, F at the first step, R after the remesh"
            words = cells[9].replace(",", "").split()
            steady, first = float(words[3]), float(words[7])
            checks.check(
                f"{tag} N={n}: fewer CG iterations per steady step than from zero at the first step",
                0 < steady < first,
                cells[9],
            )
    if kind != "yade":
        checks.check(f"{tag} N={n} {kind}: no unscheduled remesh", cells[10] == "0", cells[10])


def run(tag, work, extra, threads):
    report, data, png = (os.path.join(work, f"{tag}.{ext}") for ext in ("md", "json", "png"))
    run = subprocess.run(
        ["yade-double", "-n", "-x", os.path.join(BENCH, "growth.py"), "--quick"]
        + extra
        + [f"--out={report}", f"--json={data}", f"--figure={png}"],
        capture_output=True,
        text=True,
        timeout=1200,
    )
    checks.check(f"{tag}: growth.py --quick exits with 0", run.returncode == 0, (run.stdout + run.stderr)[-800:])
    if run.returncode != 0:
        return
    with open(data) as f:
        measured = json.load(f)
    checks.check(f"{tag}: no child failed", not any(c.get("failed") for c in measured["timing"] + measured["memory"]))
    text = open(report).read()
    rows = table_rows(text)
    expected = {(n, k, t) for n in (3000, 6000) for k in ("yade", "pfv", "pfv-multigrid") for t in threads}
    expected |= {(12000, k, t) for k in ("pfv", "pfv-multigrid") for t in threads}
    checks.check(f"{tag}: one row per size, engine and thread count", set(rows) == expected, str(sorted(rows)))
    for (n, kind, t), cells in sorted(rows.items()):
        check_row(tag, n, kind, t, cells, moving=tag != "static")
    checks.check(f"{tag}: report has the ratio table", "PFV / YADE:" in text)
    checks.check(f"{tag}: report has the fitted exponents", "Fitted exponents" in text)
    checks.check(f"{tag}: figure written", os.path.exists(png) and os.path.getsize(png) > 0)


with tempfile.TemporaryDirectory(prefix="pfv-growth-") as work:
    run("static", work, [], (1,))
    run("drift", work, ["--motion=drift", "--threads=1,2"], (1, 2))
checks.report("growth")
