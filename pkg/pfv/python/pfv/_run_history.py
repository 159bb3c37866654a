"""Which scene a pfv.FlowEngine runs in and when it last stepped, a part of the engine.

dV/dt spans the time since the engine's last step, so that step must have been the engine's run of
the previous iteration; after a gap (the engine dead, its iterPeriod skipping iterations, a failed
step) or in a scene the engine has not run in (O.reset(), O.switchScene), the history is forgotten.
A scene is told from another by a token the engine leaves in its ``O.tags``.
"""
from __future__ import annotations

import uuid
from typing import Any

_SCENE_TAG = "pfv.FlowEngine"  # key in O.tags of the token that tells this scene from a new one


class RunHistory:
    """The scene token and the last step of the engine whose key (in the engine registry) is `key`."""

    def __init__(self, key: int) -> None:
        self._tag_key = f"{_SCENE_TAG}.{key}"
        self.scene_tag: str | None = None  # the value this engine left in O.tags: a new scene lacks it
        self.last_step: tuple[int, float, float] | None = None  # (O.iter, O.time, dt) of the last step

    def in_scene(self, scene: Any) -> bool:
        """Whether this engine last ran in `scene` (which then holds its tag)."""
        try:
            return self.scene_tag is not None and scene.tags[self._tag_key] == self.scene_tag
        except KeyError:
            return False

    def enter(self, scene: Any) -> bool:
        """Tag `scene` as this engine's; True if the engine had run in another scene before."""
        if self.in_scene(scene):
            return False
        new = self.scene_tag is not None  # not the first step: a new scene
        if new:
            self.last_step = None
        self.scene_tag = uuid.uuid4().hex
        scene.tags[self._tag_key] = self.scene_tag
        return new

    def time_since_last_step(self, scene: Any, iter_period: int) -> tuple[float, bool]:
        """The time the positions moved over since the last step of this engine, and whether the dV/dt
        history must be forgotten: then O.dt, when that step was not the last iteration's run of the
        engine (`iter_period`, the PyRunner's)."""
        last = self.last_step
        period = max(1, int(iter_period))
        if last is not None and scene.iter - last[0] == period:
            return (scene.dt if period == 1 else scene.time - last[1]), False
        return scene.dt, last is not None

    def record(self, scene: Any, dt: float) -> None:
        """A step made: `dt` the time its dV/dt spanned."""
        self.last_step = (scene.iter, scene.time, dt)
