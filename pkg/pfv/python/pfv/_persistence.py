"""O.save / O.load of a scene with a pfv.FlowEngine: the engine goes on where it stopped.

YADE saves a ``PyRunner`` subclass as a plain ``PyRunner`` (its command and label, nothing of the
Python object), and restores it so. PFV therefore wraps YADE's ``save``/``saveTmp`` and
``load``/``loadTmp``/``reload``: before a save, each pfv engine in ``O.engines`` writes its
settings and its run state (the positions its mesh was built from, the positions and pressures
of its last step, the remesh schedule) into a tag of the scene, ``O.tags["pfv.saved.<i>"]``
for the engine at ``O.engines[i]``; after a load, every plain ``PyRunner`` with PFV's command
and such a tag is replaced by a new ``pfv.FlowEngine`` rebuilt from it (which rebuilds the
same mesh: the triangulation is a function of its input), and YADE binds its label again. The
next step then equals the uninterrupted run's. A tag is emptied once used; arrays travel as
base64 of their float64 bytes, bit for bit.
"""
from __future__ import annotations

import base64
import builtins
import json
from typing import Any

import numpy as np

import yade
from yade.wrapper import Omega, PyRunner

TAG = "pfv.saved."  # + index in O.engines


def _encode(value: Any) -> Any:
    if isinstance(value, np.ndarray):
        data = np.ascontiguousarray(value, dtype=np.float64)
        return {"__array__": base64.b64encode(data.tobytes()).decode("ascii"), "shape": list(data.shape)}
    if isinstance(value, dict):
        return {k: _encode(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_encode(v) for v in value]
    if isinstance(value, (np.floating, np.integer, np.bool_)):
        return value.item()
    return value


def _decode(value: Any) -> Any:
    if isinstance(value, dict):
        if "__array__" in value:
            data = np.frombuffer(base64.b64decode(value["__array__"]), dtype=np.float64)
            return data.reshape(value["shape"]).copy()
        return {k: _decode(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_decode(v) for v in value]
    return value


def _flow_engine_class() -> type:
    from .flow_engine import FlowEngine  # circular at import time: flow_engine installs this module

    return FlowEngine


def _before_save() -> None:
    cls = _flow_engine_class()
    tags = yade.O.tags
    for key in tags.keys():  # an earlier save's, for engines no longer there
        if key.startswith(TAG):
            tags[key] = ""
    for i, engine in enumerate(yade.O.engines):
        if isinstance(engine, cls):
            tags[TAG + str(i)] = json.dumps(_encode(engine._saved_state()))


def _after_load() -> None:
    cls = _flow_engine_class()
    engines = list(yade.O.engines)
    restored = False
    for i, runner in enumerate(engines):
        try:
            text = yade.O.tags[TAG + str(i)]
        except KeyError:
            continue
        if not text or type(runner) is not PyRunner or not cls.drives(runner.command):
            continue
        engines[i] = cls._from_saved(_decode(json.loads(text)), runner)
        yade.O.tags[TAG + str(i)] = ""
        restored = True
    if restored:
        yade.O.engines = engines  # YADE binds the labels to the new objects


def adopt_runner(command: str):
    """The engine rebuilt for the restored PyRunner that runs `command`, put in its place in
    O.engines from the next iteration on (this one is under way), or None without a saved state."""
    cls = _flow_engine_class()
    engines = list(yade.O.engines)
    for i, runner in enumerate(engines):
        if type(runner) is PyRunner and runner.command == command:
            try:
                text = yade.O.tags[TAG + str(i)]
            except KeyError:
                return None
            if not text:
                return None
            engines[i] = cls._from_saved(_decode(json.loads(text)), runner)
            yade.O.tags[TAG + str(i)] = ""
            # Taken up at the next iteration; YADE binds labels then, the script may look before.
            yade.O.engines = engines
            if runner.label:
                setattr(builtins, runner.label, engines[i])
            return engines[i]
    return None


def _wrap(method_name: str, before=None, after=None) -> None:
    original = getattr(Omega, method_name)
    if getattr(original, "_pfv_wrapped", False):
        return

    def wrapped(self, *args, **kwargs):
        if before is not None:
            before()
        result = original(self, *args, **kwargs)
        if after is not None:
            after()
        return result

    wrapped._pfv_wrapped = True
    wrapped.__wrapped__ = original  # YADE's own method
    wrapped.__doc__ = original.__doc__
    setattr(Omega, method_name, wrapped)


def install() -> None:
    """Wrap YADE's save and load methods (once per process)."""
    for name in ("save", "saveTmp"):
        _wrap(name, before=_before_save)
    for name in ("load", "loadTmp", "reload", "reloadTmp"):
        if hasattr(Omega, name):
            _wrap(name, after=_after_load)
