"""The Stokes reference on a random periodic packing and the flux through PFV's throats: the CI case.

    PYTHONPATH=build/python:tests yade-double -n -x tests/yade/validation/test_stokes_random_quick.py  (exit 0 = pass)

Runs ``python3 -m validation.stokes.periodic_random --quick`` from the repository's root with Debian's
/usr/bin/python3 (dolfinx, dolfinx-mpc, gmsh and the pfv build on PYTHONPATH) on the stored packing
small_mono_c40_s11 (16 equal spheres, solid fraction 0.4, gaps of at least 3 %) at h = 0.1, and compares with
tests/data/stokes_random_quick.json (``--quick --write-reference`` regenerates it): the DOFs and kappa of the same
mesh (1e-6), PFV's kappa (1e-9), the mean velocity rebuilt from the FEM's flux through every throat of PFV's
triangulation within 1 % of the FEM's volume mean, the fluxes out of every pore balanced to 1 %, PFV's own throat
fluxes giving its mean velocity to 1e-12, every throat's constriction open (no contact in this packing), no folded
cell, and the stored packing's solid fraction and smallest gap. Under a minute.
"""
import os
import subprocess

from pfv_testing import checks, paths

env = dict(os.environ, OMP_NUM_THREADS='1', OPENBLAS_NUM_THREADS='1')
command = ['/usr/bin/python3', '-m', 'validation.stokes.periodic_random', '--quick']
done = subprocess.run(command, env=env, cwd=paths.REPO)
checks.check('periodic_random --quick passed', done.returncode == 0, '(exit code %d)' % done.returncode)
checks.report('Stokes random periodic')
