"""solver='multigrid' and solver='auto' in a YADE scene, and their bad input.

    yade-double -n -x tests/yade/test_multigrid_solver.py      (exit 0 = pass)

The 1000-sphere permeameter, pressure 1 on ymin, 0 on ymax, spheres free to move (DEM steps):
  * the default is solver='auto', which picks CHOLMOD here and says so in core.solver_choice;
    useSolver reads 3 for it;
  * solver='multigrid' gives the fluxes and forces of CHOLMOD at every one of 20 DEM steps
    across a remesh (fluxes to 1e-8, conserved to 1e-8), with either multigrid_smoother;
  * max_factor_bytes below this factor makes 'auto' choose multigrid and report why;
  * an unknown solver or smoother name and a negative max_factor_bytes raise ValueError naming the setting,
    and the engine still runs afterwards.
"""
import os
import sys

HERE = os.path.dirname(os.path.abspath(sys.argv[0] if sys.argv and sys.argv[0].endswith('.py') else __file__))
sys.path.insert(0, HERE)

import robustness as rb  # noqa: E402
from yade import O  # noqa: E402


def history(steps=20, **kw):
    """Outflux and the fluid force on body 10 at each step."""
    O.reset()
    flow = rb.fresh(frozen=False, meshUpdateInterval=8, **kw)
    out = []
    for _ in range(steps):
        rb.run(1)
        out.append((flow.getBoundaryFlux(3), tuple(O.forces.f(10)), rb.conserved(flow)))
    return flow, out


flow, direct = history(solver="cholesky", mixed_precision=False)
rb.check("solver='cholesky': useSolver reads 3", flow.useSolver == 3)
flow, multigrid = history(solver="multigrid")
rb.check("solver='multigrid' is built", flow.core.solver_choice.startswith("multigrid"), flow.core.solver_choice)
rb.check("solver='multigrid': useSolver reads -1 (no YADE number)", flow.useSolver == -1)
rb.check("multigrid remeshed during the run", flow.core.remesh_count >= 3, f"{flow.core.remesh_count}")
worst_q = max(abs(a[0] / b[0] - 1) for a, b in zip(multigrid, direct))
worst_f = max(max(abs(x - y) for x, y in zip(a[1], b[1])) / max(abs(y) for y in b[1])
              for a, b in zip(multigrid, direct))
rb.check("multigrid outflux equals CHOLMOD's at every step (1e-8)", worst_q < 1e-8, f"worst {worst_q:.2e}")
rb.check("multigrid force on a sphere equals CHOLMOD's at every step (1e-7)", worst_f < 1e-7, f"worst {worst_f:.2e}")
worst_m = max(abs(imbalance) / scale for _, _, (_, (scale, imbalance)) in multigrid)
rb.check("multigrid conserves mass at every step (1e-8 of the largest wall flux)", all(m[2][0] for m in multigrid),
         f"worst {worst_m:.2e}")
flow, jacobi = history(solver="multigrid", multigrid_smoother="jacobi")
rb.check("multigrid_smoother='jacobi' is set", flow.multigrid_smoother == "jacobi")
worst_q = max(abs(a[0] / b[0] - 1) for a, b in zip(jacobi, direct))
worst_m = max(abs(imbalance) / scale for _, _, (_, (scale, imbalance)) in jacobi)
rb.check("with Jacobi smoothing too: outflux equals CHOLMOD's (1e-8)", worst_q < 1e-8, f"worst {worst_q:.2e}")
rb.check("with Jacobi smoothing too: mass conserved (1e-8)", all(m[2][0] for m in jacobi), f"worst {worst_m:.2e}")

O.reset()
flow = rb.fresh()
rb.check("the default solver is 'auto'", flow.solver == "auto")
rb.check("solver='auto' reads as useSolver 3", flow.useSolver == 3)
rb.run(1)
rb.check("auto picks CHOLMOD for a small packing", flow.core.solver_choice.startswith("cholesky: the factor stores"),
         flow.core.solver_choice)

O.reset()
flow = rb.fresh(max_factor_bytes=1e4)
rb.run(1)
rb.check("auto picks multigrid beyond max_factor_bytes",
         flow.core.solver_choice.startswith("multigrid: the Cholesky factor would store"), flow.core.solver_choice)
q = flow.getBoundaryFlux(3)

O.reset()
flow = rb.fresh()
rb.run(1)
rb.expect_error("unknown solver name", ValueError, "solver must be one of", lambda: setattr(flow, "solver", "amg"))
rb.expect_error("negative max_factor_bytes", ValueError, "max_factor_bytes",
                lambda: setattr(flow, "max_factor_bytes", -1.0))
rb.expect_error("unknown multigrid smoother", ValueError, "multigrid_smoother must be one of",
                lambda: setattr(flow, "multigrid_smoother", "sor"))
rb.check("the solver is unchanged after the refused settings",
         flow.solver == "auto" and flow.multigrid_smoother == "gauss_seidel")
rb.run(1)
rb.check("the engine still runs after the refused settings", abs(flow.getBoundaryFlux(3) / q - 1) < 1e-8,
         f"{flow.getBoundaryFlux(3):.6e} vs {q:.6e}")
rb.report("multigrid solver")
