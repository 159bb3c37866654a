"""YADE's calls that end scenes: ``O.reset()``, ``resetThisScene``/``resetCurrentScene``,
``resetAllScenes`` and the loads (``_persistence``), wrapped once per process.

Two things go wrong in YADE without them:

* ``O.reset()`` waits for the thread of a background ``O.run()`` to finish its iteration while it holds
  Python's GIL, and a Python engine (a ``PyRunner``, so ``pfv.FlowEngine``) in that iteration waits for
  the GIL: both wait forever. YADE's loads and its other resets release the GIL while they wait. The
  wrapped ``O.reset()`` first stops the run as they do (YADE's own ``resetThisScene``), then resets.
* YADE's converter of Python lists (``O.engines = [...]``) keeps a reference to every object of the list,
  so an engine that was ever in ``O.engines`` is never freed. The engines of an ended scene free their
  mesh, factor and results here (their settings stay: put into another scene, they start afresh).

The end of the process is one more: a script that ends while ``O.run()`` runs leaves YADE's thread
running while Python finalizes, and a thread that takes the GIL back then is ended on the spot, which
the C++ of a step (that lets the GIL go while it computes) cannot survive (``std::terminate``). At
exit, before Python finalizes, the run is paused, a step under way finishes, and no step starts.
"""
from __future__ import annotations

import atexit
from typing import Any, Callable

import yade
from yade.wrapper import Omega

from . import _registry as registry


def wrap(method_name: str, before: Callable[[], Any] | None = None, after: Callable[[Any], None] | None = None) -> None:
    """Wrap YADE's `method_name` of Omega (once per process): `before()` runs first, its value goes to
    `after(value)` once YADE's method has returned (not when it raised)."""
    original = getattr(Omega, method_name, None)
    if original is None or getattr(original, "_pfv_wrapped", False):
        return

    def wrapped(self, *args, **kwargs):
        token = before() if before is not None else None
        result = original(self, *args, **kwargs)
        if after is not None:
            after(token)
        return result

    wrapped._pfv_wrapped = True
    wrapped.__wrapped__ = original  # YADE's own method
    wrapped.__doc__ = original.__doc__
    wrapped.__name__ = method_name
    setattr(Omega, method_name, wrapped)


def yade_method(method_name: str) -> Callable[..., Any]:
    """YADE's own `method_name` of Omega, unwrapped."""
    method = getattr(Omega, method_name)
    return getattr(method, "__wrapped__", method)


def engines_of_this_scene() -> list[Any]:
    """The engines holding a mesh of the current scene (which the call about to run ends)."""
    return registry.holding(yade.O)


def engines_of_all_scenes() -> list[Any]:
    """The engines holding a mesh (every scene is about to end)."""
    return registry.holding(None)


def release(engines: list[Any]) -> None:
    """Free the meshes of `engines`, whose scene has ended."""
    for engine in engines:
        engine._release()


def _stop_then_list_all() -> list[Any]:
    # YADE's resetThisScene stops the run without the GIL (the running engine may finish its step),
    # then empties the current scene, which O.reset() is about to drop anyway.
    yade_method("resetThisScene")(yade.O)
    return engines_of_all_scenes()


_exiting = False


def exiting() -> bool:
    """Whether Python is about to finalize: a step must not start."""
    return _exiting


def _at_exit() -> None:
    global _exiting
    _exiting = True
    if yade.O.running:
        yade.O.pause()  # the thread ends after its iteration
    for engine in registry.engines():
        with engine._lock:  # a step under way finishes (the wait lets the GIL go)
            pass


def install() -> None:
    """Wrap YADE's resets (once per process), and pause the run at exit."""
    if not getattr(install, "done", False):
        atexit.register(_at_exit)
        install.done = True
    wrap("reset", before=_stop_then_list_all, after=release)
    wrap("resetAllScenes", before=engines_of_all_scenes, after=release)
    for name in ("resetThisScene", "resetCurrentScene"):
        wrap(name, before=engines_of_this_scene, after=release)
