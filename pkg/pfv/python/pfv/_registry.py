"""The live pfv.FlowEngines of the process: how a PyRunner command finds its engine, and which
engines hold a mesh.

YADE keeps a reference to every engine ever put into O.engines, so an engine taken out is never
freed: the step of an engine in use frees the mesh of those no longer in their scene
(``release_unused``), and the calls that end a scene free the meshes of its engines
(``holding``, ``_lifecycle``).
"""
from __future__ import annotations

import weakref
from typing import Any

import yade

_engines = weakref.WeakValueDictionary()  # key -> engine: PyRunner commands find their engine here
_holding: set[int] = set()  # keys of the engines that hold a mesh


def add(engine: Any) -> None:
    _engines[engine._key] = engine


def get(key: int) -> Any:
    """The engine of `key`, or None once it is gone."""
    return _engines.get(key)


def engines() -> list[Any]:
    """Every live engine."""
    return list(_engines.values())


def hold(engine: Any) -> None:
    """`engine` holds a mesh now."""
    _holding.add(engine._key)


def drop(engine: Any) -> None:
    """`engine` holds no mesh any more."""
    _holding.discard(engine._key)


def holding(scene: Any) -> list[Any]:
    """The engines that hold a mesh and last ran in `scene` (every scene: None)."""
    engines = []
    for key in list(_holding):
        engine = _engines.get(key)
        if engine is None:
            _holding.discard(key)
        elif scene is None or engine._ran_in(scene):
            engines.append(engine)
    return engines


def release_unused(current: Any) -> None:
    """Free the meshes of the engines that ran in the current scene but are no longer in O.engines."""
    others = [key for key in _holding if key != current._key]
    if not others:
        return
    scene = yade.O
    engines = scene.engines
    for key in others:
        engine = _engines.get(key)
        if engine is None:
            _holding.discard(key)
        else:
            engine._release_if_gone(scene, engines)
