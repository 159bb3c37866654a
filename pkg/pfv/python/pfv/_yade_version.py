"""The YADE version PFV's bridge is pinned to, checked when pfv is imported inside YADE.

The bridge (pkg/pfv/yade_bridge) reads YADE's C++ objects by their memory layout and calls a
function of YADE's by its mangled name, both as one YADE build has them; that build's version is
stated in pkg/pfv/yade_bridge/yade_version.hpp and reaches Python as ``_core.PINNED_YADE_VERSION``.
Under another YADE, importing pfv raises ``YadeVersionError`` (an ImportError) naming both
versions. YADE states its version as ``yade.config.version`` (e.g. "2023.02a").
"""
from __future__ import annotations

from ._core import PINNED_YADE_VERSION


class YadeVersionError(ImportError):
    """pfv was imported inside a YADE other than the one its bridge is pinned to."""


def check(running: str, pinned: str = PINNED_YADE_VERSION) -> None:
    """Raise YadeVersionError unless `running` (YADE's version string) is `pinned`."""
    if str(running).strip() != pinned:
        raise YadeVersionError(
            f"pfv is built for YADE {pinned} (it reads YADE's objects by their memory layout in that version), "
            f"but this is YADE {running}; rebuild PFV against this YADE after checking the layouts in "
            "pkg/pfv/yade_bridge, or run YADE " + pinned
        )


def check_running_yade() -> None:
    """check() on the YADE this process runs; nothing without YADE (plain Python)."""
    try:
        import yade.config
    except ImportError:
        return
    check(getattr(yade.config, "version", "of unknown version"))
