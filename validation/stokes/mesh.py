"""Tetrahedral mesh of the fluid in the unit cube around frozen spheres (gmsh, OpenCASCADE kernel).

The fluid is the cube minus the union of the spheres. Facet markers: the six faces of the cube
1..6 in the order xmin, xmax, ymin, ymax, zmin, zmax, and sphere k as SPHERE_TAG + k.

One number sets the refinement level: ``surface``, the element size on a sphere of radius
R_REF l0 or more; smaller spheres get ``surface * r / R_REF``, and the size grows linearly from
the sphere surfaces to ``bulk = BULK_PER_SURFACE * surface`` at a distance ``layer`` (fixed) and is
``bulk`` beyond: a finer level scales every size by the same factor. The sizes are graded towards
the spheres because the flux is carried through the throats between them, whose velocity profile
the surface size resolves: on the 8-sphere packing refining the spheres' surfaces moved kappa by
percents where halving the bulk size moved it by 0.01 %; on the random 25-sphere packing, whose
pores are larger, halving the bulk size moved it by 0.8 %, so the bulk is refined with the
surface. Refining the near-contact gaps (0.02 r wide after the shrink) to a sixth of the surface
size moved kappa by 0.04 % on the 8 spheres: the gaps get no refinement of their own.
"""
import basix
import gmsh
import numpy as np
import ufl
from dolfinx import fem
from dolfinx.io import gmshio
from mpi4py import MPI

SPHERE_TAG = 100
FACES = ("xmin", "xmax", "ymin", "ymax", "zmin", "zmax")


def _face_of(point, tol=1e-9):
    for axis in range(3):
        for side, value in enumerate((0.0, 1.0)):
            if abs(point[axis] - value) < tol:
                return 1 + 2 * axis + side
    return None


def _sphere_of(point, centres, radii):
    gap = np.abs(np.linalg.norm(centres - point, axis=1) - radii)
    k = int(np.argmin(gap))
    return k if gap[k] < 1e-6 else None


R_REF = 0.08
BULK_PER_SURFACE = 10.0 / 3.0


def build(packing, surface, layer=0.32, order=2, verbose=False):
    """The dolfinx mesh, cell tags and facet tags of the fluid domain (run on one process)."""
    centres = np.asarray(packing["centres"], dtype=float)
    radii = np.asarray(packing["radii"], dtype=float)
    bulk = BULK_PER_SURFACE * surface
    gmsh.initialize()
    try:
        gmsh.option.setNumber("General.Terminal", 1 if verbose else 0)
        gmsh.model.add("fluid")
        occ = gmsh.model.occ
        box = occ.addBox(0, 0, 0, 1, 1, 1)
        balls = [(3, occ.addSphere(*c, r)) for c, r in zip(centres, radii)]
        fluid, _ = occ.cut([(3, box)], balls)
        occ.synchronize()
        volumes = [tag for dim, tag in fluid if dim == 3]
        gmsh.model.addPhysicalGroup(3, volumes, 1)
        groups = {}
        for dim, tag in gmsh.model.getBoundary(fluid, oriented=False):
            lo, hi = gmsh.model.getParametrizationBounds(2, tag)
            point = np.array(gmsh.model.getValue(2, tag, 0.5 * (np.array(lo) + np.array(hi))))
            face = _face_of(point)
            if face is None:
                k = _sphere_of(point, centres, radii)
                if k is None:
                    raise RuntimeError("surface %d is neither a face of the cube nor a sphere" % tag)
                face = SPHERE_TAG + k
            groups.setdefault(face, []).append(abs(tag))
        for marker, tags in groups.items():
            gmsh.model.addPhysicalGroup(2, tags, marker)

        field = gmsh.model.mesh.field
        fields = []
        for k, r in enumerate(radii):
            size = surface * min(1.0, r / R_REF)
            dist = field.add("Distance")
            field.setNumbers(dist, "SurfacesList", groups[SPHERE_TAG + k])
            near = field.add("Threshold")
            field.setNumber(near, "InField", dist)
            field.setNumber(near, "SizeMin", size)
            field.setNumber(near, "SizeMax", bulk)
            field.setNumber(near, "DistMin", 0.0)
            field.setNumber(near, "DistMax", layer)
            fields.append(near)
        smallest = field.add("Min")
        field.setNumbers(smallest, "FieldsList", fields)
        field.setAsBackgroundMesh(smallest)
        mesh_options()
        mesh, cells, facets = generate(order)
    finally:
        gmsh.finalize()
    return mesh, cells, facets


def tangled_cells(mesh):
    """Number of cells whose Jacobian determinant changes sign (or vanishes) over their vertices and a
    degree-6 quadrature's points: curved cells that fold over themselves."""
    points, _ = basix.make_quadrature(basix.CellType.tetrahedron, 6)
    points = np.vstack([points, [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]]])
    det = fem.Expression(ufl.det(ufl.Jacobian(mesh)), points)
    n = mesh.topology.index_map(mesh.topology.dim).size_local
    values = det.eval(np.arange(n, dtype=np.int32)).reshape(n, -1)
    return int(np.count_nonzero(values.min(axis=1) * values.max(axis=1) <= 0))


def mesh_options():
    """gmsh's options of every mesh here: sizes from the background field alone, deterministic, one thread."""
    gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
    gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
    gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)
    gmsh.option.setNumber("Mesh.Algorithm3D", 1)  # Delaunay: deterministic
    gmsh.option.setNumber("General.NumThreads", 1)


def generate(order):
    """The 3-D mesh of gmsh's current model, of the given order, as dolfinx's (mesh, cell tags, facet tags)."""
    gmsh.model.mesh.generate(3)
    if order > 1:
        gmsh.model.mesh.setOrder(order)
        # Curving the edges onto the spheres tangles cells whose straight edges cut a narrow gap:
        # their Jacobian changes sign inside the cell (1-2 % of the cells at these sizes), which
        # breaks the flux balance between the two pressure faces (3e-3 on the 8-sphere packing,
        # 3e-2 on 54 spheres) and moves the pressure / viscous split of single sphere forces by
        # tens of per cent on coarse meshes. gmsh's elastic untangling leaves under 0.1 % of the
        # cells folded on 8 to 54 spheres.
        gmsh.model.mesh.optimize("HighOrderElastic")
    return gmshio.model_to_mesh(gmsh.model, MPI.COMM_SELF, 0, gdim=3)
