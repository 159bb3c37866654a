"""YADE's FlowEngine attribute surface as PFV sees it: the names it implements and those it refuses.

pfv.FlowEngine keeps YADE's attribute names. Most map one to one onto a setting of the C++ core
under a PEP 8 name (``CORE_NAME``); a few are properties of FlowEngine itself (the six-value
boundary lists, ``useSolver``, ...), which use the converters below. Every other name YADE's
FlowEngine has is accepted only at YADE's default value (``check_default``) and reads back as that
default; YADE methods PFV lacks raise NotImplementedError. Kept apart from the engine so that the
rules "implemented, refused, misspelt" read in one place, next to the generated name list
(``_yade_api.py``).
"""
from __future__ import annotations

import ast
import math
import numbers
from collections.abc import Iterable, Sequence
from typing import Any

import numpy as np

from ._yade_api import ATTRIBUTES as _YADE_ATTRIBUTES, METHODS as _YADE_METHODS

# YADE attribute -> attribute of the core (pfv.Engine) that implements it.
CORE_NAME: dict[str, str] = {
    "viscosity": "viscosity",
    "permeabilityFactor": "permeability_factor",
    "clampKValues": "clamp_k_values",
    "minKdivKmean": "min_k_div_k_mean",
    "maxKdivKmean": "max_k_div_k_mean",
    "slipBoundary": "slip_boundary",
    "tolerance": "tolerance",
    "relax": "relax",
    "forceMetis": "force_metis",
    "meshUpdateInterval": "mesh_update_interval",
    "defTolerance": "def_tolerance",
    "pZero": "p_zero",
    "multithread": "background_remesh",
    "fluidBulkModulus": "fluid_bulk_modulus",
    "minimumPorosity": "minimum_porosity",
    "flatThreshold": "flat_threshold",
    "volumeCorrection": "volume_correction",
    "doInterpolate": "interpolate_on_remesh",
    "meanK_opt": "clamp_k_values",  # YADE's deprecated alias of clampKValues
    "viscousShear": "viscous_shear",
    # PFV extensions (PEP 8 names: YADE has no equivalent).
    "mixed_precision": "mixed_precision",
    "mixed_precision_min_entries": "mixed_precision_min_entries",
    "refinement_tolerance": "refinement_tolerance",
    "fluid_density": "fluid_density",
    "yade_wall_throat_factor": "yade_wall_throat_factor",
    "solver": "solver",
    "max_factor_bytes": "max_factor_bytes",
    "multigrid_smoother": "multigrid_smoother",
    "shear_viscosity": "shear_viscosity",
}

# YADE's useSolver numbers and the core's solver names (YADE's 2, Taucs, has no counterpart).
# YADE's 3, its default direct solver, is PFV's default too: "auto", the factor unless it would
# not fit or multigrid's step costs less (doc/solvers.md); solver="cholesky" insists on the factor.
_SOLVER_OF_USE_SOLVER: dict[int, str] = {0: "gauss_seidel", 1: "conjugate_gradient", 3: "auto"}
# Both of PFV's direct paths read as 3. The multigrid solver has no YADE number (YADE's 4 is its
# GPU CHOLMOD) and reads as -1.
_USE_SOLVER_OF: dict[str, int] = {**{v: k for k, v in _SOLVER_OF_USE_SOLVER.items()}, "cholesky": 3, "multigrid": -1}


def is_yade_attribute(name: str) -> bool:
    """Whether YADE's FlowEngine has an attribute of this name."""
    return name in _YADE_ATTRIBUTES


def is_yade_method(name: str) -> bool:
    """Whether YADE's FlowEngine has a method of this name."""
    return name in _YADE_METHODS


def default(name: str) -> Any:
    """YADE's default value of its FlowEngine attribute `name` (its repr when it is no Python literal)."""
    text = _YADE_ATTRIBUTES[name]
    try:
        return ast.literal_eval(text)
    except (ValueError, SyntaxError):
        return text


def check_default(name: str, value: Any) -> None:
    """Accept `value` for the unsupported YADE attribute `name` only if it is YADE's default, given as
    YADE's converter for the default's type would take it (a string, None or a complex number never
    stands for a number or a flag, nor a number for a string)."""
    expected = default(name)
    try:
        if isinstance(expected, bool):
            value = as_flag(name, value)
        elif isinstance(expected, int):
            value = as_integer(name, value)
        elif isinstance(expected, float):
            value = as_number(name, value)
        elif isinstance(expected, str) and not isinstance(value, str):
            raise TypeError(f"{name} must be a string, got {value!r}")
    except ValueError:  # NaN or inf: not the default either
        pass
    try:
        same = bool(value == expected)
    except (TypeError, ValueError):
        same = False
    if not same:
        raise NotImplementedError(
            f"pfv.FlowEngine does not support YADE FlowEngine attribute '{name}' yet "
            f"(only its default value {expected!r} is accepted)"
        )


def unsupported_method(name: str) -> NotImplementedError:
    """The error for a YADE FlowEngine method PFV does not implement."""
    return NotImplementedError(f"pfv.FlowEngine does not support YADE FlowEngine method '{name}' yet")


def unknown_attribute(name: str, setting: bool) -> AttributeError:
    """The error for a name neither PFV nor YADE's FlowEngine has (`setting`: on assignment)."""
    if setting:
        return AttributeError(f"pfv.FlowEngine has no attribute '{name}' (and neither has YADE's FlowEngine)")
    return AttributeError(f"pfv.FlowEngine has no attribute '{name}'")


def solver_of_use_solver(value: int) -> str:
    """The core's solver name for YADE's useSolver number."""
    value = as_integer("useSolver", value)
    if value not in _SOLVER_OF_USE_SOLVER:
        raise ValueError(
            "useSolver must be 0 (Gauss-Seidel), 1 (preconditioned CG, PFV) or 3 (CHOLMOD, as solver='auto'), "
            f"got {value}"
        )
    return _SOLVER_OF_USE_SOLVER[value]


def use_solver_of(solver: str) -> int:
    """YADE's useSolver number for the core's solver name."""
    return _USE_SOLVER_OF[solver]


def _six(name: str, value: Any, kinds: tuple[type, ...], what: str, each: str) -> list[Any]:
    """The six items of `value`, each an instance of `kinds`, else TypeError naming `name`.
    Strict as YADE's own converters are: no truthiness of strings or None, no truncation."""
    if isinstance(value, (str, bytes)) or not isinstance(value, Iterable):
        raise TypeError(
            f"{name} must be a sequence of 6 {what} (xmin, xmax, ymin, ymax, zmin, zmax), " f"got {value!r}"
        )
    items = list(value)
    if len(items) != 6:
        raise ValueError(f"{name} needs 6 values (xmin, xmax, ymin, ymax, zmin, zmax), got {len(items)}")
    for w, item in enumerate(items):
        if not isinstance(item, kinds) or isinstance(item, (str, bytes)):
            raise TypeError(f"{name}[{w}] must be {each}, got {item!r}")
    return items


def as_bool6(name: str, value: Iterable[Any]) -> list[bool]:
    """Six flags, one per wall (xmin, xmax, ymin, ymax, zmin, zmax): bools or integers."""
    return [bool(v) for v in _six(name, value, (numbers.Integral, np.bool_), "flags", "a bool")]


def as_flag(name: str, value: Any) -> bool:
    """A flag: a bool or an integer (YADE's converters take both), not a string or None."""
    if not isinstance(value, (numbers.Integral, np.bool_)):
        raise TypeError(f"{name} must be a bool, got {value!r}")
    return bool(value)


def as_float6(name: str, value: Iterable[Any]) -> list[float]:
    """Six finite numbers, one per wall (xmin, xmax, ymin, ymax, zmin, zmax)."""
    items = [float(v) for v in _six(name, value, (numbers.Real,), "numbers", "a number")]
    for w, v in enumerate(items):
        if not math.isfinite(v):
            raise ValueError(f"{name}[{w}] must be finite, got {v!r}")
    return items


def as_wall_ids(value: Iterable[Any]) -> list[int]:
    """Six body ids, one per wall (xmin, xmax, ymin, ymax, zmin, zmax): Python or numpy integers, not floats
    or bools."""
    items = _six("wallIds", value, (numbers.Integral,), "body ids", "an integer body id")
    return [as_index(f"wallIds[{w}]", v) for w, v in enumerate(items)]


def as_point(name: str, value: Any) -> tuple[float, float, float]:
    """A finite point (x, y, z) of numbers (as_number: no strings)."""
    try:
        items = None if isinstance(value, (str, bytes)) else list(value)  # Vector3 iterates by index
    except TypeError:
        items = None
    if items is None or not all(is_number(v) for v in items):
        raise TypeError(f"{name} must be a point (x, y, z) of numbers, got {value!r}")
    point = tuple(float(v) for v in items)
    if len(point) != 3 or not all(math.isfinite(v) for v in point):
        raise ValueError(f"{name} must be a finite point (x, y, z), got {value!r}")
    return point


def as_setting(name: str, value: Any, current: Any) -> Any:
    """`value` checked for the core setting behind YADE attribute `name`, whose current value
    `current` gives the type: a flag (bool or integer), an integer, or a finite number. The core
    checks the ranges, and the strings a string setting takes; this names the attribute when the
    type is wrong."""
    if isinstance(current, bool):
        return as_flag(name, value)
    if isinstance(current, int):
        return as_integer(name, value)
    if isinstance(current, float):
        return as_number(name, value)
    return value


def is_number(value: Any) -> bool:
    """A real number as YADE's float converter takes it (int, bool, float), or a numpy real scalar."""
    return isinstance(value, (numbers.Real, np.bool_)) and not isinstance(value, (str, bytes))


def as_number(name: str, value: Any) -> float:
    """A finite float: a Python int, bool or float as YADE's converter takes them, or a numpy real scalar
    (YADE's refuses those but numpy.float64); a string, None, a complex number or a sequence raises
    TypeError, NaN and inf ValueError."""
    if not is_number(value):
        raise TypeError(f"{name} must be a number, got {value!r}")
    value = float(value)
    if not math.isfinite(value):
        raise ValueError(f"{name} must be finite, got {value!r}")
    return value


def as_positive(name: str, value: Any) -> float:
    """A positive finite float."""
    value = as_number(name, value)
    if value <= 0:
        raise ValueError(f"{name} must be positive, got {value!r}")
    return value


# The range of a C int: the core's integer settings.
INT_MIN, INT_MAX = -(2**31), 2**31 - 1


def as_integer(name: str, value: Any, low: int = INT_MIN, high: int = INT_MAX) -> int:
    """An integer in [low, high]: a Python or numpy integer (a bool, a float or a string is refused:
    YADE's converter takes a bool for an integer, PFV does not)."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Integral):
        raise TypeError(f"{name} must be an integer, got {value!r}")
    value = int(value)
    if not low <= value <= high:
        raise ValueError(f"{name} must be in [{low}, {high}], got {value}")
    return value


def as_index(name: str, value: Any) -> int:
    """An integer index: a Python or numpy integer (a bool or a float is refused)."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Integral):
        raise TypeError(f"{name} must be an integer, got {value!r}")
    return int(value)


def as_numbers(name: str, value: Any) -> list[float]:
    """A sequence of finite numbers."""
    if isinstance(value, (str, bytes)) or not isinstance(value, Sequence | np.ndarray):
        raise TypeError(f"{name} must be a sequence of numbers, got {value!r}")
    return [as_number(f"{name}[{i}]", v) for i, v in enumerate(value)]


def runner_attributes(runner: type, engine: type) -> frozenset[str]:
    """The data attributes of YADE's PyRunner (`runner`) that an engine subclass (`engine`) keeps as a PyRunner does:
    those it does not define itself."""
    return frozenset(
        a for a in dir(runner) if not a.startswith("_") and not callable(getattr(runner, a)) and a not in vars(engine)
    )


# The PyRunner attributes of an engine's schedule, which YADE saves and restores with the scene (an engine rebuilt
# after O.load takes them from the restored PyRunner).
RUNNER_SCHEDULE = (
    "iterPeriod",
    "virtPeriod",
    "realPeriod",
    "nDo",
    "initRun",
    "firstIterRun",
    "iterLast",
    "virtLast",
    "realLast",
    "nDone",
    "dead",
    "ignoreErrors",
    "updateGlobals",
)
