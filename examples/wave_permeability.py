# -*- coding: utf-8 -*-
"""The role of permeability (thesis section 6.3.4, claims 29 and 30): the loose bed under a constant
half-wave p_top = A (1 + cos(pi x / L)), A = 300 Pa, at three permeabilities, and once more with the
shear viscous forces.

    yade-double -n -x examples/wave_permeability.py [--quick] [--amplitude=300] [--duration=10]
                                                    [--factors=0.25,1,4] [--shear_viscosity=0.001]
                                                    [--out=DIR]

The permeability is scaled by FlowEngine.permeabilityFactor (every conductance times the factor), the
thesis' three unstated Kd values by three factors (default 1/4, 1, 4). For each run: the time the bed
spends liquefied (mean grad H / i_c over the 25 sensor pairs above 0.8), its final porosity and
settlement, and the largest horizontal displacement on the symmetry axis; the thesis expects no
liquefaction for the most permeable bed, a duration growing as 1/Kd for the others, and lower final
porosity for lower Kd. The run at factor 1 is repeated with viscousShear=True: the thesis finds n(t)
unchanged (claim 30); the largest |n_shear(t) - n(t)| is reported. The shear term takes the
viscosity --shear_viscosity (FlowEngine.shear_viscosity; default water's 1e-3 Pa s as in the
thesis' test, while the pressure term keeps the bed's scaled viscosity; 0 = the same viscosity).
Results in DIR/permeability.json.
"""
import json
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(sys.argv[0])))  # yade -x: argv[0] is the script
import seabed_sample  # noqa: E402
import seabed_wave  # noqa: E402
from yade import plot  # noqa: E402
from pfv import waves  # noqa: E402


def liquefied_seconds(data):
    """Simulated time during which the mean grad H / i_c over the sensor pairs exceeds the threshold."""
    t = np.asarray(data["t"])
    ratio = np.mean([data[k] for k in data if k.startswith("r_")], axis=0)
    dt = np.diff(t, prepend=t[0])
    return float(np.sum(dt[ratio > seabed_wave.LIQUEFIED]))


o = seabed_wave.options(
    sys.argv[1:],
    dict(amplitude=300.0, duration=10.0, factors="0.25,1,4", shear_viscosity=1e-3, out="wave-permeability"),
)
num = 1000 if o["quick"] else 5000
sample = seabed_sample.prepare(num, 30.0)
factors = [float(f) for f in o["factors"].split(",")]
runs = [(f, False) for f in factors] + [(1.0, True)]
results, porosity = [], {}
for factor, shear in runs:
    name = f"K{factor:g}" + ("-shear" if shear else "")
    load = waves.HalfWave(amplitude=o["amplitude"], length=sample["box"][0])
    settings = dict(permeabilityFactor=factor, viscousShear=shear)
    if shear:
        settings["shear_viscosity"] = o["shear_viscosity"]
    summary = seabed_wave.run(name, load, sample, o["duration"], os.path.join(o["out"], name), 1.0, settings)
    porosity[name] = (np.asarray(plot.data["t"]), np.asarray(plot.data["porosity"]))
    results.append(
        dict(
            name=name,
            permeability_factor=factor,
            viscous_shear=shear,
            shear_viscosity=o["shear_viscosity"] if shear else None,
            liquefied_seconds=liquefied_seconds(plot.data),
            final_porosity=summary["final_porosity"],
            settlement=summary["settlement"],
            max_axis_dx=summary["max_axis_dx"],
            peak_mean_ratio=summary["peak_mean_ratio"],
            wall_seconds=summary["wall_seconds"],
        )
    )
    print(
        f"{name}: liquefied for {results[-1]['liquefied_seconds']:.2f} s, n -> {summary['final_porosity']:.4f}, "
        f"settlement {summary['settlement']:.4f} m, max axis dx {summary['max_axis_dx']:.4f} m"
    )
t0, n0 = porosity["K1"]
t1, n1 = porosity["K1-shear"]
shear_difference = float(np.max(np.abs(np.interp(t0, t1, n1) - n0)))
print(f"viscous shear: largest |n_shear(t) - n(t)| = {shear_difference:.2e}")
with open(os.path.join(o["out"], "permeability.json"), "w") as f:
    json.dump(
        dict(amplitude=o["amplitude"], grains=num, runs=results, shear_porosity_difference=shear_difference),
        f,
        indent=1,
    )
sys.exit(0)
