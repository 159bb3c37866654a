"""Saves the pressure system of bench/growth.py's scene (jittered lattice, permeameter along y) for pfv_amg_solve.

    OMP_NUM_THREADS=1 PYTHONPATH=build/python /usr/bin/python3.11 bench/amg/save_lattice_system.py N FOLDER

One step of the C++ engine (no YADE) with the double CHOLMOD factor, then core.save_system(FOLDER): G, b and the
direct solution, which `build/pfv_amg_solve FOLDER` compares its own against. Prints the engine's remesh stages.
"""
import os
import sys

import pfv
from pfv_testing.lattice import jittered_lattice

n, folder = int(float(sys.argv[1])), sys.argv[2]
centres, radii = jittered_lattice(n, 1)
lo, hi = (centres - radii[:, None]).min(axis=0), (centres + radii[:, None]).max(axis=0)
engine = pfv.Engine()
engine.bnd_is_pressure = [False, False, True, True, False, False]
engine.bnd_value = [0.0, 0.0, 1.0, 0.0, 0.0, 0.0]
engine.solver = "cholesky"
engine.mixed_precision = False
engine.step(centres, radii, [lo[0], hi[0], lo[1], hi[1], lo[2], hi[2]], 1e-3)
os.makedirs(folder, exist_ok=True)
engine.save_system(folder)
print({k: round(v, 3) for k, v in engine.remesh_times().items() if v > 0})
