"""The wave map's tooling end to end: yade-batch runs a two-line table of examples/wave_standing.py,
the Slurm array script runs one line by hand (SLURM_ARRAY_TASK_ID), and examples/wave_map.py
collects the jobs into the map (PNG) with claim 32 beside it.

    yade-double -n -x tests/yade/waves/test_wave_map_batch.py        (exit 0 = pass)

The jobs are 0.05 s of simulated time each (a few hundred steps): this tests the plumbing and the
outputs, not liquefaction (tests/yade/waves/test_wave_standing_quick.py does).
"""
import json
import os
import subprocess
import tempfile

from pfv_testing import paths, robustness as rb

TABLE = os.path.join(paths.TEST_DATA, "wave_map_test.table")
EXAMPLES = paths.EXAMPLES
work = tempfile.mkdtemp(prefix="pfv-wave-map-")
env = dict(os.environ, OMP_NUM_THREADS="1")


def run(cmd, cwd):
    done = subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True, timeout=900)
    if done.returncode != 0:
        print(done.stdout[-3000:], done.stderr[-3000:])
    return done


batch = run(["yade-batch", "-j", "1", TABLE, os.path.join(EXAMPLES, "wave_standing.py")], work)
rb.check("yade-batch runs the table", batch.returncode == 0, f"(exit {batch.returncode})")
summaries = {}
for name in ("test-A50-T0.5", "test-A400-T1"):
    path = os.path.join(work, "wave-map", name, "summary.json")
    if os.path.exists(path):
        with open(path) as f:
            summaries[name] = json.load(f)
rb.check("each job wrote its summary under wave-map/<description>", len(summaries) == 2, f"({sorted(summaries)})")
rb.check(
    "each job ran its line's amplitude and period",
    all(
        ("amplitude=%s," % a) in summaries.get(n, {}).get("profile", "")
        and ("period=%s," % t) in summaries.get(n, {}).get("profile", "")
        for n, a, t in (("test-A50-T0.5", "50.0", "0.5"), ("test-A400-T1", "400.0", "1.0"))
    ),
)
for name in summaries:
    folder = os.path.join(work, "wave-map", name)
    rb.check(
        f"{name}: time series, profiles and plot written",
        all(os.path.getsize(os.path.join(folder, f)) > 0 for f in ("timeseries.csv", "profiles.json", "waves.png")),
    )

slurm_dir = tempfile.mkdtemp(prefix="pfv-wave-slurm-")
env_task = dict(env, SLURM_ARRAY_TASK_ID="2")
done = subprocess.run(
    ["bash", os.path.join(EXAMPLES, "wave_map.slurm"), TABLE],
    cwd=slurm_dir,
    env=env_task,
    capture_output=True,
    text=True,
    timeout=900,
)
ran = os.path.join(slurm_dir, "wave-map")
made = sorted(os.listdir(ran)) if os.path.isdir(ran) else []
rb.check(
    "the Slurm array script runs only its task's line",
    done.returncode == 0 and made == ["test-A400-T1"],
    f"(exit {done.returncode}, ran {made})",
)

collect = run(
    ["yade-double", "-n", "-x", os.path.join(EXAMPLES, "wave_map.py"), "--dir=wave-map", "--out=map.png"], work
)
rows = [line for line in collect.stdout.splitlines() if line.startswith(("| 50 |", "| 400 |"))]
rb.check(
    "wave_map.py draws the map and lists both jobs with the thesis' verdict",
    collect.returncode == 0
    and os.path.getsize(os.path.join(work, "map.png")) > 0
    and len(rows) == 2
    and rows[0].endswith("| stable |")
    and rows[1].endswith("| liquefied |"),
    f"({rows})",
)
rb.report("wave map batch")
