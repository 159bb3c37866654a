"""Taylor-Hood (P2-P1) Stokes flow in the fluid mesh of mesh.py, solved by LDL^T (MUMPS through PETSc) or,
for meshes whose factor does not fit in memory, by preconditioned MINRES.

Pressure dp on the face y = 0 and 0 on y = 1 (natural condition sigma.n = -p n, with
sigma = -p I + 2 mu eps(u)); no-slip on the spheres; on the four lateral faces either no-slip or
symmetry (u.n = 0 with zero tangential traction). Returns the flux through both pressure faces,
the permeability kappa = mu Q l0 / (dp S) with S = l0^2 and Q their mean (l0 = 1, so kappa is
kappa / l0^2), and
the force of the fluid on every sphere and lateral face, split into its pressure and viscous
parts.

The iterative solve (method="minres") uses the block-diagonal preconditioner diag(A_u, M_p / mu) of the Stokes
operator, which keeps the MINRES iteration count bounded independently of the mesh size (Elman, Silvester and
Wathen, "Finite elements and fast iterative solvers", ch. 4): A_u the vector Laplacian mu grad u : grad v (spectrally
equivalent to the strain-rate form by Korn's inequality, with the spheres' no-slip condition), approximated by one
BoomerAMG V-cycle (hypre; the vector Laplacian does not couple the components, so
unknown-based AMG coarsens each on its own), M_p the P1 pressure mass matrix, approximated by
Jacobi. Its memory is that of the two assembled matrices and the AMG hierarchy, O(DOFs).
"""
import time

import numpy as np
import ufl
from dolfinx import fem
from dolfinx.mesh import meshtags
from mpi4py import MPI
from petsc4py import PETSc

from .mesh import FACES, SPHERE_TAG

LATERAL = (1, 2, 5, 6)  # xmin, xmax, zmin, zmax: the flow is along y
INLET, OUTLET = 3, 4


def solve(
    mesh,
    facets,
    n_spheres,
    lateral="symmetry",
    dp=1.0,
    mu=1.0,
    blr_tolerance=1e-10,
    symmetric=True,
    method="direct",
    rtol=1e-10,
):
    start = time.perf_counter()
    cell = mesh.ufl_cell()
    element = ufl.MixedElement([ufl.VectorElement("Lagrange", cell, 2), ufl.FiniteElement("Lagrange", cell, 1)])
    W = fem.FunctionSpace(mesh, element)
    fdim = mesh.topology.dim - 1
    mesh.topology.create_connectivity(fdim, mesh.topology.dim)
    V, _ = W.sub(0).collapse()
    bcs = boundary_conditions(W, V, facets, n_spheres, lateral)

    u, p = ufl.TrialFunctions(W)
    v, q = ufl.TestFunctions(W)
    ds = ufl.Measure("ds", domain=mesh, subdomain_data=facets)
    n = ufl.FacetNormal(mesh)
    a = (2 * mu * ufl.inner(ufl.sym(ufl.grad(u)), ufl.sym(ufl.grad(v))) - p * ufl.div(v) - q * ufl.div(u)) * ufl.dx
    L = -dp * ufl.inner(n, v) * ds(INLET)

    A = fem.petsc.assemble_matrix(fem.form(a), bcs=bcs)
    A.assemble()
    b = fem.petsc.assemble_vector(fem.form(L))
    fem.petsc.apply_lifting(b, [fem.form(a)], bcs=[bcs])
    b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    fem.petsc.set_bc(b, bcs)
    if method == "direct":
        ksp = direct_solver(A, blr_tolerance, symmetric)
        preconditioner = None
    elif method == "minres":
        ksp, preconditioner = minres_solver(W, A, bcs, mu, u, v, p, q, rtol)
    else:
        raise ValueError("method must be 'direct' or 'minres'")
    w = fem.Function(W)
    assembled = time.perf_counter()
    ksp.solve(b, w.vector)
    w.x.scatter_forward()
    solved = time.perf_counter()
    iterations = ksp.getIterationNumber()
    if method == "minres" and ksp.getConvergedReason() <= 0:
        raise RuntimeError(
            "MINRES did not converge (reason %d after %d iterations)" % (ksp.getConvergedReason(), iterations)
        )
    ksp.getPC().reset()  # frees MUMPS' factor (or the AMG hierarchy) before the forces' forms are assembled
    uh, ph = w.split()

    def integral(expr):
        return mesh.comm.allreduce(fem.assemble_scalar(fem.form(expr)), op=MPI.SUM)

    q_in = -integral(ufl.dot(uh, n) * ds(INLET))
    q_out = integral(ufl.dot(uh, n) * ds(OUTLET))
    flux = 0.5 * (q_in + q_out)
    # Every section y = const carries the same flux in the exact solution; the volume integral of
    # u_y (l0 = 1) is their mean, reported beside the two face fluxes as a check.
    flux_mean = integral(uh[1] * ufl.dx)
    forces = solid_forces(mesh, facets, n_spheres, uh, ph, mu)
    for obj in (ksp, A, b) + ((preconditioner,) if preconditioner is not None else ()):
        obj.destroy()
    return {
        "lateral": lateral,
        "flux_in": q_in,
        "flux_out": q_out,
        "flux_mean": flux_mean,
        "kappa": mu * flux / dp,  # l0 = 1, S = 1
        "dofs": W.dofmap.index_map.size_global * W.dofmap.index_map_bs,
        "velocity_dofs": V.dofmap.index_map.size_global * V.dofmap.index_map_bs,
        "cells": mesh.topology.index_map(3).size_global,
        "seconds_assembly": assembled - start,
        "seconds_solve": solved - assembled,
        "solver": method,
        "iterations": iterations,
        "forces": forces,
    }


def boundary_conditions(W, V, facets, n_spheres, lateral):
    """No-slip on the spheres (and, with lateral="noslip", on the four lateral faces); with
    lateral="symmetry" only the normal velocity vanishes on the lateral faces."""
    fdim = W.mesh.topology.dim - 1

    def marked(markers):
        return np.concatenate([facets.find(m) for m in markers]).astype(np.int32)

    zero = fem.Function(V)
    walls = [SPHERE_TAG + k for k in range(n_spheres)]
    if lateral == "noslip":
        walls += list(LATERAL)
    bcs = [fem.dirichletbc(zero, fem.locate_dofs_topological((W.sub(0), V), fdim, marked(walls)), W.sub(0))]
    if lateral == "symmetry":
        for axis, markers in ((0, (1, 2)), (2, (5, 6))):
            sub = W.sub(0).sub(axis)
            dofs = fem.locate_dofs_topological(sub, fdim, marked(markers))
            bcs.append(fem.dirichletbc(PETSc.ScalarType(0), dofs, sub))
    elif lateral != "noslip":
        raise ValueError("lateral must be 'symmetry' or 'noslip'")
    return bcs


def solid_forces(mesh, facets, n_spheres, uh, ph, mu):
    """The force of the fluid on every sphere and lateral face (marker_forces)."""
    named = [(SPHERE_TAG + k, "sphere%d" % k) for k in range(n_spheres)] + [(m, FACES[m - 1]) for m in LATERAL]
    return marker_forces(mesh, facets, named, uh, ph, mu)


def marker_forces(mesh, facets, named, uh, ph, mu):
    """{name: {"pressure": [x, y, z], "viscous": [x, y, z]}}, for every (marker, name) of `named`, the force
    of the fluid on the surface of that marker, -sigma.n with n the outward normal of the fluid, split into
    its pressure and viscous parts. One marker at a time is tagged 1 in its own MeshTags, so the forms
    compile once."""
    fdim = mesh.topology.dim - 1
    n = ufl.FacetNormal(mesh)
    e = fem.Constant(mesh, np.zeros(3, dtype=PETSc.ScalarType))

    def part_forms(measure):
        return (
            fem.form(ph * ufl.dot(n, e) * measure(1)),
            fem.form(-2 * mu * ufl.dot(ufl.dot(ufl.sym(ufl.grad(uh)), n), e) * measure(1)),
        )

    forces = {}
    for marker, name in named:
        tags = meshtags(
            mesh, fdim, np.sort(facets.find(marker)).astype(np.int32), np.ones(len(facets.find(marker)), dtype=np.int32)
        )
        forms = part_forms(ufl.Measure("ds", domain=mesh, subdomain_data=tags))
        parts = {"pressure": [], "viscous": []}
        for i in range(3):
            e.value = np.eye(3)[i]
            for key, form in zip(("pressure", "viscous"), forms):
                parts[key].append(mesh.comm.allreduce(fem.assemble_scalar(form), op=MPI.SUM))
        forces[name] = parts
    return forces


def direct_solver(A, blr_tolerance, symmetric):
    ksp = PETSc.KSP().create(MPI.COMM_SELF)
    ksp.setOperators(A)
    ksp.setType("preonly")
    pc = ksp.getPC()
    if symmetric:
        # The Stokes matrix is symmetric (indefinite): MUMPS' LDL^T stores one triangle.
        A.setOption(PETSc.Mat.Option.SYMMETRIC, True)
        pc.setType("cholesky")
    else:
        pc.setType("lu")
    pc.setFactorSolverType("mumps")
    pc.setFactorSetUpSolverType()
    if blr_tolerance > 0:
        # MUMPS' block low-rank factorisation (ICNTL 35, dropping tolerance CNTL 7): on the
        # 8-sphere packing at 165 000 DOFs it cuts the peak memory from 5.4 to 4.5 GB and the
        # solve by a quarter; at 1e-10 it moves kappa and the forces by about 1e-10 relative.
        pc.getFactorMatrix().setMumpsIcntl(35, 2)
        pc.getFactorMatrix().setMumpsCntl(7, blr_tolerance)
    return ksp


def minres_solver(W, A, bcs, mu, u, v, p, q, rtol):
    """MINRES on the Stokes matrix A with the block-diagonal preconditioner of the module docstring."""
    P = fem.petsc.assemble_matrix(fem.form(preconditioner_form(mu, u, v, p, q)), bcs=bcs)
    P.assemble()
    return minres_ksp(W, A, P, rtol), P


def preconditioner_form(mu, u, v, p, q):
    """The bilinear form of the preconditioner's matrix: the vector Laplacian and the pressure mass / mu."""
    return (mu * ufl.inner(ufl.grad(u), ufl.grad(v)) + (1.0 / mu) * p * q) * ufl.dx


def minres_ksp(W, A, P, rtol):
    """MINRES on A, preconditioned by one BoomerAMG V-cycle on P's velocity block and Jacobi on its pressure
    block (W the mixed space whose sub-spaces give the blocks' dofs)."""
    _, u_dofs = W.sub(0).collapse()
    _, p_dofs = W.sub(1).collapse()
    is_u = PETSc.IS().createGeneral(np.sort(np.asarray(u_dofs, dtype=np.int32)), comm=MPI.COMM_SELF)
    is_p = PETSc.IS().createGeneral(np.sort(np.asarray(p_dofs, dtype=np.int32)), comm=MPI.COMM_SELF)
    ksp = PETSc.KSP().create(MPI.COMM_SELF)
    # The sub-solvers are configured through PETSc's options database under a prefix of this KSP (set
    # before the splits are made, which inherit it), removed again once the solver is set up, so that
    # nothing leaks into later solvers.
    prefix = "stokes_minres_"
    ksp.setOptionsPrefix(prefix)
    ksp.setOperators(A, P)
    ksp.setType("minres")
    # PETSc's MINRES measures the preconditioned residual; rtol is relative to its initial value.
    ksp.setTolerances(rtol=rtol, atol=0.0, max_it=5000)
    pc = ksp.getPC()
    pc.setType("fieldsplit")
    pc.setFieldSplitIS(("u", is_u), ("p", is_p))
    pc.setFieldSplitType(PETSc.PC.CompositeType.ADDITIVE)
    settings = {
        "fieldsplit_u_ksp_type": "preonly",
        "fieldsplit_u_pc_type": "hypre",
        "fieldsplit_u_pc_hypre_type": "boomeramg",
        "fieldsplit_u_pc_hypre_boomeramg_strong_threshold": 0.5,
        "fieldsplit_u_pc_hypre_boomeramg_coarsen_type": "HMIS",
        "fieldsplit_u_pc_hypre_boomeramg_interp_type": "ext+i",
        "fieldsplit_u_pc_hypre_boomeramg_P_max": 4,
        "fieldsplit_p_ksp_type": "preonly",
        "fieldsplit_p_pc_type": "jacobi",
    }
    opts = PETSc.Options()
    for key, value in settings.items():
        opts[prefix + key] = value
    ksp.setFromOptions()
    pc.setUp()
    for key in settings:
        opts.delValue(prefix + key)
    for index_set in (is_u, is_p):
        index_set.destroy()
    return ksp
