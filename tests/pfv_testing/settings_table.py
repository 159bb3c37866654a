"""The tables of settings, shared by the suites that walk through them: what a change of each rebuilds
(tests/data/settings_invalidation.csv), and what kind of value each takes and which values it refuses
(tests/data/settings_validation.csv)."""
import ast
import csv
import os

import numpy as np

from pfv_testing import paths

TABLE = os.path.join(paths.TEST_DATA, "settings_invalidation.csv")


def rows():
    """The table's rows as dicts (lines starting with # are comments)."""
    with open(TABLE) as f:
        return list(csv.DictReader(line for line in f if not line.startswith("#")))


def change(target, name, value):
    """Set attribute `name` to `value`, or call method `name` with the tuple `value`."""
    member = getattr(target, name)
    if callable(member):
        member(*value)
    else:
        setattr(target, name, value)


# -- the settings' validation (tests/data/settings_validation.csv) ------------------------------------
VALIDATION_TABLE = os.path.join(paths.TEST_DATA, "settings_validation.csv")
NAN, INF = float("nan"), float("inf")

# The bad values of each kind of setting, with the exception each raises: a wrong type TypeError,
# a value of the right type that cannot be (NaN, inf, a sequence of the wrong length) ValueError. A
# bool is a number as YADE's converters take it (True is 1.0), but no integer: PFV refuses that.
_SEQUENCE_TYPES = [None, "abcdef", 3, 1 + 0j]
BAD_VALUES = {
    "flag": [(v, TypeError) for v in ("no", "True", "", None, 1.5, NAN, 1 + 0j, [True], np.float64(1.0))],
    "integer": [(v, TypeError) for v in ("3", None, 1.5, NAN, INF, 1 + 0j, [3], True, np.float64(3.0), np.bool_(True))]
    + [(2**70, ValueError)],
    "number": [(v, TypeError) for v in ("1.0", "nan", None, 1 + 0j, [1.0], np.array([1.0]), b"1")]
    + [(v, ValueError) for v in (NAN, INF, -INF, np.float64(NAN), np.float32(INF))],
    "choice": [(v, TypeError) for v in (None, 3, 1.5, True, ["auto"], b"auto")],
    "bool6": [(v, TypeError) for v in _SEQUENCE_TYPES + [[1, 0, "x", 0, 0, 0], [None] * 6, [1.5] * 6]]
    + [([1] * 5, ValueError), ([1] * 7, ValueError)],
    "float6": [(v, TypeError) for v in _SEQUENCE_TYPES + [[0, 0, "1", 0, 0, 0], [1 + 0j] * 6, [None] * 6]]
    + [(v, ValueError) for v in ([NAN] * 6, [0.0] * 5 + [INF], [1.0] * 5)],
    "ids6": [(v, TypeError) for v in _SEQUENCE_TYPES + [[0, 1, 2, 3, 4, 5.0], [0, 1, 2, 3, 4, "5"], [True] * 6]]
    + [([0] * 5, ValueError)],
    "ids": [(v, TypeError) for v in (None, "abc", 3, [1.5], ["1"], [True], [None])],
    "numbers": [(v, TypeError) for v in (None, "abc", 3.0, [1.0, "2"], [1 + 0j], [None])]
    + [(v, ValueError) for v in ([NAN], [0.0, INF])],
    "vectors6": [(v, TypeError) for v in (None, "abcdef", 3, [(0, 0, "1")] * 6, [None] * 6)]
    + [(v, ValueError) for v in ([(0, 0, 0)] * 5, [(NAN, 0, 0)] * 6, [(0, 0)] * 6)],
    "text": [(v, TypeError) for v in (None, 3, b"x", ["x"])],
    "point": [(v, TypeError) for v in (None, "abc", 3.0, (1, 2, "3"), (1 + 0j, 0, 0))]
    + [(v, ValueError) for v in ((1, 2), (1, 2, NAN), (INF, 0, 0))],
    "profile": [(v, TypeError) for v in (None, "abc", (3, 0, [0.0, "1"], [0, 1]), (3.0, 0, [0, 1], [0, 1]))]
    + [((3, 0, [0.0, NAN], [0.0, 1.0]), ValueError)],
    # YADE's own attributes (PyRunner's), refused by YADE's converters (a bool takes None as False).
    "runner_str": [(v, TypeError) for v in (None, 3, 1.5)],
    "runner_bool": [(v, TypeError) for v in ("no", 1.5, 1 + 0j, [True])],
    "runner_int": [(v, TypeError) for v in ("3", None, 1.5, 1 + 0j, [3])],
    "runner_float": [(v, TypeError) for v in ("1", None, 1 + 0j, [1.0])],
}


def validation_rows():
    """The rows of settings_validation.csv as dicts, out_of_range parsed and range_error an exception class."""
    with open(VALIDATION_TABLE) as f:
        rows = list(csv.DictReader(line for line in f if not line.startswith("#")))
    errors = {"ValueError": ValueError, "SyntaxError": SyntaxError}
    for row in rows:
        row["out_of_range"] = ast.literal_eval(row["out_of_range"])
        row["range_error"] = errors[row["range_error"]]
    return rows


def bad_values(row):
    """(value, exception) of every bad value of a row: those of its kind, then those out of its range."""
    return BAD_VALUES[row["kind"]] + [(v, row["range_error"]) for v in row["out_of_range"]]


def numpy_values(kind, current):
    """The current value of a setting of `kind` as numpy gives it (numpy scalars, arrays), which the
    setting must take as it takes Python's; [] for YADE's own attributes (YADE refuses numpy scalars
    but numpy.float64)."""
    if kind == "flag":
        return [np.bool_(current)]
    if kind == "integer":
        return [np.int64(current), np.int32(current)]
    if kind == "number":
        return (
            [np.float64(current), np.float32(current), np.int64(current)]
            if current == int(current)
            else [
                np.float64(current),
                np.float32(current),
            ]
        )
    if kind in ("choice", "text"):
        return [np.str_(current)]
    if kind in ("bool6", "float6", "numbers", "vectors6", "point"):
        return [np.array(current, dtype=float if kind != "bool6" else bool)]
    if kind in ("ids6", "ids"):
        return [np.array(current, dtype=np.int64), [np.int32(v) for v in current]]
    if kind == "profile":
        wall, axis, positions, pressures = current
        return [(np.int64(wall), np.int64(axis), np.array(positions, dtype=float), np.array(pressures, dtype=float))]
    return []
