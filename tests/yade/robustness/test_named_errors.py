"""Errors a user can act on: YADE body ids and setting names, never the engine's internal indices;
numpy scalars wherever Python's ints and floats are taken.

    yade-double -n -x tests/yade/robustness/test_named_errors.py        (exit 0 = pass)

1. Every message of the C++ core that names a vertex (a sphere or a wall by its place in the
   engine's arrays) must say "sphere k" or "wall w", the forms pfv.FlowEngine turns into YADE's body
   ids: read off the sources, so that a new message cannot name a vertex.
2. Steps that fail on values out of the physical range (a fluid_density whose buoyancy overflows,
   an imposed flux whose pressures do) name the setting or the YADE body (#id) and the place, and
   no internal index; the engine then steps as before.
3. Every method that takes a body id, a cell id, a wall, a condition index or a number gives the
   same answer for numpy integers and floats (np.int64, np.int32, np.uint16, np.float64,
   np.float32) as for Python's, and refuses a float, a string or a bool where an index belongs
   (TypeError) instead of truncating or parsing it.
"""
import os
import re
import warnings

import numpy as np

from pfv_testing import paths
from pfv_testing import robustness as rb
from yade import O  # noqa: E402
from yade.wrapper import NewtonIntegrator  # noqa: E402

warnings.simplefilter("ignore")

# -- 1. the core's messages name spheres and walls, not vertices --------------------------------------
# A string literal ending in "vertex " / "vertices " (or "row ", "index ") followed by a number.
INTERNAL = re.compile(r'"[^"\n]*\b(vertex|vertices|row|node)\s*"\s*\+\s*std::to_string')
found = []
sources = 0
for folder in ("pkg/pfv", "lib"):
    for root, _, files in os.walk(os.path.join(paths.REPO, folder)):
        for name in files:
            if name.endswith((".cpp", ".hpp")):
                sources += 1
                with open(os.path.join(root, name)) as f:
                    text = f.read()
                found += [f"{name}: {m.group(0)}" for m in INTERNAL.finditer(text)]
rb.check(f"no message of the {sources} C++ sources names an internal vertex or row", not found, "; ".join(found))


# -- 2. failed steps name the setting or the body -------------------------------------------------------
def bare_index(message):
    """An internal index in a message: "vertex 3", "sphere 3" without YADE's '#', "row 3"."""
    return re.search(r"\b(vertex|vertices|row|node) \d|\bspheres? \d", message)


def fails_named(what, fragments, action):
    """`action` (a step) raises an error naming all `fragments` and no internal index."""
    try:
        action()
    except Exception as error:  # noqa: BLE001
        message = str(error)
        missing = [f for f in fragments if f not in message]
        rb.check(
            f"{what}: names {', '.join(fragments)}, no internal index",
            not missing and not bare_index(message),
            f"({type(error).__name__}: {message.splitlines()[-1][:200]})",
        )
        return
    rb.fail(f"{what}: no error raised")


def step():
    flow.updateTriangulation = True
    rb.run(1)


flow = rb.fresh()
rb.run(1)
q_ref = flow.getBoundaryFlux(2)
first_sphere = min(b.id for b in O.bodies if b.id not in flow.wallIds)
newton = [e for e in O.engines if isinstance(e, NewtonIntegrator)][0]
newton.gravity = (0, -9.81, 0)  # buoyancy acts with the NewtonIntegrator's gravity
# (what, change, undo, fragments the message must hold)
failures = [
    (
        "fluid_density = 1e308",
        lambda: setattr(flow, "fluid_density", 1e308),
        lambda: setattr(flow, "fluid_density", 0.0),
        ["fluid_density", f"sphere #{first_sphere}"],
    ),
    (
        "an imposed flux of 1e308",
        lambda: flow.imposeFlux((0.5, 0.5, 0.5), 1e308),
        flow.clearImposedFlux,
        ["non-finite pore pressure", " at (", "imposed fluxes"],
    ),
]
for what, change, undo, fragments in failures:
    change()
    fails_named(what, fragments, step)
    undo()
flow.fluid_density = 0.0
newton.gravity = (0, 0, 0)
step()
rb.check("the engine steps as before", abs(flow.getBoundaryFlux(2) - q_ref) <= 1e-9 * abs(q_ref))

# -- 3. numpy scalars as ids, indices and numbers ----------------------------------------------------------
cell, sphere, wall_body = 3, first_sphere + 4, flow.wallIds[2]
condition = flow.imposePressure(tuple(flow.getCellCenter(cell)), 0.25)
step()
INT = "i"  # an argument given as numpy integers
FLOAT = "f"  # an argument given as numpy floats
queries = [
    ("getCellPressure", [(cell, INT)]),
    ("getCellCenter", [(cell, INT)]),
    ("getCellBarycenter", [(cell, INT)]),
    ("getVertices", [(cell, INT)]),
    ("getNeighbors", [(cell, INT)]),
    ("isCellNeighbor", [(cell, INT), (flow.getNeighbors(cell)[0], INT)]),
    ("getConductivity", [(cell, INT), (1, INT)]),
    ("getDiffusionCoeff", [(cell, INT), (1, INT)]),
    ("surfaceSolidThroatInPore", [(cell, INT), (2, INT)]),
    ("getCellInvVoidVolume", [(cell, INT)]),
    ("getCellFluxFromId", [(cell, INT)]),
    ("getCellPImposed", [(cell, INT)]),
    ("getCellFlux", [(condition, INT)]),
    ("getIncidentCells", [(sphere, INT)]),
    ("fluidForce", [(sphere, INT)]),
    ("shearLubForce", [(sphere, INT)]),
    ("avFlVelOnSph", [(sphere, INT)]),
    ("volume", [(sphere, INT)]),
    ("getBoundaryFlux", [(wall_body, INT)]),
    ("getBoundaryFluidArea", [(wall_body, INT)]),
    ("getBoundaryVel", [(wall_body, INT)]),
    ("getBoundaryVolume", [(wall_body, INT), (1e-3, FLOAT)]),
    ("averageSlicePressure", [(0.5, FLOAT), (1, INT)]),
    ("getPorePressure", [((0.5, 0.25, 0.5), FLOAT)]),
    ("getCellVelocity", [((0.5, 0.25, 0.5), FLOAT)]),
    ("getCell", [(0.5, FLOAT), (0.25, FLOAT), (0.5, FLOAT)]),
    ("getCellVolume", [((0.5, 0.25, 0.5), FLOAT)]),
]
INT_TYPES = (np.int64, np.int32, np.uint16, np.intp)
FLOAT_TYPES = (np.float64, np.float32)


def as_numpy(value, kind, numpy_type):
    if isinstance(value, tuple):
        return tuple(numpy_type(v) for v in value)
    return numpy_type(value)


def numpy_calls(method, args):
    """(description, numpy args, Python args giving the same value) for each numpy type of each argument."""
    for position, (value, kind) in enumerate(args):
        for numpy_type in INT_TYPES if kind == INT else FLOAT_TYPES:
            given = [v for v, _ in args]
            given[position] = as_numpy(value, kind, numpy_type)
            plain = list(given)  # what Python's types make of the same value (float32 rounds)
            plain[position] = (
                tuple(float(v) for v in given[position])
                if isinstance(value, tuple)
                else (int(given[position]) if kind == INT else float(given[position]))
            )
            yield f"{method}(... {numpy_type.__name__} ...)", given, plain


def equal(a, b):
    return repr(a) == repr(b)


def refused_indices(method, args):
    """A float of the same value, its string or a bool in place of each integer argument: TypeError."""
    problems = []
    for position, (value, kind) in enumerate(args):
        if kind != INT:
            continue
        for bad in (float(value), str(value), bool(value)):
            given = [v for v, _ in args]
            given[position] = bad
            try:
                getattr(flow, method)(*given)
                problems.append(f"{bad!r} taken")
            except TypeError:
                pass
            except Exception as error:  # noqa: BLE001
                problems.append(f"{bad!r}: {type(error).__name__}: {error}")
    return problems


calls = refusals = 0
for method, args in queries:
    problems = refused_indices(method, args)
    refusals += 3 * sum(kind == INT for _, kind in args)
    rb.check(f"{method} refuses a float, a string or a bool as an index", not problems, "; ".join(problems[:3]))
    problems = []
    for what, given, plain in numpy_calls(method, args):
        calls += 1
        try:
            got, expected = getattr(flow, method)(*given), getattr(flow, method)(*plain)
            if not equal(got, expected):
                problems.append(f"{what}: {got!r} vs {expected!r}")
        except Exception as error:  # noqa: BLE001
            problems.append(f"{what}: {type(error).__name__}: {error}")
    rb.check(f"{method} takes numpy scalars as Python's", not problems, "; ".join(problems[:3]))

# The methods that change conditions, each with numpy arguments and then undone.
changes = [
    ("setCellPImposed", lambda t: flow.setCellPImposed(t(cell), np.bool_(True)), lambda: flow.getCellPImposed(cell)),
    ("setCellPressure", lambda t: flow.setCellPressure(t(cell), np.float32(0.5)), lambda: flow.getCellPressure(cell)),
    ("blockCell", lambda t: flow.blockCell(t(cell), np.bool_(False)), lambda: flow.getConductivity(cell, 0)),
    ("setImposedPressure", lambda t: flow.setImposedPressure(t(condition), np.float64(0.125)), lambda: None),
    ("imposePressureFromId", lambda t: flow.imposePressureFromId(t(cell), np.float32(0.5)), lambda: None),
    ("setBoundaryNormal", lambda t: flow.setBoundaryNormal(t(2), np.array([0.0, 1.0, 0.0])), lambda: None),
    ("set_boundary_pressure", lambda t: flow.set_boundary_pressure(t(3), lambda x, y, z, time: 0.0 * x), None),
]
for name, change, _ in changes:
    problems = []
    for numpy_type in INT_TYPES:
        calls += 1
        try:
            change(numpy_type)
        except Exception as error:  # noqa: BLE001
            problems.append(f"{numpy_type.__name__}: {type(error).__name__}: {error}")
    rb.check(f"{name} takes numpy integers", not problems, "; ".join(problems[:3]))
rb.check("set_boundary_pressure's wall is a Python int again", type(flow.boundary_pressure[0]) is int)
flow.clear_boundary_pressure()
print(
    f"{len(queries)} queries and {len(changes)} changes, {calls} calls with numpy scalars, "
    f"{refusals} indices of the wrong type refused"
)
rb.report("named-errors")
