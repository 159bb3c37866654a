"""The periodic Stokes reference on its CI case: the simple cubic array at c = 0.45 on one coarse mesh.

    yade-double -n -x tests/yade/validation/test_stokes_periodic_quick.py      (exit 0 = pass)

Runs ``python3 -m validation.stokes.periodic_run --quick`` from the repository's root with Debian's /usr/bin/python3
(dolfinx 0.5.2, dolfinx-mpc 0.5.0 and gmsh, which scripts/setup installs; the script fails, it does not skip, when
they are missing) and compares with tests/data/stokes_periodic_quick.json, which ``periodic_run.py --quick
--write-reference`` regenerates: kappa with the sphere at the cell's centre and at its corner (cut into eight
pieces by the periodic faces) to 1e-6 of the stored values of the same meshes and to 2 % of Zick & Homsy (1982),
the two placements within 0.5 % of each other, the forces on the sphere balancing G V_cell to 1 %, at most 0.1 %
of the cells folded, and MINRES equal to the direct solve to 1e-8. Under a minute.
"""
import os
import subprocess

from pfv_testing import checks, paths

env = dict(os.environ, OMP_NUM_THREADS='1', OPENBLAS_NUM_THREADS='1')
done = subprocess.run(['/usr/bin/python3', '-m', 'validation.stokes.periodic_run', '--quick'], env=env, cwd=paths.REPO)
checks.check('validation.stokes.periodic_run --quick passed', done.returncode == 0, '(exit code %d)' % done.returncode)
checks.report('Stokes periodic')
