# -*- coding: utf-8 -*-
"""The half-wavelength sinusoid with a ramped amplitude (thesis sections 6.2-6.3), dense and loose:
p_top = A(t) (1 + cos(pi x / L)), A(t) = rate t.

    yade-double -n -x examples/wave_ramp.py [--quick] [--rate=100] [--duration=20] [--out=DIR] [--bed=dense|loose]
    yade-double -n -x examples/wave_ramp.py --from=DIR     (the criterion again on the records in DIR)

--bed runs one of the two beds only (two processes run the beds side by side on two cores, each
with its own --duration: the loose bed fails at a fraction of the dense bed's amplitude); --from
then reads both records from DIR (with --bed, that bed's only), also the time series a run stopped early
leaves behind (checkpointed as it goes; the grain count then comes from --quick).

Both samples (phi_c1 = 1 and 30 deg; phi_c2 = 30 deg) under the same ramp. A sample becomes unstable
at the amplitude where the root-mean-square grain velocity sqrt(2 KE / M) exceeds 1 % of sqrt(g d50),
the velocity scale of a grain falling by its own size, after having been below it (a bed still
settling from its deposition when the ramp starts is not yet failing; pfv.diagnostics.instability_onset):
grains at rest on a stable bed
move orders of magnitude slower, a failing bed faster (the thesis reads the instability off the jump of
its KE curve: 1500 Pa dense, about a quarter of that loose). The amplitudes at 0.5 % and 2 % are
printed beside it to show how much the threshold matters; the ratio dense / loose is printed against
the thesis' about 4, and everything is written to DIR/instability.json.
"""
import json
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(sys.argv[0])))  # yade -x: argv[0] is the script
import seabed_sample  # noqa: E402
import seabed_wave  # noqa: E402
from pfv import diagnostics  # noqa: E402

THRESHOLDS = (0.005, 0.01, 0.02)  # of sqrt(g d50); 0.01 is the criterion
CRITERION = 0.01


def instability_amplitudes(ke, amplitude, mass, d50):
    """{threshold: amplitude (Pa) where the bed, once at rest, moves faster than threshold * sqrt(g d50)}."""
    return {f: diagnostics.instability_onset(amplitude, ke, mass, d50, f, seabed_sample.GRAVITY) for f in THRESHOLDS}


def read_record(folder):
    """t, KE and A of a timeseries.csv written by seabed_wave.run (plot.saveDataTxt)."""
    path = os.path.join(folder, "timeseries.csv")
    with open(path) as f:
        head = f.readline().lstrip("#").split()
    data = np.loadtxt(path)
    col = {h: i for i, h in enumerate(head)}
    return data[:, col["t"]], data[:, col["KE"]], data[:, col["A"]]


def sample_mass(sample):
    rho = sample["grains"]["density"]
    return sum(4 / 3 * math.pi * s[3] ** 3 * rho for s in sample["spheres"])


o = seabed_wave.options(sys.argv[1:], dict(rate=100.0, duration=20.0, out="wave-ramp", bed="", **{"from": ""}))
folder = o["from"] or o["out"]
num = 1000 if o["quick"] else 5000
BEDS = (("dense", 1.0), ("loose", 30.0))
if o["bed"] and o["bed"] not in dict(BEDS):
    raise SystemExit(f"--bed={o['bed']}: expected dense or loose")
unstable = {}
for name, friction in BEDS:
    if o["bed"] and name != o["bed"]:
        continue
    partial = False
    if o["from"]:
        summary = os.path.join(folder, name, "summary.json")
        if os.path.exists(summary):
            with open(summary) as f:
                num = json.load(f)["grains"]
        else:  # a run stopped early leaves its checkpointed time series only (size from --quick)
            partial = True
    sample = seabed_sample.prepare(num, friction)
    if not o["from"]:
        from yade import plot
        from pfv import waves

        load = waves.HalfWave(amplitude=0.0, rate=o["rate"], length=sample["box"][0])
        seabed_wave.run(f"ramp-{name}", load, sample, o["duration"], os.path.join(folder, name), 1.0)
        record = plot.data["t"], plot.data["KE"], plot.data["A"]
    else:
        record = read_record(os.path.join(folder, name))
    unstable[name] = instability_amplitudes(record[1], record[2], sample_mass(sample), sample["grains"]["d50"])
    if partial:
        print(
            f"{name}: no summary.json, the run did not finish: its record ends at t = {record[0][-1]:.2f} s, "
            f"A = {record[2][-1]:.0f} Pa ({num} grains assumed from --quick)"
        )
    print(
        f"{name} (n = {sample['porosity']:.3f}): unstable at A = {unstable[name][CRITERION]:.0f} Pa "
        f"(thresholds {', '.join(f'{100 * f:g} %: {a:.0f} Pa' for f, a in unstable[name].items())})"
    )
if o["bed"]:
    sys.exit(0)  # one bed: the ratio comes from --from=DIR once both records are there
ratios = {f: unstable["dense"][f] / unstable["loose"][f] for f in THRESHOLDS}
print(
    f"instability amplitude dense / loose = {ratios[CRITERION]:.2f} (thesis: about 4; thresholds "
    f"{', '.join(f'{100 * f:g} %: {r:.2f}' for f, r in ratios.items())})"
)
with open(os.path.join(folder, "instability.json"), "w") as f:
    json.dump(
        dict(
            criterion="rms grain velocity > threshold * sqrt(g d50)",
            threshold=CRITERION,
            unstable_amplitude={k: v[CRITERION] for k, v in unstable.items()},
            ratio=ratios[CRITERION],
            by_threshold={
                str(t): dict(dense=unstable["dense"][t], loose=unstable["loose"][t], ratio=ratios[t])
                for t in THRESHOLDS
            },
            thesis=dict(dense=1500.0, ratio=4.0),
        ),
        f,
        indent=1,
    )
sys.exit(0)
