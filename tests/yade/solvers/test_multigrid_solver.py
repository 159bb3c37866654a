"""solver='multigrid' and solver='auto' in a YADE scene, and their bad input.

    yade-double -n -x tests/yade/solvers/test_multigrid_solver.py      (exit 0 = pass)

The 1000-sphere permeameter, pressure 1 on ymin, 0 on ymax, spheres free to move (DEM steps):
  * the default is solver='auto', which picks CHOLMOD here and says so in core.solver_choice;
    useSolver reads 3 for it, and useSolver=3 selects it (YADE's default direct solver);
  * solver='multigrid' gives the pressures of CHOLMOD within its promise, refinement_tolerance x (max p - min p),
    at every one of 20 DEM steps across remeshes, with each multigrid_smoother; the outflux and the balance of
    wall fluxes against the volume rates within what that promise implies (an error e in the pressures of the
    cells next to a pressure wall moves its flux by at most max|e| x the sum of those throats' conductances), and
    the force on a sphere to 1e-7;
  * max_factor_bytes below this factor makes 'auto' choose multigrid and report why (solver_choice, and one
    warning), and a named 'cholesky' raise RuntimeError saying so (the engine then runs with multigrid);
  * an unknown solver or smoother name and a negative max_factor_bytes raise ValueError naming the setting,
    and the engine still runs afterwards.
"""
import warnings


from pfv_testing import robustness as rb
from yade import O  # noqa: E402


def boundary_conductance(core, walls):
    """Sum of the conductances of the throats between an unknown cell and a Dirichlet cell of one of `walls`."""
    sources = core.cell_sources()
    total = 0.0
    for (a, b), k in zip(core.facet_cells(), core.conductances()):
        if a >= 0 and b >= 0 and min(sources[a], sources[b]) == -1 and max(sources[a], sources[b]) in walls:
            total += k
    return total


def history(steps=20, **kw):
    """Per step: outflux, fluid force on body 10, the mass balance, the pressures of the unknown cells, and the
    conductance of the throats to the outlet (wall 3) and to both pressure walls (2, 3)."""
    O.reset()
    flow = rb.fresh(frozen=False, meshUpdateInterval=8, **kw)
    out = []
    for _ in range(steps):
        rb.run(1)
        core = flow.core
        out.append(
            dict(
                outflux=flow.getBoundaryFlux(3),
                force=tuple(O.forces.f(10)),
                balance=rb.conserved(flow)[1],
                pressure=[p for p, w in zip(core.pressure(), core.cell_sources()) if w == -1],
                k_outlet=boundary_conductance(core, (3,)),
                k_walls=boundary_conductance(core, (2, 3)),
            )
        )
    return flow, out


def against_direct(name, steps, direct, tolerance):
    """The multigrid run `steps` against the CHOLMOD run, step by step, on the same meshes."""
    same = all(len(a["pressure"]) == len(b["pressure"]) for a, b in zip(steps, direct))
    rb.check(f"{name}: the same meshes as the CHOLMOD run", same)
    if not same:
        return
    error, outflux, balance, force = 0.0, 0.0, 0.0, 0.0
    for a, b in zip(steps, direct):
        bound = tolerance * (max(a["pressure"]) - min(a["pressure"]))
        error = max(error, max(abs(x - y) for x, y in zip(a["pressure"], b["pressure"])) / bound)
        outflux = max(outflux, abs(a["outflux"] - b["outflux"]) / (bound * a["k_outlet"]))
        scale, imbalance = a["balance"]
        balance = max(balance, abs(imbalance) / (bound * a["k_walls"]))
        force = max(force, max(abs(x - y) for x, y in zip(a["force"], b["force"])) / max(abs(y) for y in b["force"]))
    worst_m = max(abs(a["balance"][1]) / a["balance"][0] for a in steps)
    rb.check(
        f"{name}: pressures equal CHOLMOD's within refinement_tolerance x spread at every step",
        error <= 1,
        f"worst {error:.2f} x that bound",
    )
    rb.check(
        f"{name}: outflux equals CHOLMOD's within what that bound implies",
        outflux <= 1,
        f"worst {outflux:.2e} x (bound x outlet throats' conductance)",
    )
    rb.check(
        f"{name}: wall fluxes balance the volume rates within what that bound implies",
        balance <= 1,
        f"worst {balance:.2e} x (bound x pressure walls' throats' conductance); {worst_m:.2e} of the largest "
        "wall flux",
    )
    rb.check(f"{name}: force on a sphere equals CHOLMOD's at every step (1e-7)", force < 1e-7, f"worst {force:.2e}")


flow, direct = history(solver="cholesky", mixed_precision=False)
rb.check("solver='cholesky': useSolver reads 3", flow.useSolver == 3)
rb.check(
    "the CHOLMOD run conserves mass at every step (1e-8 of the largest wall flux)",
    all(abs(d["balance"][1]) <= 1e-8 * d["balance"][0] for d in direct),
)
flow, multigrid = history(solver="multigrid")
rb.check("solver='multigrid' is built", flow.core.solver_choice.startswith("multigrid"), flow.core.solver_choice)
rb.check("solver='multigrid': useSolver reads -1 (no YADE number)", flow.useSolver == -1)
rb.check("multigrid remeshed during the run", flow.core.remesh_count >= 3, f"{flow.core.remesh_count}")
against_direct("multigrid", multigrid, direct, flow.core.refinement_tolerance)
flow, jacobi = history(solver="multigrid", multigrid_smoother="jacobi")
rb.check("multigrid_smoother='jacobi' is set", flow.multigrid_smoother == "jacobi")
against_direct("multigrid, Jacobi smoothing", jacobi, direct, flow.core.refinement_tolerance)
flow, split = history(solver="multigrid", multigrid_smoother="split_gauss_seidel")
rb.check("multigrid_smoother='split_gauss_seidel' is set", flow.multigrid_smoother == "split_gauss_seidel")
against_direct("multigrid, split Gauss-Seidel smoothing", split, direct, flow.core.refinement_tolerance)

O.reset()
flow = rb.fresh()
rb.check("the default solver is 'auto'", flow.solver == "auto")
rb.check("solver='auto' reads as useSolver 3", flow.useSolver == 3)
flow.solver = "cholesky"
flow.useSolver = 3  # YADE's default direct solver: PFV's default path, not the insisting factor
rb.check("useSolver=3 selects solver='auto'", flow.solver == "auto", flow.solver)
rb.run(1)
rb.check(
    "auto picks CHOLMOD for a small packing",
    flow.core.solver_choice.startswith("cholesky: the factor stores"),
    flow.core.solver_choice,
)

O.reset()
flow = rb.fresh(max_factor_bytes=1e4)
with warnings.catch_warnings(record=True) as caught:
    warnings.simplefilter("always")
    rb.run(2)
rb.check(
    "auto picks multigrid beyond max_factor_bytes",
    flow.core.solver_choice.startswith("multigrid: the Cholesky factor would store"),
    flow.core.solver_choice,
)
said = [str(w.message) for w in caught if "solver='auto' solves by multigrid" in str(w.message)]
rb.check(
    "auto says once, in a warning, that it took multigrid and why",
    len(said) == 1 and "would store" in said[0] and "more than the budget of 0.01 MB" in said[0],
    "; ".join(said),
)
q = flow.getBoundaryFlux(3)

O.reset()
flow = rb.fresh(solver="cholesky", max_factor_bytes=1e4)
rb.expect_error(
    "a named cholesky beyond max_factor_bytes",
    RuntimeError,
    "solver='cholesky': the Cholesky factor would store",
    rb.run,
)
flow.solver = "multigrid"
rb.run(1)
rb.check(
    "after the refusal the engine runs on with another solver",
    flow.core.solver_choice == "multigrid: as set" and abs(flow.getBoundaryFlux(3) - q) <= 1e-8 * abs(q),
    f"{flow.core.solver_choice}; outflux {flow.getBoundaryFlux(3):.9e} against {q:.9e}",
)

O.reset()
flow = rb.fresh()
rb.run(1)
rb.expect_error("unknown solver name", ValueError, "solver must be one of", lambda: setattr(flow, "solver", "amg"))
rb.expect_error(
    "negative max_factor_bytes", ValueError, "max_factor_bytes", lambda: setattr(flow, "max_factor_bytes", -1.0)
)
rb.expect_error(
    "unknown multigrid smoother",
    ValueError,
    "multigrid_smoother must be one of",
    lambda: setattr(flow, "multigrid_smoother", "sor"),
)
rb.check(
    "the solver is unchanged after the refused settings",
    flow.solver == "auto" and flow.multigrid_smoother == "gauss_seidel",
)
rb.run(1)
rb.check(
    "the engine still runs after the refused settings",
    abs(flow.getBoundaryFlux(3) / q - 1) < 1e-8,
    f"{flow.getBoundaryFlux(3):.6e} vs {q:.6e}",
)
rb.report("multigrid solver")
