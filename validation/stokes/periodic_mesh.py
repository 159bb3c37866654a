"""Tetrahedral mesh of the fluid in a periodic cuboid cell around spheres (gmsh, OpenCASCADE kernel).

The fluid is the cell [0, Lx] x [0, Ly] x [0, Lz] minus every sphere and every periodic image of it that
reaches into the cell, so a sphere crossing a face appears as pieces on both sides. The surface meshes of
opposite faces are made translates of each other (gmsh's setPeriodic), so that periodic_solve.py ties every
degree of freedom on a face to exactly one on the opposite face. Facet markers as mesh.py: the faces 1..6
(xmin, xmax, ymin, ymax, zmin, zmax) and SPHERE_TAG + k for every piece of sphere k or of its images.

Sizes as mesh.py's (one number, ``surface``, the element size on the spheres, growing linearly to
BULK_PER_SURFACE times that at the distance ``layer``), but measured from the exact distance to the nearest
sphere or image, inside or outside the cell: gmsh's Distance field sees only the pieces inside the cell and
would grade the two sides of a face differently.
"""
import itertools

import gmsh
import numpy as np
from scipy.spatial import cKDTree

from .mesh import BULK_PER_SURFACE, SPHERE_TAG, generate, mesh_options

# A sphere nearer to tangency with a face plane than this (relative to the cell) is refused: it would cut the
# face in a vanishing circle or leave a gap far thinner than any element size this module makes.
TANGENT_TOLERANCE = 1e-4


def images(centres, radii, cell, reach=0.0):
    """(sphere index, centre) of every sphere and periodic image that comes within `reach` of the cell."""
    cell = np.asarray(cell, dtype=float)
    out = []
    for k, (c, r) in enumerate(zip(np.asarray(centres, dtype=float), radii)):
        for shift in itertools.product((-1, 0, 1), repeat=3):
            x = c + np.array(shift) * cell
            outside = np.maximum(np.maximum(-x, x - cell), 0.0)
            gap = np.linalg.norm(outside) - r
            if gap < reach:
                out.append((k, x))
    return out


def check_tangency(centres, radii, cell):
    """Refuse spheres within TANGENT_TOLERANCE of tangency with a face plane of the cell."""
    cell = np.asarray(cell, dtype=float)
    for c, r in zip(np.asarray(centres, dtype=float), radii):
        for axis in range(3):
            for plane in (0.0, cell[axis]):
                if abs(abs(c[axis] - plane) - r) < TANGENT_TOLERANCE * cell[axis]:
                    raise ValueError("a sphere is tangent to the face %s = %g" % ("xyz"[axis], plane))


def _face_of(box, cell, tol=1e-5):
    """Face marker 1..6 of a surface whose bounding box is flat on a face of the cell, else None (OpenCASCADE
    pads bounding boxes by 1e-7)."""
    lo, hi = np.array(box[:3]), np.array(box[3:])
    for axis in range(3):
        if hi[axis] - lo[axis] < tol:
            for side, value in enumerate((0.0, cell[axis])):
                if abs(lo[axis] - value) < tol:
                    return 1 + 2 * axis + side
    return None


def _sphere_of(tag, spheres):
    """Index of the sphere whose image carries surface `tag` (a point of it lies on that image)."""
    lo, hi = gmsh.model.getParametrizationBounds(2, tag)
    point = np.array(gmsh.model.getValue(2, tag, 0.5 * (np.array(lo) + np.array(hi))))
    gaps = [abs(np.linalg.norm(point - x) - r) for _, x, r in spheres]
    best = int(np.argmin(gaps))
    if gaps[best] > 1e-6:
        raise RuntimeError("surface %d is neither a face of the cell nor a sphere" % tag)
    return spheres[best][0]


def _classify(fluid, spheres, cell):
    """{marker: [surface tags]} of the fluid's boundary."""
    groups = {}
    for _, tag in gmsh.model.getBoundary(fluid, oriented=False):
        tag = abs(tag)
        face = _face_of(gmsh.model.getBoundingBox(2, tag), cell)
        marker = face if face is not None else SPHERE_TAG + _sphere_of(tag, spheres)
        groups.setdefault(marker, []).append(tag)
    return groups


def _make_periodic(groups, cell, tol=1e-5):
    """Each surface of a max face meshed as the translate of its counterpart on the min face, found by
    its translated bounding box."""
    for axis in range(3):
        shift = np.zeros(3)
        shift[axis] = cell[axis]
        masters = {tag: np.array(gmsh.model.getBoundingBox(2, tag)) for tag in groups.get(1 + 2 * axis, [])}
        for slave in groups.get(2 + 2 * axis, []):
            box = np.array(gmsh.model.getBoundingBox(2, slave)) - np.concatenate([shift, shift])
            match = [tag for tag, b in masters.items() if np.abs(b - box).max() < tol]
            if len(match) != 1:
                raise RuntimeError(
                    "face %s: surface %d has %d periodic counterparts" % ("xyz"[axis], slave, len(match))
                )
            translation = np.eye(4)
            translation[:3, 3] = shift
            gmsh.model.mesh.setPeriodic(2, [slave], match, translation.ravel().tolist())


def _size_field(spheres, surface, layer, gap_elements=0.0, smallest=0.25):
    """Element size `surface` on the spheres, growing linearly to BULK_PER_SURFACE times that at the distance
    `layer` from the nearest sphere image (exact distances, images inside and outside the cell alike).

    With gap_elements > 0, also at most the local width of a gap between two spheres (the distances to the
    two nearest sphere surfaces summed) over gap_elements, but not below `smallest` times `surface`: a
    curved element whose straight edges cross a gap much narrower than itself folds (section 7 of
    doc/validation.md), and on a random packing's many near-contacts the folds leave MINRES' preconditioner
    indefinite. Gaps narrower than that floor are left to the elastic untangling.

    A callback rather than one gmsh field per image: a random packing of 100 spheres has some 400 images near
    the cell, and gmsh evaluates every field at every size query."""
    centres = np.array([x for _, x, _ in spheres])
    radii = np.array([r for _, _, r in spheres])
    tree = cKDTree(centres)
    # the two nearest surfaces are among the nearest centres (radii differ by at most a factor 2 here)
    k = min(len(centres), 12)

    def size(dim, tag, x, y, z):
        distance, index = tree.query((x, y, z), k=k)
        gaps = np.sort(np.maximum(np.atleast_1d(distance) - radii[np.atleast_1d(index)], 0.0))
        out = surface * (1.0 + (BULK_PER_SURFACE - 1.0) * min(gaps[0] / layer, 1.0))
        if gap_elements > 0 and len(gaps) > 1:
            out = min(out, max((gaps[0] + gaps[1]) / gap_elements, smallest * surface))
        return out

    gmsh.model.mesh.setSizeCallback(size)


def build(packing, surface, layer=0.32, order=2, verbose=False, gap_elements=0.0):
    """The dolfinx mesh, cell tags and facet tags of the fluid in the periodic cell of `packing` (its
    ``cell``, the side lengths, default the unit cube; ``centres`` inside the cell; ``radii``)."""
    cell = np.asarray(packing.get("cell", (1.0, 1.0, 1.0)), dtype=float)
    centres = np.mod(np.asarray(packing["centres"], dtype=float), cell)
    radii = np.asarray(packing["radii"], dtype=float)
    check_tangency(centres, radii, cell)
    cutting = [(k, x, radii[k]) for k, x in images(centres, radii, cell)]
    near = [(k, x, radii[k]) for k, x in images(centres, radii, cell, reach=layer)]
    gmsh.initialize()
    try:
        gmsh.option.setNumber("General.Terminal", 1 if verbose else 0)
        gmsh.model.add("periodic fluid")
        occ = gmsh.model.occ
        box = occ.addBox(0, 0, 0, *cell)
        balls = [(3, occ.addSphere(*x, r)) for _, x, r in cutting]
        fluid, _ = occ.cut([(3, box)], balls)
        occ.synchronize()
        gmsh.model.addPhysicalGroup(3, [tag for dim, tag in fluid if dim == 3], 1)
        groups = _classify(fluid, cutting, cell)
        for marker, tags in groups.items():
            gmsh.model.addPhysicalGroup(2, tags, marker)
        _make_periodic(groups, cell)
        _size_field(near, surface, layer, gap_elements)
        mesh_options()
        mesh, cells, facets = generate(order)
    finally:
        gmsh.finalize()
    return mesh, cells, facets


def simple_cubic(c, shrink=0.0, corner=False):
    """One sphere per unit cube at solid fraction c (before the shrink), at the centre or (corner=True)
    at the origin, where it is cut into eight pieces."""
    radius = (3.0 * c / (4.0 * np.pi)) ** (1.0 / 3.0)
    centre = [0.0, 0.0, 0.0] if corner else [0.5, 0.5, 0.5]
    return _lattice("sc", c, [centre], radius, shrink)


def body_centred(c, shrink=0.0):
    """Two spheres per cube, at the origin and the centre (touching at c = pi sqrt(3) / 8 = 0.680)."""
    radius = (3.0 * c / (8.0 * np.pi)) ** (1.0 / 3.0)
    return _lattice("bcc", c, [[0.0, 0.0, 0.0], [0.5, 0.5, 0.5]], radius, shrink)


def face_centred(c, shrink=0.0):
    """Four spheres per cube, at the origin and the face centres (touching at c = pi sqrt(2) / 6 = 0.740)."""
    radius = (3.0 * c / (16.0 * np.pi)) ** (1.0 / 3.0)
    centres = [[0.0, 0.0, 0.0], [0.5, 0.5, 0.0], [0.5, 0.0, 0.5], [0.0, 0.5, 0.5]]
    return _lattice("fcc", c, centres, radius, shrink)


def _lattice(name, c, centres, radius, shrink):
    n = len(centres)
    return {
        "name": "%s_%.4g" % (name, c) + ("@%g" % shrink if shrink else ""),
        "array": name,
        "c": c,
        "shrink": shrink,
        "cell": [1.0, 1.0, 1.0],
        "centres": np.array(centres, dtype=float),
        "radii": np.full(n, radius * (1.0 - shrink)),
        "radius_unshrunk": radius,
    }
