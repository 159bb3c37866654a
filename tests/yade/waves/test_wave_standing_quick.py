"""A quick standing wave on the loose seabed liquefies at a large amplitude and not at a small one
(thesis section 6.4, claim 32: 400 Pa always liquefies, 50 Pa never).

    yade-double -n -x tests/yade/waves/test_wave_standing_quick.py        (exit 0 = pass)

examples/wave_standing.py --quick (1000 grains deposited at 30 deg, n = 0.430, i_c = 0.911), T = 1 s,
3 s of simulated time each. Liquefied: the period-mean of grad H / i_c over the 30 sensor pairs
exceeds 0.8 (seabed_wave.py). Measured: A = 400 Pa 0.861 (liquefied, still rising), A = 50 Pa
0.435; the test also asks the large amplitude's peak to be at least 1.5 x the small one's.

The time-step guard must not warn: the example's first step, taken before the collective viscous limit
is known, is at most half of the guard's 0.8 x limit on this bed (collective limit 0.58 dt_MV), so that
beds with half this bed's limit stay quiet too (the dense 5000-grain bed of the full-size runs: 0.31 dt_MV,
in summary.json of examples/wave_standing.py --friction=1 --duration=0.002).
"""
import json
import os
import subprocess
import tempfile

from pfv_testing import paths, robustness as rb

script = paths.example("wave_standing.py")
work = tempfile.mkdtemp(prefix="pfv-wave-standing-")
peaks = {}
for amplitude in (400, 50):
    out = os.path.join(work, f"A{amplitude}")
    done = subprocess.run(
        [
            "yade-double",
            "-n",
            "-x",
            script,
            "--quick",
            f"--amplitude={amplitude}",
            "--period=1",
            "--duration=3",
            f"--out={out}",
        ],
        env=dict(os.environ, OMP_NUM_THREADS="1"),
        capture_output=True,
        text=True,
        timeout=1200,
    )
    if done.returncode != 0:
        print(done.stdout[-3000:], done.stderr[-3000:])
    with open(os.path.join(out, "summary.json")) as f:
        s = json.load(f)
    peaks[amplitude] = s["peak_mean_ratio"]
    steps = s["time_steps"]
    rb.check(f"A = {amplitude} Pa: no TimeStepWarning", "TimeStepWarning" not in done.stderr + done.stdout)
    margin = steps["first_step"] / (0.8 * steps["collective_viscous"])
    rb.check(
        f"A = {amplitude} Pa: the first step is at most half the guard's limit",
        margin <= 0.5,
        f"({margin:.2f}; collective limit {steps['collective_viscous'] / steps['viscous']:.2f} dt_MV)",
    )
    print(
        f"A = {amplitude} Pa: peak period-mean grad H / i_c {s['peak_mean_ratio']:.3f}, "
        f"n {s['porosity0']:.3f} -> {s['final_porosity']:.3f}, {s['steps']} steps"
    )
rb.check("A = 400 Pa liquefies (grad H / i_c > 0.8)", peaks[400] > 0.8, f"({peaks[400]:.3f})")
rb.check("A = 50 Pa does not", peaks[50] < 0.8, f"({peaks[50]:.3f})")
rb.check(
    "the large amplitude drives the gradient well above the small one",
    peaks[400] >= 1.5 * peaks[50],
    f"({peaks[400]:.3f} vs {peaks[50]:.3f})",
)
rb.report("standing wave")
