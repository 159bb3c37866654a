"""bench/growth.py --quick runs every engine at every quick size and writes its report (no timing is asserted).

    yade-double -n -x tests/yade/bench/test_growth_quick.py      (exit 0 = pass)

Runs the growth benchmark's quick mode (3 000 and 6 000 spheres with YADE, PFV and PFV multigrid; 12 000 PFV only) in
a subprocess into a temporary folder and checks: exit 0; no child failed; one row per (size, engine) with positive,
finite first-step, remesh and dry-step times and peak RSS; PFV's rows name the solver it used (CHOLMOD for 'auto' at
these sizes, multigrid when asked); the report holds the PFV / YADE ratio table and the fitted exponents; the figure
exists.
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


with tempfile.TemporaryDirectory(prefix="pfv-growth-") as work:
    report, data, png = (os.path.join(work, name) for name in ("growth.md", "growth.json", "growth.png"))
    run = subprocess.run(
        [
            "yade-double",
            "-n",
            "-x",
            os.path.join(BENCH, "growth.py"),
            "--quick",
            f"--out={report}",
            f"--json={data}",
            f"--figure={png}",
        ],
        capture_output=True,
        text=True,
        timeout=1200,
    )
    checks.check("growth.py --quick exits with 0", run.returncode == 0, (run.stdout + run.stderr)[-800:])
    if run.returncode == 0:
        with open(data) as f:
            measured = json.load(f)
        checks.check("no child failed", not any(c.get("failed") for c in measured["timing"] + measured["memory"]))
        # The report's main table: | N | engine | first | remesh | flow | dry | coupled/dry | peak | solver |
        text = open(report).read()
        rows = {}
        for line in text.splitlines():
            cells = [c.strip() for c in line.strip().strip("|").split("|")]
            digits = cells[0].replace("\u202f", "")
            if len(cells) == 9 and digits.isdigit():
                rows[(int(digits), cells[1])] = cells
        expected = {(n, k) for n in (3000, 6000) for k in ("yade", "pfv", "pfv-multigrid")}
        expected |= {(12000, "pfv"), (12000, "pfv-multigrid")}
        checks.check("one row per size and engine", set(rows) == expected, str(sorted(rows)))
        for (n, kind), cells in sorted(rows.items()):
            numbers = [float(c) for c in (cells[2], cells[3], cells[5], cells[7])]  # first, remesh, dry, peak
            checks.check(
                f"N={n} {kind}: positive first step, remesh, dry step and peak RSS",
                all(map(positive, numbers)),
                str(cells),
            )
            ratio, spread = cells[6].split(" ", 1)
            low, high = (float(x) for x in spread.strip("()").split("\u2013"))
            checks.check(
                f"N={n} {kind}: coupled / dry, the median of the blocks, within their range",
                0 < low <= float(ratio) <= high,
                cells[6],
            )
            if kind == "pfv":
                checks.check(f"N={n} pfv: auto chose CHOLMOD", cells[8].startswith("cholesky"), cells[8])
            if kind == "pfv-multigrid":
                checks.check(f"N={n} pfv-multigrid: multigrid", cells[8].startswith("multigrid"), cells[8])
        checks.check("report has the ratio table", "PFV / YADE:" in text)
        checks.check("report has the fitted exponents", "Fitted exponents" in text)
        checks.check("figure written", os.path.exists(png) and os.path.getsize(png) > 0)
checks.report("growth")
