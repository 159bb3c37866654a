"""The scene scan: what pfv.FlowEngine reads of YADE's bodies at each remesh, and the per-step read.

A ``SceneScan`` is made from ``O.bodies`` whenever the bodies or the mesh may have changed. It holds
the coupled spheres (YADE ids, rows in ``O.bodies``, radii, masses of the dynamic ones), the wall
bodies (rows and the offset of a box wall's inner face), the map from body id to the core's vertex,
the DEM time-step limit, the force bridge that adds the fluid forces to YADE's bodies, and the
position reader chosen for this scene: YADE's SpherePack read in place when it reproduces the
Python interface exactly, else one coordinate list per axis. Between scans, ``read_positions``
gives the sphere centres and the six boundary coordinates at every step. Kept apart from the
engine because it is the only part that knows YADE's body layout.
"""
from __future__ import annotations

import math
import warnings
from collections.abc import Sequence

import numpy as np

import yade
from yade.wrapper import Box, Facet, Sphere, Wall
from yade.minieigenHP import Vector3
from yade._packSpheres import SpherePack

from ._core import YadeForceBridge, gather_axis, gather_sphere_pack, sphere_pack_size

_coordinates = yade._utils.coordsAndDisplacements
_WALL_SHAPES = (Box, Wall, Facet)  # the shapes a body named in wallIds may have


def _equivalent_radius(scene, clump) -> float:
    """The radius of the sphere of the clump's volume (the sum of its members' volumes), placed at its
    centre of mass: how a clump enters the triangulation with convertClumps, as in YADE."""
    cubes = 0.0
    for member in clump.shape.members.keys():
        shape = scene.bodies[member].shape
        if not isinstance(shape, Sphere):
            raise NotImplementedError(
                f"pfv.FlowEngine: clump #{clump.id} has a member that is not a sphere "
                f"(#{member}, {type(shape).__name__})"
            )
        cubes += shape.radius**3
    return cubes ** (1.0 / 3.0)


class _CoupledSpheres:
    """One pass over O.bodies: the spheres (and clumps, with convert_clumps) coupled with the fluid, in
    id order, and what the scan needs of every body. Each attribute read through Boost.Python makes a
    new wrapper: each is read once per body (the scan runs at every remesh; bench/flow_benchmark.py
    times it)."""

    def __init__(self, scene, wall_set: set[int], mask: int, convert_clumps: bool) -> None:
        self.ids, self.radii, self.rows, self.masses = [], [], [], []
        self.others = self.clumps = 0
        self.pack_index = []  # the spheres' places in SpherePack.fromSimulation(): every sphere body in id order
        self.mass_per_diameter = float("inf")  # min m/d over the dynamic coupled spheres
        self.row_of = row_of = {}
        pack_size = 0
        for row, b in enumerate(scene.bodies):
            bid = b.id
            row_of[bid] = row
            shape = b.shape
            is_clump = b.isClump
            is_sphere = isinstance(shape, Sphere) and not is_clump
            pack_size += is_sphere
            if bid in wall_set or (mask > 0 and not b.groupMask & mask):
                continue  # a wall, or not affected by this engine (YADE leaves it out of the triangulation)
            radius = self._radius(scene, b, shape, is_clump, is_sphere, convert_clumps)
            if radius is not None:
                self._add(b, bid, row, radius, pack_size - 1 if is_sphere else -1)
        self.pack_size = pack_size

    def _radius(self, scene, b, shape, is_clump: bool, is_sphere: bool, convert_clumps: bool) -> float | None:
        """The radius b enters the triangulation with, None if it does not."""
        if is_clump:
            if not convert_clumps:
                return None  # its members are the spheres
            radius = _equivalent_radius(scene, b)
            self.clumps += 1
            return radius
        if b.isClumpMember and convert_clumps:
            return None  # the clump stands for it
        if is_sphere:
            return shape.radius
        self.others += 1
        return None

    def _add(self, b, bid: int, row: int, radius: float, pack_index: int) -> None:
        self.pack_index.append(pack_index)
        self.ids.append(bid)
        self.radii.append(radius)
        self.rows.append(row)
        state = b.state
        mass = state.mass
        if not math.isfinite(mass) or mass < 0:
            raise ValueError(
                f"pfv.FlowEngine: sphere #{bid} has mass {mass}: a coupled sphere needs a " "finite mass >= 0"
            )
        moving = b.dynamic and mass > 0 and state.blockedDOFs != "xyzXYZ"
        self.masses.append(mass if moving else 0.0)
        if moving:
            self.mass_per_diameter = min(self.mass_per_diameter, mass / (2 * radius))


class SceneScan:
    """Sphere ids, radii, masses and wall bodies of the scene, and how to read their positions.

    `wall_ids` and `use_max_min` are the engine's wallIds and boundaryUseMaxMin; `use_sphere_pack`
    False always reads the coordinate lists; `warned` collects the one-time warnings of the engine;
    `previous` is the last scan, whose force bridge and position array are reused when they fit.
    YADE's `mask` (> 0: only spheres whose groupMask shares a bit with it), `convert_clumps` (False:
    clump members are coupled as spheres, the clumps left out) and `wall_thickness` (> 0: a wall
    body bounds the domain at this half thickness from its centre) are applied as YADE does.
    """

    def __init__(
        self,
        wall_ids: Sequence[int],
        use_max_min: Sequence[bool],
        *,
        use_sphere_pack: bool = True,
        warned: set[str] | None = None,
        previous: SceneScan | None = None,
        mask: int = 0,
        convert_clumps: bool = True,
        wall_thickness: float = 0.0,
    ) -> None:
        scene = yade.O
        if scene.periodic:
            raise NotImplementedError("pfv.FlowEngine does not support periodic scenes yet")
        self.wall_ids = list(wall_ids)
        self.outdated = False  # set by the engine when wallIds changes: scan again before use
        spheres = _CoupledSpheres(scene, set(self.wall_ids), mask, convert_clumps)
        ids = spheres.ids
        if not ids:
            raise ValueError(
                f"pfv.FlowEngine: the scene has no sphere to couple with the fluid "
                f"({len(spheres.row_of)} bodies, walls wallIds = {self.wall_ids})"
            )
        self.clumps = spheres.clumps  # clumps entered as their equivalent spheres
        if warned is None:
            warned = set()
        if spheres.others and "others" not in warned:
            warned.add("others")
            # stacklevel 4: the engine's step, the caller of CoupledBodies.rescan.
            warnings.warn(
                f"pfv.FlowEngine: {spheres.others} bodies that are neither spheres nor the six walls "
                "are left out of the flow",
                stacklevel=4,
            )
        wall_rows, wall_half = self._scan_walls(scene, spheres.row_of, use_max_min, wall_thickness)
        vertex_of_id = {bid: k for k, bid in enumerate(ids)}
        for w, bid in enumerate(self.wall_ids):
            vertex_of_id.setdefault(bid, len(ids) + w)
        self.ids = np.array(ids, dtype=np.int64)  # YADE ids of the coupled spheres
        self.rows = np.array(spheres.rows, dtype=np.int64)  # their rows in O.bodies
        self.radii = np.array(spheres.radii, dtype=float)
        self.masses = np.array(spheres.masses, dtype=float)  # 0 for spheres that do not move
        self.mass_per_diameter = spheres.mass_per_diameter
        self.wall_rows = wall_rows  # -1: wall not in the scene
        self.wall_half = wall_half  # inner face - centre, along the wall's axis
        self.n_bodies = len(scene.bodies)
        self.n_listed = len(spheres.row_of)  # bodies in the coordinate lists
        self.vertex_of_id = vertex_of_id  # body id -> row of core.forces()
        self._bridge_key, self.force_bridge = self._make_force_bridge(ids, wall_rows, previous)
        dem = yade.utils.PWaveTimeStep() if ids else float("inf")
        self.dt_dem = dem if dem > 0 else float("inf")
        self._positions = previous._positions if previous is not None else None
        self._wall_setter: dict[int, int] = {}  # wall -> sphere that placed it (boundaryUseMaxMin)
        self.pack: SpherePack | None = None  # a SpherePack whose array this scan reads, or None
        self.pack_index: np.ndarray | None = None  # the spheres' places in the pack
        self.pack_size = 0  # sphere bodies in the pack
        if use_sphere_pack and not spheres.clumps:  # a SpherePack lists no clump bodies
            self._choose_position_reader(np.array(spheres.pack_index, dtype=np.int64), spheres.pack_size, use_max_min)

    def _scan_walls(
        self, scene, row_of: dict[int, int], use_max_min: Sequence[bool], wall_thickness: float
    ) -> tuple[list[int], list[float]]:
        """Each wall's row in O.bodies (-1: not a body) and the offset of its inner face from its centre."""
        wall_rows, wall_half = [], []
        for w, bid in enumerate(self.wall_ids):
            if bid not in row_of:
                if not use_max_min[w]:
                    raise ValueError(f"wallIds[{w}] = {bid} is not a body of the scene")
                wall_rows.append(-1)
                wall_half.append(0.0)
                continue
            b = scene.bodies[bid]
            # The body's position bounds the domain unless boundaryUseMaxMin: it must be a wall.
            if not use_max_min[w] and (not isinstance(b.shape, _WALL_SHAPES) or b.isClump or b.isClumpMember):
                raise ValueError(
                    f"wallIds[{w}] = {bid} names a {type(b.shape).__name__} body, not a wall " "(a Box, Wall or Facet)"
                )
            wall_rows.append(row_of[bid])
            # A box wall bounds the domain with its inner face, unless wallThickness says where.
            if wall_thickness > 0:
                half = 0.5 * wall_thickness
            else:
                half = b.shape.extents[w // 2] if isinstance(b.shape, Box) else 0.0
            wall_half.append(-half if w % 2 else half)
        return wall_rows, wall_half

    def _make_force_bridge(
        self, ids: list[int], wall_rows: list[int], previous: SceneScan | None
    ) -> tuple[tuple[list[int], list[int]], YadeForceBridge]:
        """Spheres get force rows 0..n-1, the walls present rows n + w; the previous scan's bridge is
        kept when it maps the same bodies (its Vector3s are made once)."""
        bridge_ids = ids + [bid for w, bid in enumerate(self.wall_ids) if wall_rows[w] >= 0]
        bridge_rows = list(range(len(ids))) + [len(ids) + w for w in range(6) if wall_rows[w] >= 0]
        key = (bridge_ids, bridge_rows)
        if previous is not None and previous._bridge_key == key:
            return key, previous.force_bridge
        return key, YadeForceBridge(
            Vector3, np.array(bridge_ids, dtype=np.int64), np.array(bridge_rows, dtype=np.int64)
        )

    def _choose_position_reader(self, pack_index: np.ndarray, pack_size: int, use_max_min: Sequence[bool]) -> None:
        """Read the centres from a SpherePack (pkg/pfv/yade_bridge/yade_sphere_pack.hpp) if this YADE's pack gives,
        for every sphere, the centre and radius YADE's Python interface gives, bit for bit."""
        pack = SpherePack()
        pack.fromSimulation()
        centres, radii = np.empty((len(pack_index), 3)), np.empty(len(pack_index))
        if sphere_pack_size(pack) < 0 or not gather_sphere_pack(pack, pack_index, centres, radii, pack_size):
            return
        listed = self.read_positions(use_max_min)
        if listed is not None and np.array_equal(centres, listed[0]) and np.array_equal(radii, self.radii):
            self.pack_index = pack_index
            self.pack_size = pack_size
            self.pack = pack

    @property
    def position_source(self) -> str:
        """ "SpherePack" or "coordinate lists" (see FlowEngine.position_source)."""
        return "SpherePack" if self.pack is not None else "coordinate lists"

    def read_positions(self, use_max_min: Sequence[bool]) -> tuple[np.ndarray, list[float]] | None:
        """Sphere centres (n, 3) and the six boundary coordinates, or None if bodies were erased
        since the scan. `use_max_min` is boundaryUseMaxMin: a wall's coordinate from the spheres'
        extent rather than from its body."""
        pos = self._positions
        if pos is None or len(pos) != len(self.rows):  # one array per scan, not per step (core.step copies it)
            pos = np.empty((len(self.rows), 3))
            self._positions = pos
        walls = [0.0] * 6
        read = self._read_pack if self.pack is not None else self._read_lists
        if not read(pos, walls, use_max_min):
            return None
        self._walls_from_spheres(pos, walls, use_max_min)
        return pos, walls

    def _read_pack(self, pos: np.ndarray, walls: list[float], use_max_min: Sequence[bool]) -> bool:
        """The centres from the SpherePack, the walls from their bodies; False if bodies were erased."""
        pack = self.pack
        pack.fromSimulation()
        if not gather_sphere_pack(pack, self.pack_index, pos, None, self.pack_size):
            return False
        bodies = yade.O.bodies
        for w in range(6):
            if not use_max_min[w]:
                wall = bodies[self.wall_ids[w]]
                if wall is None:
                    return False
                walls[w] = wall.state.pos[w // 2] + self.wall_half[w]
        return True

    def _read_lists(self, pos: np.ndarray, walls: list[float], use_max_min: Sequence[bool]) -> bool:
        """The centres and the walls from the coordinate lists; False if bodies were erased."""
        for axis in range(3):
            coords = _coordinates(axis)[0]
            if len(coords) != self.n_listed:
                return False
            gather_axis(coords, self.rows, pos, axis)
            for w in (2 * axis, 2 * axis + 1):
                if not use_max_min[w]:
                    walls[w] = coords[self.wall_rows[w]] + self.wall_half[w]
            del coords  # one list alive at a time
        return True

    def _walls_from_spheres(self, pos: np.ndarray, walls: list[float], use_max_min: Sequence[bool]) -> None:
        """boundaryUseMaxMin: the wall at the extreme sphere surface, and which sphere placed it."""
        for w in range(6):
            if use_max_min[w]:
                axis = w // 2
                extreme = pos[:, axis] + self.radii if w % 2 else self.radii - pos[:, axis]
                k = int(extreme.argmax())
                walls[w] = float(pos[k, axis] + self.radii[k] if w % 2 else pos[k, axis] - self.radii[k])
                self._wall_setter[w] = k
            else:
                self._wall_setter.pop(w, None)

    def describe_wall_setter(self, w: int) -> str | None:
        """ "wall w is placed by sphere #id at (x, y, z)" when boundaryUseMaxMin placed it, else None."""
        k = self._wall_setter.get(w)
        if k is None or self._positions is None or k >= len(self.ids):
            return None
        return (
            f"wall {w} is placed by sphere #{self.ids[k]} at {tuple(self._positions[k].tolist())} "
            "(boundaryUseMaxMin)"
        )
