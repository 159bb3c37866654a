"""Tetrahedral mesh of the fluid in the unit cube around frozen spheres (gmsh, OpenCASCADE kernel).

The fluid is the cube minus the union of the spheres. Facet markers: the six faces of the cube
1..6 in the order xmin, xmax, ymin, ymax, zmin, zmax, and sphere k as SPHERE_TAG + k. The element
size is ``h`` in the bulk, ``h * surface_factor`` on the spheres (at most 0.6 r on a sphere of
radius r), and ``h * gap_factor`` within a
ball around each near-contact (sphere-sphere or sphere-wall gap below ``gap_ball`` l0), so the
narrow gaps left by the shrink are resolved by a few elements.
"""
import gmsh
import numpy as np
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


def _contact_points(centres, radii, gap_ball):
    """Midpoints of every sphere-sphere and sphere-wall gap narrower than gap_ball."""
    points = []
    n = len(radii)
    for i in range(n):
        for j in range(i + 1, n):
            d = centres[j] - centres[i]
            dist = np.linalg.norm(d)
            if dist - radii[i] - radii[j] < gap_ball:
                points.append(centres[i] + d / dist * (radii[i] + 0.5 * (dist - radii[i] - radii[j])))
        for axis in range(3):
            for wall in (0.0, 1.0):
                if abs(centres[i][axis] - wall) - radii[i] < gap_ball:
                    p = centres[i].copy()
                    p[axis] = 0.5 * (wall + centres[i][axis] + np.sign(wall - centres[i][axis]) * radii[i])
                    points.append(p)
    return points


def build(packing, h, surface_factor=0.5, gap_factor=0.15, gap_ball=0.02, order=2, verbose=False):
    """The dolfinx mesh, cell tags and facet tags of the fluid domain (run on one process)."""
    centres = np.asarray(packing["centres"], dtype=float)
    radii = np.asarray(packing["radii"], dtype=float)
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

        sphere_surfaces = [t for m, tags in groups.items() if m >= SPHERE_TAG for t in tags]
        field = gmsh.model.mesh.field
        dist = field.add("Distance")
        field.setNumbers(dist, "SurfacesList", sphere_surfaces)
        near = field.add("Threshold")
        field.setNumber(near, "InField", dist)
        field.setNumber(near, "SizeMin", h * surface_factor)
        field.setNumber(near, "SizeMax", h)
        field.setNumber(near, "DistMin", 0.0)
        field.setNumber(near, "DistMax", 2.0 * h)
        fields = [near]
        for c, r in zip(centres, radii):  # small spheres: elements of at most 0.6 r on and near them
            if 0.6 * r < h * surface_factor:
                ball = field.add("Ball")
                for key, value in zip(("XCenter", "YCenter", "ZCenter"), c):
                    field.setNumber(ball, key, value)
                field.setNumber(ball, "Radius", 1.5 * r)
                field.setNumber(ball, "Thickness", r)
                field.setNumber(ball, "VIn", 0.6 * r)
                field.setNumber(ball, "VOut", h)
                fields.append(ball)
        for p in _contact_points(centres, radii, gap_ball):
            ball = field.add("Ball")
            field.setNumber(ball, "XCenter", p[0])
            field.setNumber(ball, "YCenter", p[1])
            field.setNumber(ball, "ZCenter", p[2])
            field.setNumber(ball, "Radius", 0.06)
            field.setNumber(ball, "Thickness", 0.06)
            field.setNumber(ball, "VIn", h * gap_factor)
            field.setNumber(ball, "VOut", h)
            fields.append(ball)
        smallest = field.add("Min")
        field.setNumbers(smallest, "FieldsList", fields)
        field.setAsBackgroundMesh(smallest)
        gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
        gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
        gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)
        gmsh.option.setNumber("Mesh.Algorithm3D", 1)  # Delaunay: deterministic
        gmsh.option.setNumber("General.NumThreads", 1)
        gmsh.model.mesh.generate(3)
        if order > 1:
            gmsh.model.mesh.setOrder(order)
        mesh, cells, facets = gmshio.model_to_mesh(gmsh.model, MPI.COMM_SELF, 0, gdim=3)
    finally:
        gmsh.finalize()
    return mesh, cells, facets
