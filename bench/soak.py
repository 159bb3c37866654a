"""Long-run health of the engine: memory (RSS) and flux conservation over many remeshes.

    python3.11 bench/soak.py [--steps=20000] [--spheres=2000] [--remesh=50] [--every=1000]
    (PYTHONPATH=build/python if pfv is not installed; also runs under yade-double -n -x)

A jittered lattice of spheres breathes (periodic uniaxial compression with small random
motion) inside fixed walls, drained at ymin and ymax; the engine remeshes every --remesh steps.
Prints, every --every steps: RSS, remesh count, and the conservation error
|Qout + sum(dV/dt)| / sum|dV/dt| (outflow must equal the volume lost by the pores).
Exit code 1 if RSS grew by more than --max-growth MB after the first tenth of the run, or if
the conservation error exceeded --max-error at any step.
"""
import resource  # noqa: F401  (peak RSS is also available there)
import sys

import numpy as np
import pfv
from pfv_testing.cli import option


def rss_mb():
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * 4096 / 2**20


def main():
    steps, n_target = option(sys.argv[1:], "steps", 20000), option(sys.argv[1:], "spheres", 2000)
    remesh, every = option(sys.argv[1:], "remesh", 50), option(sys.argv[1:], "every", 1000)
    max_growth, max_error = option(sys.argv[1:], "max-growth", 5.0), option(sys.argv[1:], "max-error", 1e-8)
    m = max(2, round(n_target ** (1 / 3)))
    rng = np.random.default_rng(7)
    base = (np.indices((m, m, m)).reshape(3, -1).T + 0.5) / m
    base += rng.uniform(-0.05, 0.05, base.shape) / m
    radii = rng.uniform(0.3, 0.4, len(base)) / m
    engine = pfv.Engine()
    engine.bnd_is_pressure = [False, False, True, True, False, False]
    engine.bnd_value = [0.0, 0.0, 1.0, 0.0, 0.0, 0.0]
    engine.mesh_update_interval = remesh
    walls = [0, 1, 0, 1, 0, 1]
    dt, worst, rss_ref = 1e-3, 0.0, None
    print(f"soak: {len(base)} spheres, {steps} steps, remesh every {remesh}")
    for i in range(steps):
        squeeze = 1 - 0.01 * (1 - np.cos(2 * np.pi * i / 2000))  # y compressed by up to 2 %
        pos = base.copy()
        pos[:, 1] = 0.5 + (pos[:, 1] - 0.5) * squeeze
        pos += rng.normal(0, 1e-5 / m, pos.shape)
        engine.step(pos, radii, walls, dt)
        out = engine.boundary_flux(2) + engine.boundary_flux(3)
        rate = engine.volume_rate_total()
        if i > 0 and abs(rate) > 0:
            scale = max(abs(rate), abs(engine.boundary_flux(2)))
            worst = max(worst, abs(out + rate) / scale)
        if i == steps // 10:
            rss_ref = rss_mb()
        if i % every == 0 or i == steps - 1:
            print(
                f"step {i:6d}  RSS {rss_mb():8.1f} MB  remeshes {engine.remesh_count:5d}  "
                f"worst conservation error {worst:.2e}",
                flush=True,
            )
    growth = rss_mb() - rss_ref
    print(f"RSS growth after the first tenth: {growth:.2f} MB; worst conservation error {worst:.2e}")
    ok = growth <= max_growth and worst <= max_error
    print("soak", "passed" if ok else "FAILED")
    return 0 if ok else 1


if __name__ == "__main__" or "yade" in sys.modules:
    sys.exit(main())
