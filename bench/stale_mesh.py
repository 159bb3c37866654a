"""The error of a mesh run on after the spheres moved, against a mesh built at their current positions.

    PYTHONPATH=build/python /usr/bin/python3 bench/stale_mesh.py [N] [--drifts=0.01,0.02,0.05,0.1,0.2]

The benchmarks' jittered lattice (N spheres, default 3000; spacing 1), a permeameter along y (p = 100 on ymin, 0 on
ymax, the walls 0.2 beyond the spheres' extent), dV/dt negligible (a time step of 1e10 s): the flux and the forces
are those of the positions alone. Every sphere moves along its own random direction by the drift (in spacings) in
100 equal steps under the mesh of the start, which never remeshes. Printed, one row per drift: the cells and the
volume inside out (pfv.Engine's inverted_cells and inverted_volume_fraction), the relative error of the flux through
ymin and the relative L2 error of the sphere forces against a fresh engine at the final positions, and whether the
2 % inverted-volume rule forced a remesh. The table of doc/model.md ("Cells turned inside out between remeshes").
"""
import sys

import numpy as np

from pfv_testing.cli import option
from pfv_testing.lattice import jittered_lattice, permeameter_engine, walls_around

STEPS = 100
STATIC = 1e10


def row(n, drift):
    pos, rad = jittered_lattice(n)
    walls = walls_around(pos, rad, 0.2)
    lo, hi = np.array(walls[0::2]), np.array(walls[1::2])
    rng = np.random.default_rng(3)
    d = rng.normal(size=pos.shape)
    d *= (drift / STEPS) / np.linalg.norm(d, axis=1)[:, None]
    keep_in = (lo + rad[:, None] * 1.01, hi - rad[:, None] * 1.01)
    stale = permeameter_engine()
    for _ in range(STEPS):
        stale.step(pos, rad, walls, STATIC)
        pos = np.clip(pos + d, *keep_in)
    stale.step(pos, rad, walls, STATIC)
    fresh = permeameter_engine()
    fresh.step(pos, rad, walls, STATIC)
    fa, fb = stale.forces()[:n], fresh.forces()[:n]
    return dict(
        cells=stale.inverted_cells / stale.n_cells(),
        volume=stale.inverted_volume_fraction,
        flux=abs(stale.boundary_flux(2) / fresh.boundary_flux(2) - 1),
        forces=np.linalg.norm(fa - fb) / np.linalg.norm(fb),
        forced=stale.inversion_remeshes,
    )


def main(argv):
    sizes = [a for a in argv if not a.startswith('--')]
    n = int(float(sizes[0])) if sizes else 3000
    drifts = [float(x) for x in option(argv, 'drifts', '0.01,0.02,0.05,0.1,0.2').split(',')]
    print(
        '| motion since the remesh [spacings] | cells inside out | volume inside out | flux error '
        '| sphere forces, relative L2 error | forced remeshes |'
    )
    print('|---|---|---|---|---|---|')
    for drift in drifts:
        r = row(n, drift)
        print(
            f"| {drift:g} | {100 * r['cells']:.2g} % | {100 * r['volume']:.2g} % | {100 * r['flux']:.2g} % "
            f"| {100 * r['forces']:.2g} % | {r['forced']} |",
            flush=True,
        )
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
