"""How pfv.FlowEngine hands its YADE-named attributes and methods to the parts that own them.

The engine holds its parts as attributes (``engine._bodies``, ``engine._geometry``, ...). A forwarded
attribute or method is declared on the engine class with the part's own member, so that the name,
the docstring and the signature are the part's and live in one place:

    wallIds = setting("_bodies", CoupledBodies.wallIds)
    getCellBarycenter = method("_geometry", CellGeometry.getCellBarycenter)

Both run under the engine's lock (``engine._lock``; but for a method that takes it itself): YADE's
O.run() steps on a thread of its own and a step holds the lock, so that an attribute read or a query
made meanwhile waits for the step and never sees a mesh being rebuilt (the C++ engine takes its own
lock too, shared_engine.hpp).
"""
from __future__ import annotations

import functools
from typing import Any, Callable


def exclusive(method: Callable[..., Any]) -> Callable[..., Any]:
    """Run an engine method under the engine's lock."""

    @functools.wraps(method)
    def locked(self, *args, **kwargs):
        with self._lock:
            return method(self, *args, **kwargs)

    return locked


def setting(part: str, member: property) -> property:
    """An engine property that reads and writes the property `member` of its part `part`."""

    def get(engine):
        with engine._lock:
            return member.fget(getattr(engine, part))

    def set_(engine, value):
        with engine._lock:
            member.fset(getattr(engine, part), value)

    # A read-only member stays read-only (no setter): the engine's attribute surface tells them apart.
    return property(get, set_ if member.fset is not None else None, doc=member.__doc__)


def method(part: str, function: Callable[..., Any], locked: bool = True) -> Callable[..., Any]:
    """An engine method that calls the method `function` of its part `part`; `locked` False for a
    method that takes the lock itself, for its part that needs it."""

    @functools.wraps(function)
    def forwarded(engine, *args, **kwargs):
        if not locked:
            return function(getattr(engine, part), *args, **kwargs)
        with engine._lock:
            return function(getattr(engine, part), *args, **kwargs)

    return forwarded
