"""The Stokes reference's flux through the throats of PFV's regular triangulation.

A throat of the pore network is the facet shared by two tetrahedra: the triangle of three sphere centres. The
reference's flux through it is the integral of u . n over that triangle, by quadrature of the finite-element
velocity (a degree-2 three-point rule on each triangle of a regular m x m subdivision, m set by the element size so
that the sub-triangles are a third of an element across). The velocity is 0 in the spheres (points there are
known from the geometry) and periodic (points are wrapped into the cell). Points of the fluid that no cell holds,
between a curved sphere surface and its mesh, count as solid: their area is far below the quadrature's error.

The divergence-free field makes the fluxes out of each tetrahedron sum to zero; the sum of their magnitudes gives
the quadrature's own error (``imbalance``), which the study reports beside every comparison.
"""
import numpy as np
from dolfinx import geometry
from scipy.spatial import cKDTree

# Sub-triangles per element size along a triangle's longest edge. 3 and 6 gave the CI case's mean velocity from
# its throat fluxes alike to 2e-5 (both 0.67 % from the FEM's volume mean, the discrete field's own error, which
# shrinks with the mesh: 0.2 % at h = 0.07 on a 12-sphere cell) and its pore imbalance to 1e-5.
SUBDIVISION = 3.0
# Rule of degree 2 on a triangle: barycentric points and equal weights (1/3 each, times the area).
_RULE = np.array([[2 / 3, 1 / 6, 1 / 6], [1 / 6, 2 / 3, 1 / 6], [1 / 6, 1 / 6, 2 / 3]])


def subdivision(m):
    """Barycentric quadrature points (n, 3) and weights (sum 1) of the m x m subdivision of a triangle."""
    points = []
    for i in range(m):
        for j in range(m - i):
            up = np.array([[i, j], [i + 1, j], [i, j + 1]], dtype=float) / m
            points.append(_RULE @ up)
            if i + j < m - 1:
                down = np.array([[i + 1, j], [i + 1, j + 1], [i, j + 1]], dtype=float) / m
                points.append(_RULE @ down)
    st = np.concatenate(points)
    bary = np.column_stack([1.0 - st.sum(1), st])
    return bary, np.full(len(bary), 1.0 / len(bary))


def in_solid(points, centres, radii, cell):
    """Whether each point (wrapped into the cell) lies in a sphere or one of its periodic images."""
    cell = np.asarray(cell, dtype=float)
    tree = cKDTree(np.mod(centres, cell), boxsize=cell)
    reach = float(np.max(radii))
    solid = np.zeros(len(points), dtype=bool)
    for i, near in enumerate(tree.query_ball_point(points, reach)):
        if near:
            d = points[i] - centres[near]
            d -= np.round(d / cell) * cell
            solid[i] = bool((np.einsum("ij,ij->i", d, d) < np.asarray(radii)[near] ** 2).any())
    return solid


def locate(mesh, points, tolerance=1e-9):
    """Per point, a cell holding it (-1: none), by the barycentric coordinates in the straight tetrahedron of the
    cell's corners among the bounding-box candidates. dolfinx's compute_colliding_cells stops with "GJK error: max
    iteration limit reached" on curved cells; a point between a curved face and its chord is then given the
    neighbour's cell or none, and its value is extrapolated from the cell found or taken as solid."""
    tree = geometry.BoundingBoxTree(mesh, mesh.topology.dim)
    candidates = geometry.compute_collisions(tree, points)
    offsets, links = candidates.offsets, candidates.array
    owner = np.repeat(np.arange(len(points)), np.diff(offsets))
    x = mesh.geometry.x
    corners = x[mesh.geometry.dofmap.array.reshape(-1, mesh.geometry.dofmap.offsets[1])[:, :4]]
    out = np.full(len(points), -1, dtype=np.int32)
    for start in range(0, len(links), 2_000_000):
        cell, own = links[start : start + 2_000_000], owner[start : start + 2_000_000]
        c = corners[cell]
        m = np.stack([c[:, 1] - c[:, 0], c[:, 2] - c[:, 0], c[:, 3] - c[:, 0]], axis=2)
        lam = np.linalg.solve(m, (points[own] - c[:, 0])[:, :, None])[:, :, 0]
        inside = np.minimum(lam.min(1), 1.0 - lam.sum(1)) >= -tolerance
        out[own[inside]] = cell[inside]
    return out


def evaluate(f, points, cells, size):
    """f at the points in their cells, (n, size); NaN at a point whose cell's pull-back fails (a point just
    outside a curved cell: dolfinx's Newton iteration then stops with an error for the whole call, so the
    calls are split until the failing points are alone)."""
    try:
        return f.eval(points, cells).reshape(len(points), size)
    except RuntimeError:
        if len(points) == 1:
            return np.full((1, size), np.nan)
        half = len(points) // 2
        return np.concatenate(
            [evaluate(f, points[:half], cells[:half], size), evaluate(f, points[half:], cells[half:], size)]
        )


def velocity_at(mesh, u, points):
    """u (a collapsed P2 vector function) at the points; zero where no cell holds the point or the cell's
    pull-back fails. Also returns the count of such points."""
    cells = locate(mesh, points)
    found = np.nonzero(cells >= 0)[0]
    out = np.zeros((len(points), 3))
    if len(found):
        out[found] = evaluate(u, points[found], cells[found], 3)
    lost = ~np.isfinite(out).all(1)
    out[lost] = 0.0
    return out, len(points) - len(found) + int(lost.sum())


def pressure_at(mesh, p, points, gradient, cell):
    """The pressure p~ + G . x at points (unwrapped; p~ is evaluated at their wrapped images), NaN where no
    cell holds the point."""
    wrapped = np.ascontiguousarray(np.mod(points, np.asarray(cell, dtype=float)))
    cells = locate(mesh, wrapped)
    out = np.full(len(points), np.nan)
    found = np.nonzero(cells >= 0)[0]
    if len(found):
        out[found] = evaluate(p, wrapped[found], cells[found], 1)[:, 0]
    return out + np.asarray(points) @ np.asarray(gradient, dtype=float)


def fluxes(mesh, u, triangles, normals, centres, radii, cell, element_size, chunk=400_000):
    """Per triangle (m, 3 vertices, 3), the flux of u through it along its unit normal (m, 3)."""
    cell = np.asarray(cell, dtype=float)
    triangles = np.asarray(triangles, dtype=float)
    out = np.zeros(len(triangles))
    edges = np.linalg.norm(triangles - np.roll(triangles, 1, axis=1), axis=2).max(1)
    subdivisions = np.maximum(2, np.ceil(SUBDIVISION * edges / element_size).astype(int))
    missing = 0
    batch, owners, weights = [], [], []

    def flush():
        nonlocal missing, batch, owners, weights
        if not batch:
            return
        pts = np.mod(np.concatenate(batch), cell)
        own = np.concatenate(owners)
        w = np.concatenate(weights)
        fluid = ~in_solid(pts, centres, radii, cell)
        vel = np.zeros_like(pts)
        vel[fluid], lost = velocity_at(mesh, u, np.ascontiguousarray(pts[fluid]))
        missing += lost
        np.add.at(out, own, w * np.einsum("ij,ij->i", vel, normals[own]))
        batch, owners, weights = [], [], []

    rules = {}
    count = 0
    for f, (tri, m) in enumerate(zip(triangles, subdivisions)):
        if m not in rules:
            rules[m] = subdivision(int(m))
        bary, w = rules[m]
        area = 0.5 * np.linalg.norm(np.cross(tri[1] - tri[0], tri[2] - tri[0]))
        batch.append(bary @ tri)
        owners.append(np.full(len(w), f))
        weights.append(w * area)
        count += len(w)
        if count > chunk:
            flush()
            count = 0
    flush()
    return out, missing


def imbalance(cells, flux, n_cells):
    """|sum of the fluxes out of each pore| summed, over the sum of |flux| out of each pore: 0 for exact fluxes."""
    i, j = np.asarray(cells)[:, 0], np.asarray(cells)[:, 1]
    net = np.bincount(i, flux, n_cells) - np.bincount(j, flux, n_cells)
    gross = np.bincount(i, np.abs(flux), n_cells) + np.bincount(j, np.abs(flux), n_cells)
    return float(np.abs(net).sum() / gross.sum())
