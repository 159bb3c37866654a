"""O.save / O.load of a scene with a pfv.FlowEngine or pfv.PeriodicFlowEngine: the engine goes on where it stopped.

YADE saves a ``PyRunner`` subclass as a plain ``PyRunner`` (its command, label and schedule, nothing
of the Python object), and restores it so. PFV therefore wraps YADE's ``save``/``saveTmp``/
``sceneToString`` and ``load``/``loadTmp``/``reload``/``stringToScene``: before a save, each pfv
engine in ``O.engines`` writes its settings and its run state (the positions its mesh was built
from, the positions and pressures of its last step, the remesh schedule) into a tag of the scene,
``O.tags["pfv.saved.<i>"]`` for the engine at ``O.engines[i]``; after a load, every plain
``PyRunner`` with PFV's command and such a tag is replaced by a new engine of its class rebuilt from
it (which rebuilds the same mesh: the triangulation is a function of its input), and its label is
bound to it. The next step then equals the uninterrupted run's. A tag is emptied once used; arrays
travel as base64 of their float64 bytes, bit for bit.

A scene loaded where the wrappers did not see it (a process that imports pfv after the load, or
never: the PyRunner's command imports it at the first step) is taken over when pfv is imported.
Until then YADE's label names the plain PyRunner: attributes a script sets on it are kept in its
dictionary and applied to the engine when it takes over.
"""
from __future__ import annotations

import base64
import builtins
import json
import threading
import warnings
import weakref
from typing import Any

import numpy as np

import yade
from yade.wrapper import PyRunner

from . import _lifecycle

TAG = "pfv.saved."  # + index in O.engines
_adopted = weakref.WeakValueDictionary()  # command of a restored PyRunner -> the engine in its place


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


def _engine_classes() -> tuple[type, ...]:
    """The engine classes whose state a scene carries; each has drives(command), _saved_state() and
    _from_saved(state, runner)."""
    from .flow_engine import FlowEngine  # circular at import time: flow_engine installs this module
    from .periodic_flow_engine import PeriodicFlowEngine

    return FlowEngine, PeriodicFlowEngine


def _class_driving(command: str) -> type | None:
    return next((cls for cls in _engine_classes() if cls.drives(command)), None)


def _due_again(runner: PyRunner) -> int | None:
    """A scene saved in the middle of an iteration (while O.run() runs) is loaded with that iteration to
    run again from its start. The fluid forces of the engine's run in it are not saved, so the engine must
    run in it again: the iterLast that makes it due then, if YADE had started it in the iteration under
    way (None if not, or if the scene is between iterations)."""
    scene = yade.O
    if scene.subStep < 0 or runner.iterPeriod <= 0 or runner.iterLast != scene.iter:
        return None
    return scene.iter - runner.iterPeriod


def _before_save() -> None:
    classes = _engine_classes()
    tags = yade.O.tags
    for key in tags.keys():  # an earlier save's, for engines no longer there
        if key.startswith(TAG):
            tags[key] = ""
    for i, engine in enumerate(yade.O.engines):
        if isinstance(engine, classes):
            tags[TAG + str(i)] = json.dumps(_encode(engine._saved_state()))


def _restored_runners(engines: list[Any]) -> list[tuple[int, PyRunner, str, type]]:
    """(index, runner, saved state, engine class) of the plain PyRunners of `engines` that stand for a pfv
    engine."""
    found = []
    for i, runner in enumerate(engines):
        cls = _class_driving(runner.command) if type(runner) is PyRunner else None
        if cls is None:
            continue
        try:
            text = yade.O.tags[TAG + str(i)]
        except KeyError:
            continue
        if text:
            found.append((i, runner, text, cls))
    return found


def _settings_of_label(runner: PyRunner) -> dict[str, Any]:
    """What a script set on the runner's label before pfv took it over: YADE binds the label to a plain
    PyRunner, which keeps any attribute in its own dictionary, where no engine would read it."""
    bound = getattr(builtins, runner.label, None) if runner.label else None
    if type(bound) is not PyRunner or bound.command != runner.command:
        return {}
    return dict(vars(bound))


def _rebuilt(state: dict[str, Any], runner: PyRunner, cls: type) -> Any:
    """The engine of class `cls` for `runner`, with the settings made on its label before pfv took it over."""
    engine = cls._from_saved(state, runner)
    for name, value in _settings_of_label(runner).items():
        try:
            setattr(engine, name, value)
        except Exception as error:
            raise type(error)(
                f"pfv.{cls.__name__} '{runner.label}': {name} = {value!r}, set on the plain PyRunner YADE restored "
                f"before pfv was imported, is refused: {error} (import pfv before O.load)"
            ) from None
    return engine


def adopt_restored(loaded: bool = False) -> None:
    """Put a pfv engine rebuilt from its saved state in place of every plain PyRunner that stands for
    one, and bind the labels to them. Each engine is built before any is put in place: a setting refused
    leaves the scene as it was. `loaded`: the scene was loaded and has not run since (not from a step)."""
    engines = list(yade.O.engines)
    restored = _restored_runners(engines)
    rebuilt = [(i, runner, _rebuilt(_decode(json.loads(text)), runner, cls)) for i, runner, text, cls in restored]
    if not rebuilt:
        return
    for i, runner, engine in rebuilt:
        engines[i] = engine
        last = _due_again(runner) if loaded else None
        if last is not None:
            engine.iterLast = last
    # Between iterations YADE puts the list in place and binds the labels; in the middle of one (a scene
    # saved while O.run() ran, or a load from within a step) it keeps the list for the next iteration and
    # binds the labels to the engines of the iteration under way: the plain runners.
    yade.O.engines = engines
    for i, runner, engine in rebuilt:
        yade.O.tags[TAG + str(i)] = ""
        _adopted[runner.command] = engine
        if runner.label:
            setattr(builtins, runner.label, engine)


def engine_for(command: str) -> Any:
    """The pfv engine that stands for the plain PyRunner running `command` (all of the scene's taken
    over now), or None without a saved state."""
    adopt_restored()
    engine = _adopted.get(command)
    if engine is None or not any(e is engine for e in yade.O.engines):
        return None
    return engine


def running_engine(engine: Any, command: str, name: str) -> Any:
    """The engine a PyRunner running `command` drives: `engine` (its registry's, or None) while it is in O.engines;
    after a load the running PyRunner is a restored copy, and driving the old object would be silently wrong, so the
    engine adopted for the command. (A scene loaded by O.load is adopted at the load or when pfv is imported; in the
    iteration under way when it was adopted, YADE still runs the restored copies, which drive the adopted
    engines.) Raises RuntimeError naming pfv.`name` when the scene carries no saved state for it."""
    if engine is not None and any(e is engine for e in yade.O.engines):
        return engine
    adopted = engine_for(command)
    if adopted is None:
        raise RuntimeError(
            f"this pfv.{name} must be re-created: YADE restored it as a plain PyRunner and the scene carries no "
            f"saved state for it (saved before PFV could add it?); create a new pfv.{name} and put it back into "
            "O.engines"
        )
    return adopted


def _adopt_at_import() -> None:
    """A scene loaded before pfv was imported (``yade scene.yade.gz``, O.load in a script that imports pfv
    later): its engines are taken over now."""
    try:
        adopt_restored(loaded=threading.current_thread() is threading.main_thread())  # not from a step
    except Exception as error:  # the first step raises it again, naming the setting
        warnings.warn(f"pfv: the engines of the loaded scene are not taken over yet: {error}", stacklevel=3)


def _before_load() -> list[Any]:
    return _lifecycle.engines_of_this_scene()


def _after_load(ended: list[Any]) -> None:
    _lifecycle.release(ended)
    adopt_restored(loaded=True)


def install() -> None:
    """Wrap YADE's save and load methods (once per process), and take over a scene loaded before."""
    _lifecycle.install()
    for name in ("save", "saveTmp", "sceneToString"):
        _lifecycle.wrap(name, before=_before_save)
    for name in ("load", "loadTmp", "reload", "stringToScene"):
        _lifecycle.wrap(name, before=_before_load, after=_after_load)
    _adopt_at_import()
