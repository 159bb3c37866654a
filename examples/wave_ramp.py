# -*- coding: utf-8 -*-
"""The half-wavelength sinusoid with a ramped amplitude (thesis sections 6.2-6.3), dense and loose:
p_top = A(t) (1 + cos(pi x / L)), A(t) = rate t.

    yade-double -n -x examples/wave_ramp.py [--quick] [--rate=100] [--duration=20] [--out=DIR]

Both samples (phi_c1 = 1 and 30 deg; phi_c2 = 30 deg) under the same ramp. The amplitude at which a
sample becomes unstable is where its kinetic energy first exceeds 100 times its level in the first
second (the thesis reads it off the KE curve: 1500 Pa dense, about a quarter of that loose); the
ratio of the two is printed against the thesis' about 4.
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

o = seabed_wave.options(sys.argv[1:], dict(rate=100.0, duration=20.0, out="wave-ramp"))
num = 1000 if o["quick"] else 5000
unstable = {}
for name, friction in (("dense", 1.0), ("loose", 30.0)):
    sample = seabed_sample.prepare(num, friction)
    load = waves.HalfWave(amplitude=0.0, rate=o["rate"], length=sample["box"][0])
    seabed_wave.run(f"ramp-{name}", load, sample, o["duration"], os.path.join(o["out"], name), 1.0)
    t, ke = np.asarray(plot.data["t"]), np.asarray(plot.data["KE"])
    quiet = np.median(ke[t <= 1.0]) if np.any(t <= 1.0) else ke[0]
    above = np.flatnonzero((t > 1.0) & (ke > 100 * quiet))
    unstable[name] = float(load.amplitude_at(t[above[0]])) if len(above) else float("nan")
    print(f"{name}: unstable at A = {unstable[name]:.0f} Pa")
ratio = unstable["dense"] / unstable["loose"]
print(f"instability amplitude dense / loose = {ratio:.2f} (thesis: about 4)")
with open(os.path.join(o["out"], "instability.json"), "w") as f:
    json.dump(dict(unstable_amplitude=unstable, ratio=ratio, thesis_ratio=4.0), f, indent=1)
sys.exit(0)
