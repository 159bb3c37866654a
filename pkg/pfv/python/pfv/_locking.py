"""The engine lock as a decorator, for pfv.FlowEngine and its mixins.

YADE's O.run() steps on a thread of its own; a step holds ``self._lock`` (an RLock) and so does
every query, so that a query made meanwhile waits for the step and never sees a mesh being
rebuilt (the C++ engine takes its own lock too, pfv/shared_engine.hpp).
"""
from __future__ import annotations

import functools


def exclusive(method):
    """Run `method` under the engine's lock."""
    @functools.wraps(method)
    def locked(self, *args, **kwargs):
        with self._lock:
            return method(self, *args, **kwargs)
    return locked
