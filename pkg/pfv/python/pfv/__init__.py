"""PFV: pore-scale finite-volume fluid coupling for YADE.

``from pfv import FlowEngine`` replaces YADE's built-in FlowEngine in a scene script, ``from pfv import
PeriodicFlowEngine`` its PeriodicFlowEngine in a periodic cell.
The C++ engine alone is ``pfv.Engine`` (usable without YADE).
"""
from ._core import set_num_threads, get_max_threads  # noqa: F401
from ._engine import Engine  # noqa: F401  (the core, its settings checked at assignment)
from ._time_step import TimeStepWarning  # noqa: F401  (no YADE needed)
from . import waves  # noqa: F401  (time-dependent boundary pressures; no YADE needed)
from ._yade_version import check_running_yade

check_running_yade()  # inside another YADE than the bridge's: ImportError naming both versions

try:
    from .flow_engine import FlowEngine  # noqa: F401  (needs YADE's Python modules)
    from .periodic_flow_engine import PeriodicFlowEngine  # noqa: F401
except ImportError as _error:  # plain python3.11 without yade: the core stays usable
    _yade_import_error = _error

    def __getattr__(name):
        if name in ("FlowEngine", "PeriodicFlowEngine"):
            raise ImportError(f"pfv.{name} needs YADE (run the script with yade-double): {_yade_import_error}")
        raise AttributeError(name)
