"""A system saved by the engine, solved by its multigrid CG in one and in two MPI processes.

    yade-double -n -x tests/yade/solvers/test_amg_mpi.py      (exit 0 = pass)

The 1000-sphere permeameter (pressure 1 on ymin, 0 on ymax) takes one step with the direct
solver; core.save_system writes G, b and the solution. build/pfv_amg_solve (bench/amg/amg_solve.cpp)
solves it from zero with the engine's multigrid CG and stopping rule (1e-10 of the pressure
spread) under `mpirun -np 1` and `-np 2`, each process owning half the rows. Checks: both
converge on hypre's parallel hierarchy, each is within 2e-10 of the spread of the engine's
pressures, and the two agree with each other to the same bound.
"""
import os
import shutil
import subprocess
import tempfile

import numpy as np


from pfv_testing import robustness as rb
import pfv  # noqa: E402


def driver():
    build = os.environ.get("PFV_BUILD_DIR") or os.path.dirname(os.path.dirname(os.path.dirname(pfv.__file__)))
    path = os.path.join(build, "pfv_amg_solve")
    if not os.path.exists(path):
        rb.fail(f"no MPI driver at {path} (set PFV_BUILD_DIR to the build folder)")
        rb.report("MPI multigrid")
    return path


def read_array(path):
    with open(path) as f:
        lines = [line for line in f if not line.startswith("%")]
    n = int(lines[0].split()[0])
    return np.array([float(v) for v in lines[1 : 1 + n]])


def solve(folder, processes):
    out = os.path.join(folder, f"x{processes}.mtx")
    env = dict(
        os.environ,
        OMPI_ALLOW_RUN_AS_ROOT="1",
        OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
        OMP_NUM_THREADS="1",
        OMPI_MCA_rmaps_base_oversubscribe="1",
    )
    run = subprocess.run(
        ["mpirun", "-np", str(processes), driver(), folder, f"--out={out}"],
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
    )
    print(run.stdout.strip())
    if run.returncode != 0:
        rb.fail(f"mpirun -np {processes}: exit {run.returncode}: {run.stderr.strip()[-500:]}")
        return None, {}
    fields = run.stdout.split()
    stats = {fields[i]: float(fields[i + 1]) for i in range(0, len(fields) - 1, 2)}
    return read_array(out), stats


folder = tempfile.mkdtemp(prefix="pfv-amg-mpi-")
try:
    flow = rb.fresh(solver="cholesky", mixed_precision=False)
    rb.run(1)
    flow.core.save_system(folder)
    x_engine = read_array(os.path.join(folder, "x.mtx"))
    spread = x_engine.max() - x_engine.min()
    unknowns = int(np.count_nonzero(np.asarray(flow.core.cell_sources()) == -1))
    rb.check("the saved system has one value per unknown cell", len(x_engine) == unknowns, f"{len(x_engine)}")
    x1, s1 = solve(folder, 1)
    x2, s2 = solve(folder, 2)
    if x1 is not None and x2 is not None:
        rb.check("one process: converged", s1["converged"] == 1 and s1["processes"] == 1)
        rb.check("two processes: converged", s2["converged"] == 1 and s2["processes"] == 2)
        e1 = np.abs(x1 - x_engine).max() / spread
        e2 = np.abs(x2 - x_engine).max() / spread
        e12 = np.abs(x1 - x2).max() / spread
        rb.check("one process: the engine's pressures within 2e-10 of the spread", e1 <= 2e-10, f"{e1:.2e}")
        rb.check("two processes: the engine's pressures within 2e-10 of the spread", e2 <= 2e-10, f"{e2:.2e}")
        rb.check("one and two processes agree within 2e-10 of the spread", e12 <= 2e-10, f"{e12:.2e}")
finally:
    shutil.rmtree(folder, ignore_errors=True)
rb.report("MPI multigrid")
