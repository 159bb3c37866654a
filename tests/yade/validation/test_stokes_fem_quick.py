"""The Stokes FEM reference on its CI case: the 8-sphere cubic packing on one coarse mesh.

    yade-double -n -x tests/yade/validation/test_stokes_fem_quick.py      (exit 0 = pass)

Runs ``python3 -m validation.stokes.run --quick`` from the repository's root with Debian's /usr/bin/python3
(dolfinx 0.5.2 and gmsh, which scripts/setup installs; the script fails, it does not skip, when they are missing)
against the pfv package of PYTHONPATH, and compares with tests/data/stokes_fem_quick.json, which
``run.py --quick --write-reference`` regenerates: the FEM permeability with symmetry and with
no-slip lateral faces to 1e-6, the FEM flux balance (1e-4) and the share of folded curved cells
(0.1 %), MINRES against the direct solve (1e-8), and PFV's permeability for the three wall variants.
About a minute.
"""
import os
import subprocess

from pfv_testing import checks, paths

env = dict(os.environ, OMP_NUM_THREADS='1', OPENBLAS_NUM_THREADS='1')
done = subprocess.run(['/usr/bin/python3', '-m', 'validation.stokes.run', '--quick'], env=env, cwd=paths.REPO)
checks.check('validation.stokes.run --quick passed', done.returncode == 0, '(exit code %d)' % done.returncode)
checks.report('Stokes FEM')
