# -*- coding: utf-8 -*-
"""A standing wave on the loose seabed (thesis section 6.4): p_top = A sin(2 pi t / T) cos(pi x / L).

    yade-double -n -x examples/wave_standing.py [--quick] [--amplitude=150] [--period=1.0] [--duration=...]
                                                [--friction=30] [--viscous_shear=0] [--out=DIR]

Defaults: the thesis' base case, A = 150 Pa, T = 1 s, loose sample (phi_c1 = 30 deg), 5000 grains
(--quick: 1000), 10 periods (--quick: 4). --viscous_shear=1 adds the shear viscous forces (claim 30).
Outputs and the liquefaction criterion: seabed_wave.py.
yade-batch runs it over a table of amplitudes and periods (wave_map.table); wave_map.py draws the map.
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(sys.argv[0])))  # yade -x: argv[0] is the script
import seabed_sample  # noqa: E402
import seabed_wave  # noqa: E402
from yade import O, utils  # noqa: E402
from pfv import waves  # noqa: E402

# yade-batch passes a table line's values through readParamsFromTable; a plain run uses the defaults.
utils.readParamsFromTable(amplitude=150.0, period=1.0, quick=0, duration=0.0, noTableOk=True)
from yade.params import table  # noqa: E402

o = seabed_wave.options(
    sys.argv[1:],
    dict(
        amplitude=float(table.amplitude),
        period=float(table.period),
        duration=float(table.duration),
        friction=30.0,
        viscous_shear=0,
        out="",
    ),
)
o["quick"] = o["quick"] or bool(int(table.quick))
if utils.runningInBatch() and not o["out"]:  # a yade-batch job: its outputs go with the map's
    o["out"] = os.path.join("wave-map", O.tags["description"])
num = 1000 if o["quick"] else 5000
duration = o["duration"] or (4 if o["quick"] else 10) * o["period"]
sample = seabed_sample.prepare(num, o["friction"])
L = sample["box"][0]
load = waves.StandingWave(amplitude=o["amplitude"], period=o["period"], length=L)
out = o["out"] or f"wave-standing-A{o['amplitude']:g}-T{o['period']:g}" + ("-quick" if o["quick"] else "")
settings = dict(viscousShear=True) if o["viscous_shear"] else None
seabed_wave.run("standing", load, sample, duration, out, o["period"], settings)
sys.exit(0)
