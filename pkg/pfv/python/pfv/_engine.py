"""``pfv.Engine``: the C++ engine (``pfv._core.Engine``) with its settings checked at assignment.

The core validates the range of every setting (``EngineSettings::validate``) and refuses a value
out of it with ValueError, keeping the previous one. The binding's converters are pybind11's,
looser than YADE's: a bool setting takes None as False, an integer setting given 2**40 raises a
TypeError that names neither the setting nor the value. This class checks the type first, by the
setting's current type (a flag, an integer in the range of a C int, a finite number) or, for the
settings of several values, by their own converter, and names the setting in every refusal. A
setting whose type has no converter here fails at import: a new setting cannot escape the check.
No YADE needed.
"""
from __future__ import annotations

from typing import Any, Callable

from . import _attributes as attributes
from . import _core


def _profile(name: str, value: Any) -> tuple[int, int, list[float], list[float]]:
    """(wall, axis, positions, pressures) of pressure_profile (the core checks their ranges)."""
    if isinstance(value, (str, bytes)) or not isinstance(value, (tuple, list)) or len(value) != 4:
        raise TypeError(f"{name} must be (wall, axis, positions, pressures), got {value!r}")
    wall, axis, positions, pressures = value
    return (
        attributes.as_index(f"{name} wall", wall),
        attributes.as_index(f"{name} axis", axis),
        attributes.as_numbers(f"{name} positions", positions),
        attributes.as_numbers(f"{name} pressures", pressures),
    )


def _scalar(current: Any) -> Callable[[str, Any], Any] | None:
    """The converter of a setting whose current value is `current`, by its type."""
    if isinstance(current, bool):
        return attributes.as_flag
    if isinstance(current, int):
        return attributes.as_integer
    if isinstance(current, float):
        return attributes.as_number
    if isinstance(current, str):  # one of a few names: the core lists them in its TypeError or ValueError
        return lambda name, value: value
    return None


# The settings of several values, each with its converter.
_COMPOSITE: dict[str, Callable[[str, Any], Any]] = {
    "bnd_is_pressure": attributes.as_bool6,
    "bnd_value": attributes.as_float6,
    "gravity": attributes.as_point,
    "pressure_profile": _profile,
}


def _converters() -> dict[str, Callable[[str, Any], Any]]:
    """Every writable property of the core with its converter."""
    probe = _core.Engine()
    found = {}
    for name in dir(_core.Engine):
        member = getattr(_core.Engine, name, None)
        if name.startswith("_") or not isinstance(member, property) or member.fset is None:
            continue
        convert = _COMPOSITE.get(name) or _scalar(getattr(probe, name))
        if convert is None:
            raise RuntimeError(f"pfv.Engine.{name}: no converter for a setting of type {type(getattr(probe, name))}")
        found[name] = convert
    return found


CONVERTERS = _converters()


class Engine(_core.Engine):
    """The C++ flow engine (module pfv._core) whose settings are checked at assignment: a wrong type
    raises TypeError, a value out of range ValueError, both naming the setting; the previous value
    stays."""

    __slots__ = ()

    def __setattr__(self, name: str, value: Any) -> None:
        convert = CONVERTERS.get(name)
        if convert is not None:
            value = convert(name, value)
        try:
            _core.Engine.__setattr__(self, name, value)
        except ValueError as error:
            message = str(error)
            raise ValueError(message if name in message else f"pfv.Engine.{name}: {message}") from None

    def assign(self, name: str, value: Any) -> None:
        """Set a setting already converted (pfv.FlowEngine's, which names its own attribute)."""
        _core.Engine.__setattr__(self, name, value)
