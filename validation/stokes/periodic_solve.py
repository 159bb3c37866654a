"""Taylor-Hood (P2-P1) Stokes flow through a periodic array of spheres, driven by a mean pressure gradient.

The pressure is split as p = G.x + p~ with G the imposed mean gradient and p~ periodic, which leaves

    -mu lap u + grad p~ = -G,   div u = 0   in the fluid,   u = 0 on the spheres,   u and p~ periodic,

in the weak form of solve.py (2 mu eps(u):eps(v) - p~ div v - q div u) with the body force -G. Periodicity is
imposed by dolfinx_mpc's multi-point constraints (``constraint``): every velocity and pressure degree of freedom
on a face x_i = L_i is the one at the point with each such coordinate set to 0, so that edges and corners, which
lie on two or three faces, are tied directly to their one master and no master is itself a slave. p~ is fixed by
setting it to 0 at one pressure node (the nearest to the cell's centre on neither a face nor a sphere): the
constant is the only pressure mode the constrained system leaves free. Serial: the mesh is built on one process.

Returns the superficial velocity U = (1/V_cell) int_fluid u, the permeability kappa = mu U.d / |G| along the flow
direction d = -G / |G|, and the force of the fluid on every sphere (its pieces and those of its images summed)
in three parts: the pressure p~ and viscous parts of solve.marker_forces and the mean-gradient part -G V_k,
the force of p = G.x over the closed sphere. The momentum balance of the cell makes the forces on all
spheres sum to -G V_cell exactly (the pressure and viscous parts to -G V_fluid); the surface integrals of the
discrete tractions miss that by their discretisation error, reported relative to |G| V_cell as ``balance_total``
(and, for the pressure and viscous parts against the mesh's fluid volume, as ``balance``; the two differ by the
mesh's volume error, ``volume_error``, 1e-5 or less on the reference's meshes).

Solvers as solve.py's: MUMPS' LDL^T (the constrained matrix K^T A K keeps A's symmetry, with 1 on the slaves'
diagonal), or MINRES with the block preconditioner diag(AMG on the vector Laplacian, Jacobi on the pressure
mass / mu), assembled through the same constraint; its memory is O(DOFs).
"""
import time

import dolfinx_mpc
import numpy as np
import ufl
from dolfinx import fem
from mpi4py import MPI
from petsc4py import PETSc
from scipy.spatial import cKDTree

from . import solve as walled
from .mesh import SPHERE_TAG

# method="auto": the direct solve up to this many DOFs, MINRES (memory O(DOFs)) above
DIRECT_LIMIT = 100_000


def periodic_relation(cell, tol=1e-8):
    """The map of a point on a max face to its master: every coordinate at L_i set to 0."""
    cell = np.asarray(cell, dtype=float)

    def relation(x):
        out = x.copy()
        for axis in range(3):
            on_max = np.abs(x[axis] - cell[axis]) < tol * cell[axis]
            out[axis][on_max] = x[axis][on_max] - cell[axis]
        return out

    return relation


def pressure_pin(W, facets, cell):
    """A Dirichlet condition p~ = 0 at the pressure node nearest to the cell's centre off every boundary."""
    fdim = W.mesh.topology.dim - 1
    Q, to_parent = W.sub(1).collapse()
    boundary = np.unique(np.concatenate([facets.find(m) for m in np.unique(facets.values)])).astype(np.int32)
    on_boundary = fem.locate_dofs_topological(Q, fdim, boundary)
    x = Q.tabulate_dof_coordinates()
    distance = np.linalg.norm(x - 0.5 * np.asarray(cell), axis=1)
    distance[on_boundary] = np.inf
    dof = int(np.argmin(distance))
    return fem.dirichletbc(PETSc.ScalarType(0), np.array([to_parent[dof]], dtype=np.int32), W.sub(1))


def periodic_pairs(sub, cell, fixed, tol=1e-8):
    """(slaves, masters) in the mixed space's numbering for the scalar sub-space `sub`: every dof on a max face
    that is not in `fixed` (a Dirichlet dof) and the dof at its periodic_relation image, matched by coordinates."""
    space, to_parent = sub.collapse()
    to_parent = np.asarray(to_parent)
    x = space.tabulate_dof_coordinates()
    on_max = np.any(np.abs(x - np.asarray(cell)) < tol * np.asarray(cell), axis=1)
    slaves = np.flatnonzero(on_max & ~np.isin(to_parent, fixed))
    distance, masters = cKDTree(x).query(periodic_relation(cell, tol)(x[slaves].T).T)
    if len(slaves) and distance.max() > 1e-6 * np.max(cell):
        raise RuntimeError(
            "the meshes of opposite faces do not match: a dof is %.2e from its periodic image" % distance.max()
        )
    return to_parent[slaves], to_parent[masters]


def constraint(W, bcs, cell):
    """The periodic multi-point constraint on velocity and pressure, and the number of its slaves.

    The slave-master pairs are found by matching dof coordinates, which periodic_mesh.py's conforming face meshes
    allow (serial only): dolfinx_mpc 0.5.0's own create_periodic_constraint_topological locates the images by a
    GJK collision search that fails ("max iteration limit reached") on the curved P2 cells, and on the blocked
    velocity sub-space of the mixed space it tied the wrong dofs (on a periodic Poiseuille channel with straight
    cells: 204 nodes of the faces where 119 are slaves, the mean velocity 6 times too small)."""
    fixed = np.concatenate([bc.dof_indices()[0] for bc in bcs])
    pairs = [periodic_pairs(sub, cell, fixed) for sub in [W.sub(0).sub(i) for i in range(3)] + [W.sub(1)]]
    slaves = np.concatenate([s for s, _ in pairs]).astype(np.int32)
    masters = np.concatenate([m for _, m in pairs]).astype(np.int64)
    mpc = dolfinx_mpc.MultiPointConstraint(W)
    mpc.add_constraint(
        W,
        slaves,
        masters,
        np.ones(len(slaves), dtype=PETSc.ScalarType),
        np.zeros(len(slaves), dtype=np.int32),
        np.arange(len(slaves) + 1, dtype=np.int32),
    )
    mpc.finalize()
    return mpc, {"slaves": len(slaves)}


def solve(
    mesh, facets, packing, mu=1.0, direction=(1.0, 0.0, 0.0), method="auto", blr_tolerance=1e-10, rtol=1e-10, keep=None
):
    """The flow through the periodic cell of `packing` (periodic_mesh.build's) driven by |G| = 1 along
    `direction`: a dict of U, kappa, the forces, the balance and the solver's statistics. A dict `keep` receives
    the velocity and p~ as functions of their own spaces ("u", "p")."""
    start = time.perf_counter()
    cell = np.asarray(packing.get("cell", (1.0, 1.0, 1.0)), dtype=float)
    n_spheres = len(packing["radii"])
    direction = np.asarray(direction, dtype=float) / np.linalg.norm(direction)
    gradient = -direction  # |G| = 1, flow down the gradient
    element = ufl.MixedElement(
        [ufl.VectorElement("Lagrange", mesh.ufl_cell(), 2), ufl.FiniteElement("Lagrange", mesh.ufl_cell(), 1)]
    )
    W = fem.FunctionSpace(mesh, element)
    fdim = mesh.topology.dim - 1
    mesh.topology.create_connectivity(fdim, mesh.topology.dim)
    V, _ = W.sub(0).collapse()
    spheres = np.concatenate([facets.find(SPHERE_TAG + k) for k in range(n_spheres)]).astype(np.int32)
    no_slip = fem.dirichletbc(fem.Function(V), fem.locate_dofs_topological((W.sub(0), V), fdim, spheres), W.sub(0))
    bcs = [no_slip, pressure_pin(W, facets, cell)]
    mpc, periodic = constraint(W, bcs, cell)

    u, p = ufl.TrialFunctions(W)
    v, q = ufl.TestFunctions(W)
    a = fem.form(
        (2 * mu * ufl.inner(ufl.sym(ufl.grad(u)), ufl.sym(ufl.grad(v))) - p * ufl.div(v) - q * ufl.div(u)) * ufl.dx
    )
    L = fem.form(-ufl.inner(fem.Constant(mesh, gradient), v) * ufl.dx)
    A = dolfinx_mpc.assemble_matrix(a, mpc, bcs=bcs)
    b = dolfinx_mpc.assemble_vector(L, mpc)
    dolfinx_mpc.apply_lifting(b, [a], [bcs], mpc)
    b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    fem.petsc.set_bc(b, bcs)
    dofs = W.dofmap.index_map.size_global * W.dofmap.index_map_bs
    if method == "auto":
        method = "direct" if dofs <= DIRECT_LIMIT else "minres"
    if method == "direct":
        ksp, P = walled.direct_solver(A, blr_tolerance, True), None
    elif method == "minres":
        P = dolfinx_mpc.assemble_matrix(fem.form(walled.preconditioner_form(mu, u, v, p, q)), mpc, bcs=bcs)
        ksp = walled.minres_ksp(mpc.function_space, A, P, rtol)
    else:
        raise ValueError("method must be 'auto', 'direct' or 'minres'")
    w = fem.Function(mpc.function_space)
    assembled = time.perf_counter()
    ksp.solve(b, w.vector)
    solved = time.perf_counter()
    if method == "minres" and ksp.getConvergedReason() <= 0:
        raise RuntimeError(
            "MINRES did not converge (reason %d after %d iterations)"
            % (ksp.getConvergedReason(), ksp.getIterationNumber())
        )
    iterations = ksp.getIterationNumber()
    ksp.getPC().reset()  # frees the factor (or the AMG hierarchy) before the post-processing
    w.x.scatter_forward()
    mpc.backsubstitution(w.vector)
    out = post_process(mesh, facets, packing, w, mu, gradient, direction)
    if keep is not None:
        keep["u"], keep["p"] = w.sub(0).collapse(), w.sub(1).collapse()
    for obj in (ksp, A, b) + ((P,) if P is not None else ()):
        obj.destroy()
    out.update(
        {
            "dofs": dofs,
            "cells": mesh.topology.index_map(3).size_global,
            "periodic": periodic,
            "solver": method,
            "iterations": iterations,
            "seconds_assembly": assembled - start,
            "seconds_solve": solved - assembled,
        }
    )
    return out


def post_process(mesh, facets, packing, w, mu, gradient, direction):
    """U, kappa, the forces on the spheres and the checks of one solution."""
    cell = np.asarray(packing.get("cell", (1.0, 1.0, 1.0)), dtype=float)
    radii = np.asarray(packing["radii"], dtype=float)
    uh, ph = w.split()
    volume = float(np.prod(cell))

    def integral(expr):
        return mesh.comm.allreduce(fem.assemble_scalar(fem.form(expr)), op=MPI.SUM)

    fluid = integral(fem.Constant(mesh, PETSc.ScalarType(1)) * ufl.dx)
    mean = np.array([integral(uh[i] * ufl.dx) for i in range(3)]) / volume
    # Every section normal to the flow carries the same flux in the exact solution (div u = 0 and
    # periodicity); the face x_axis = 0 against the volume mean measures how far the discrete one is.
    axis = int(np.argmax(np.abs(direction)))
    ds = ufl.Measure("ds", domain=mesh, subdomain_data=facets)
    section = integral(uh[axis] * ds(1 + 2 * axis)) * cell[axis] / volume
    named = [(SPHERE_TAG + k, "sphere%d" % k) for k in range(len(radii))]
    forces = walled.marker_forces(mesh, facets, named, uh, ph, mu)
    drag, total = np.zeros(3), np.zeros(3)
    for k, r in enumerate(radii):
        f = forces["sphere%d" % k]
        f["gradient"] = list(-gradient * 4.0 / 3.0 * np.pi * r**3)
        f["total"] = list(np.sum([f["pressure"], f["viscous"], f["gradient"]], axis=0))
        drag += np.array(f["pressure"]) + np.array(f["viscous"])
        total += np.array(f["total"])
    gnorm = np.linalg.norm(gradient)
    solid = 4.0 / 3.0 * np.pi * float(np.sum(radii**3))
    return {
        "U": list(mean),
        "kappa": float(mu * mean @ direction / gnorm),
        "fluid_volume": fluid,
        "cell_volume": volume,
        "section_flux_error": float(section / mean[axis] - 1),
        "forces": forces,
        # the pressure and viscous parts balance the body force on the fluid, G V_fluid (the mesh's)
        "balance": float(np.linalg.norm(drag + gradient * fluid) / (gnorm * volume)),
        # the whole force on the solid balances G V_cell; differs from the above by the volume error below
        "balance_total": float(np.linalg.norm(total + gradient * volume) / (gnorm * volume)),
        "volume_error": (fluid + solid) / volume - 1,
        "drag_over_gradient_volume": float(-drag @ gradient / (gnorm**2 * fluid)),
    }
