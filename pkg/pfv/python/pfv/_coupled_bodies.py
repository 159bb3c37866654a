"""The YADE bodies coupled with the fluid, a part of pfv.FlowEngine: which they are and where they are.

Owns YADE's attributes that choose the bodies and place the walls (wallIds, boundaryUseMaxMin, mask,
convertClumps, wallThickness, idOffset) and the scans of ``O.bodies`` (``_scene_scan.SceneScan``):
the current one, which each step reads the positions through, and the one the current mesh was
built from (``stepped``), whose ids name the core's vertices in every query. A change of these
attributes marks the scan outdated: the next step scans again and remeshes.
"""
from __future__ import annotations

import contextlib
import re
from collections.abc import Sequence
from typing import Any

import numpy as np

import yade

from . import _attributes as attributes
from ._scene_scan import SceneScan

# YADE's boundary normals (setBoundaryNormal), pointing into the sample.
_NORMALS = ((1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1))


class CoupledBodies:
    """The coupled spheres and the six walls; `core` is the engine's pfv.Engine, `warned` the
    engine's set of one-time warnings given (the scan warns once of bodies it leaves out)."""

    def __init__(self, core: Any, warned: set[str]) -> None:
        self._core = core
        self._warned = warned
        self._use_max_min = [True] * 6
        self._wall_ids = list(range(6))
        self._mask = 0
        self._convert_clumps = True
        self._wall_thickness = 0.0
        self._id_offset = 0
        self.use_sphere_pack = True  # False: always read the coordinate lists
        self.scan: SceneScan | None = None  # the last scan, None before the first step
        self.stepped: SceneScan | None = None  # the scan of the last successful step: the mesh's spheres

    # -- YADE's attributes ------------------------------------------------------------------------
    @property
    def boundaryUseMaxMin(self) -> list[bool]:
        return list(self._use_max_min)

    @boundaryUseMaxMin.setter
    def boundaryUseMaxMin(self, value: Sequence[bool]) -> None:
        value = attributes.as_bool6("boundaryUseMaxMin", value)
        if value != self._use_max_min:
            self._use_max_min = value
            self._core.request_remesh()
            self._core.reset_history()

    @property
    def wallIds(self) -> list[int]:
        return list(self._wall_ids)

    @wallIds.setter
    def wallIds(self, value: Sequence[int]) -> None:
        value = attributes.as_wall_ids(value)
        if value != self._wall_ids:
            self._wall_ids = value
            self._bodies_changed()

    @property
    def convertClumps(self) -> bool:
        """True (YADE's default): a clump enters the triangulation as the sphere of its members' volume at its
        centre of mass and its fluid force goes to the clump; False: its spherical members are coupled as
        spheres of their own and the clump is left out (YADE's NewtonIntegrator sums their forces)."""
        return self._convert_clumps

    @convertClumps.setter
    def convertClumps(self, value: bool) -> None:
        self._convert_clumps = attributes.as_flag("convertClumps", value)
        self._bodies_changed()

    @property
    def mask(self) -> int:
        """> 0: only spheres whose groupMask shares a bit with mask are coupled (at the next scan of the
        bodies, i.e. the next remesh)."""
        return self._mask

    @mask.setter
    def mask(self, value: int) -> None:
        self._mask = attributes.as_integer("mask", value, low=-(2**63), high=2**63 - 1)  # YADE's mask is a long
        self._bodies_changed()

    @property
    def wallThickness(self) -> float:
        """> 0: a wall body named in wallIds (without boundaryUseMaxMin) bounds the domain at half this
        thickness from its centre, towards the sample (YADE's rule); 0: at a box wall's inner face."""
        return self._wall_thickness

    @wallThickness.setter
    def wallThickness(self, value: float) -> None:
        value = attributes.as_number("wallThickness", value)
        if value < 0:
            raise ValueError(f"wallThickness must be >= 0, got {value}")
        self._wall_thickness = value
        self._bodies_changed()

    @property
    def idOffset(self) -> int:
        """YADE's id offset of the walls. Set < 0: at the next scan of the bodies it becomes len(O.bodies)
        and wallIds becomes idOffset + (0 .. 5), walls that are not bodies (with boundaryUseMaxMin)."""
        return self._id_offset

    @idOffset.setter
    def idOffset(self, value: int) -> None:
        self._id_offset = attributes.as_integer("idOffset", value)
        if self._id_offset < 0:
            self._bodies_changed()

    @property
    def position_source(self) -> str:
        """Where the sphere centres come from each step: "SpherePack" (YADE's C++ copy of the
        bodies' centres, read in place) or "coordinate lists" (yade._utils.coordsAndDisplacements,
        one Python list per axis; used when the pack's layout does not check out)."""
        return "coordinate lists" if self.scan is None else self.scan.position_source

    def setBoundaryNormal(self, index: int, v: Sequence[float]) -> None:
        """YADE's normal of boundary `index` (0..5), pointing into the sample. PFV's walls are the six
        axis-aligned planes: only YADE's default normal of each is accepted."""
        index = attributes.as_index("index", index)
        if not 0 <= index < 6:
            raise IndexError(f"boundary index must be in 0..5, got {index}")
        normal = np.array(attributes.as_point("setBoundaryNormal normal", v))
        if not np.allclose(normal, _NORMALS[index], rtol=0, atol=1e-12):
            raise NotImplementedError(
                f"pfv.FlowEngine: boundary {index} is the axis-aligned plane with normal {_NORMALS[index]}; other "
                "normals are not supported"
            )

    def _bodies_changed(self) -> None:
        """The bodies must be scanned again at the next step (which remeshes)."""
        if self.scan is not None:
            self.scan.outdated = True
        self._core.reset_history()

    # -- scans ------------------------------------------------------------------------------------
    def rescan(self) -> SceneScan:
        """Scan the bodies again (sphere ids, radii, masses, walls); done at each remesh (bodies may change).
        A negative idOffset becomes len(O.bodies) first, and wallIds follow (YADE's rule)."""
        if self._id_offset < 0:
            self._id_offset = len(yade.O.bodies)
            self._wall_ids = [self._id_offset + w for w in range(6)]
        self.scan = SceneScan(
            self._wall_ids,
            self._use_max_min,
            use_sphere_pack=self.use_sphere_pack,
            warned=self._warned,
            previous=self.scan,
            mask=self._mask,
            convert_clumps=self._convert_clumps,
            wall_thickness=self._wall_thickness,
        )
        return self.scan

    def scanned(self) -> SceneScan:
        """The current scan; scans first if there is none or the bodies' attributes changed since."""
        if self.scan is None or self.scan.outdated:
            return self.rescan()
        return self.scan

    def read_positions(self) -> tuple[np.ndarray, list[float]] | None:
        """Sphere centres (n, 3) and the six boundary coordinates, or None if bodies were erased
        since the last scan."""
        return self.scan.read_positions(self._use_max_min)

    def for_step(self, scene: Any) -> tuple[SceneScan, np.ndarray, list[float]]:
        """The scan a step uses and the positions it reads: a new scan (and a remesh) when bodies were
        added, erased or chosen otherwise, a new scan (radii and masses may have changed) before a remesh."""
        core = self._core
        scan = self.scan
        bodies_changed = scan is None or scan.outdated or len(scene.bodies) != scan.n_bodies
        if bodies_changed or core.remesh_due():
            self.rescan()
            if bodies_changed:
                core.request_remesh()
        read = self.read_positions()
        if read is None:  # bodies erased (which leaves len(O.bodies) as it was)
            self.rescan()
            core.request_remesh()
            read = self.read_positions()
        return (self.scan, *read)

    def forget(self) -> None:
        """Drop the scans: the next step scans afresh."""
        self.scan = self.stepped = None

    # -- the current mesh's bodies ------------------------------------------------------------------
    def has_mesh(self) -> bool:
        return self._core.has_mesh() and self.stepped is not None

    def require_mesh(self) -> None:
        if not self.has_mesh():
            raise RuntimeError("the flow engine has not run yet: no pore mesh (run at least one step)")

    def vertex_of(self, body_id: int) -> int:
        """The core's vertex of a body (a sphere, or a wall by its wallIds entry) of the current mesh."""
        self.require_mesh()
        v = self.stepped.vertex_of_id.get(attributes.as_index("body id", body_id))
        if v is None:
            raise ValueError(f"body {body_id} is not coupled with the fluid (not a sphere nor a wall)")
        return v

    def body_of_vertex(self, vertex: int) -> int:
        """YADE body id of a core vertex: a sphere's id, or wallIds[w] for wall w."""
        ids = self.stepped.ids
        return int(ids[vertex]) if vertex < len(ids) else int(self.stepped.wall_ids[vertex - len(ids)])

    def wall_index(self, boundary: Any) -> int:
        """The wall (0..5) of a boundary named by body id, as getBoundaryFlux takes it."""
        self.require_mesh()
        wall_ids = self.stepped.wall_ids  # those of the last step, if wallIds changed since
        boundary = attributes.as_index("boundary", boundary)
        if boundary not in wall_ids:
            raise ValueError(f"body {boundary} is not one of the boundaries wallIds = {wall_ids}")
        return wall_ids.index(boundary)

    def positions_now(self) -> tuple[np.ndarray, list[float]]:
        """The current positions of the current mesh's spheres, and the six boundary coordinates."""
        read = self.stepped.read_positions(self._use_max_min)
        if read is None:
            raise RuntimeError("bodies were erased since the last step: run a step first")
        return read

    @staticmethod
    @contextlib.contextmanager
    def named_in_errors(scan: SceneScan):
        """Errors of the core name spheres by their index in the scan and walls by number: say
        which YADE body is meant, and which sphere set a wall placed by boundaryUseMaxMin."""
        try:
            yield
        except (ValueError, RuntimeError) as error:
            message = re.sub(r"sphere (\d+)", lambda m: f"sphere #{scan.ids[int(m.group(1))]}", str(error))
            setters = [scan.describe_wall_setter(int(w)) for w in sorted(set(re.findall(r"walls? (\d)", message)))]
            setters = [s for s in setters if s]
            if setters:
                message += " (" + "; ".join(setters) + ")"
            raise type(error)(f"pfv.FlowEngine: {message}") from None

    # -- O.save / O.load ----------------------------------------------------------------------------
    def saved(self) -> dict[str, Any]:
        return {
            "boundary_use_max_min": list(self._use_max_min),
            "wall_ids": list(self._wall_ids),
            "mask": self._mask,
            "convert_clumps": self._convert_clumps,
            "wall_thickness": self._wall_thickness,
            "id_offset": self._id_offset,
            "use_sphere_pack": self.use_sphere_pack,
        }

    def restore(self, state: dict[str, Any]) -> None:
        """The settings of saved(), as they were (no remesh requested: the core's run state follows)."""
        self._use_max_min = list(state["boundary_use_max_min"])
        self._wall_ids = list(state["wall_ids"])
        self._mask = state["mask"]
        self._convert_clumps = state["convert_clumps"]
        self._wall_thickness = state["wall_thickness"]
        self._id_offset = state["id_offset"]
        self.use_sphere_pack = state["use_sphere_pack"]
