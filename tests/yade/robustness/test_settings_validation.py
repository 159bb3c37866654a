"""Every public setting of pfv.FlowEngine and of its core (pfv.Engine) is checked at assignment.

    yade-double -n -x tests/yade/robustness/test_settings_validation.py        (exit 0 = pass)

The settings come from the engine itself (its writable properties, the YADE attributes it maps onto
its core, YADE's PyRunner attributes; the core's writable properties) and must each have a row in
tests/data/settings_validation.csv: a new setting without one fails here. Each is set to every bad
value of its kind and to those out of its range (pfv_testing.settings_table): the refusal must be of
the expected exception, name the setting, and leave the value as it was; the numpy scalars and
arrays of its current value must be taken as Python's. Every other attribute of YADE's FlowEngine
is accepted at YADE's default only: its bad values (a string, None, a complex number, a list, NaN)
must be refused. After all this the engine steps to the flux of the untouched scene.
"""
import math
import warnings

from pfv_testing import robustness as rb
from pfv_testing import settings_table
from yade.wrapper import PyRunner  # noqa: E402
import pfv  # noqa: E402
from pfv import FlowEngine, _attributes, _yade_api  # noqa: E402

warnings.simplefilter("ignore")


def writable_settings():
    """The public settings of pfv.FlowEngine (yade) and of pfv.Engine (core), read off the classes."""
    own = {
        name
        for klass in FlowEngine.__mro__
        if klass.__module__.startswith("pfv")
        for name, member in vars(klass).items()
        if isinstance(member, property) and member.fset is not None
    }
    runner = {a for a in dir(PyRunner) if not a.startswith("_") and not callable(getattr(PyRunner, a))} - own
    runner = {a for a in runner if a not in vars(FlowEngine)}
    core = {
        name
        for name in dir(pfv.Engine)
        if not name.startswith("_") and isinstance(getattr(pfv.Engine, name), property)
        if getattr(pfv.Engine, name).fset is not None
    }
    return {"yade": own | set(_attributes.CORE_NAME) | runner, "core": core}


def same(a, b):
    """Equal values (lists of numbers or Vector3, strings, numbers)."""
    try:
        return repr(a) == repr(b) or a == b
    except Exception:  # noqa: BLE001
        return False


def refusals(target, row):
    """Set the setting of `row` on `target` to each of its bad values; returns the failures."""
    name, problems = row["name"], []
    cases = settings_table.bad_values(row)
    for value, kind in cases:
        before = getattr(target, name)
        try:
            setattr(target, name, value)
            problems.append(f"{value!r} taken (reads {getattr(target, name)!r})")
        except kind as error:
            if name not in str(error):
                problems.append(f"{value!r}: {type(error).__name__} does not name it: {error}")
        except Exception as error:  # noqa: BLE001
            problems.append(f"{value!r}: {type(error).__name__} instead of {kind.__name__}: {str(error)[:150]}")
        after = getattr(target, name)
        if not same(after, before):
            problems.append(f"{value!r} refused but the value changed from {before!r} to {after!r}")
            setattr(target, name, before)
    return len(cases), problems


def numpy_takes(target, row):
    """The numpy forms of the current value of `row`'s setting are taken as the value itself."""
    name, problems = row["name"], []
    before = getattr(target, name)
    values = settings_table.numpy_values(row["kind"], before)
    for value in values:
        try:
            setattr(target, name, value)
            expected = before
            if type(value).__name__ == "float32":
                expected = float(value)
            if not same(getattr(target, name), expected) and name != "updateTriangulation":
                problems.append(f"{value!r} ({type(value).__name__}) reads back {getattr(target, name)!r}")
        except Exception as error:  # noqa: BLE001
            problems.append(f"{value!r} ({type(value).__name__}) refused: {type(error).__name__}: {error}")
        setattr(target, name, before)
    return len(values), problems


flow = rb.fresh()
rb.run(1)
q_ref = flow.getBoundaryFlux(2)
rows = settings_table.validation_rows()
listed = {target: {r["name"] for r in rows if r["target"] == target} for target in ("yade", "core")}
found = writable_settings()
for target in ("yade", "core"):
    rb.check(
        f"every public setting of {target} has a row",
        not found[target] - listed[target],
        f"(missing: {sorted(found[target] - listed[target])})",
    )
    rb.check(
        f"every row of {target} is a public setting",
        not listed[target] - found[target],
        f"(not settings: {sorted(listed[target] - found[target])})",
    )

cases = numpy_cases = 0
for row in rows:
    target = flow if row["target"] == "yade" else flow.core
    label = f"{'pfv.FlowEngine' if row['target'] == 'yade' else 'pfv.Engine'}.{row['name']}"
    n, problems = refusals(target, row)
    cases += n
    rb.check(f"{label} ({row['kind']}): {n} bad values refused, value kept", not problems, "; ".join(problems[:4]))
    n, problems = numpy_takes(target, row)
    numpy_cases += n
    if n:
        rb.check(f"{label}: numpy forms of its value taken", not problems, "; ".join(problems[:4]))

# A standalone core (no YADE scene) checks the same way.
core = pfv.Engine()
for value, kind in ((None, TypeError), ("0.5", TypeError), (math.nan, ValueError)):
    rb.expect_error(
        f"pfv.Engine().viscosity = {value!r}", kind, "viscosity", lambda v=value: setattr(core, "viscosity", v)
    )
rb.expect_error("pfv.Engine() misspelt setting", AttributeError, "viscosty", lambda: setattr(core, "viscosty", 1.0))

# The attributes of YADE's FlowEngine that PFV takes at YADE's default only.
read_only = {name for name in dir(FlowEngine) if isinstance(getattr(FlowEngine, name), property)} - found["yade"]
defaults_only = sorted(set(_yade_api.ATTRIBUTES) - listed["yade"] - read_only)
default_cases, problems = 0, []
for name in defaults_only:
    default = _attributes.default(name)
    bad = [None, "x", 1 + 0j, [default], math.nan, str(default)]
    if isinstance(default, (int, float)) and not isinstance(default, bool):
        bad += [complex(default), str(default)]
    if isinstance(default, bool):
        bad += [float(default), complex(default), str(default)]
    for value in bad:
        default_cases += 1
        try:
            setattr(flow, name, value)
            problems.append(f"{name} = {value!r} taken")
        except (TypeError, NotImplementedError) as error:
            if name not in str(error):
                problems.append(f"{name} = {value!r}: the error does not name it: {error}")
        except Exception as error:  # noqa: BLE001
            problems.append(f"{name} = {value!r}: {type(error).__name__}: {error}")
        if not same(getattr(flow, name), default):
            problems.append(f"{name} reads {getattr(flow, name)!r} after {value!r}")
rb.check(
    f"{len(defaults_only)} YADE attributes taken at their default only: {default_cases} bad values refused",
    not problems,
    "; ".join(problems[:6]),
)

rb.run(1)
rb.check(
    "the engine steps as before the refusals",
    abs(flow.getBoundaryFlux(2) - q_ref) <= 1e-12 * abs(q_ref),
    f"(Qin {flow.getBoundaryFlux(2):.9g} vs {q_ref:.9g})",
)
print(
    f"{len(rows)} settings ({len(listed['yade'])} of pfv.FlowEngine, {len(listed['core'])} of pfv.Engine): "
    f"{cases} (setting, bad value) cases, {numpy_cases} numpy forms; {len(defaults_only)} YADE attributes at "
    f"their default only: {default_cases} cases"
)
rb.report("settings-validation")
