"""Bad input to the time-dependent boundary pressures (waveAction, set_boundary_pressure, pfv.waves):
each refusal is a Python exception naming the attribute or parameter, and leaves the scene usable.

    yade-double -n -x tests/yade/waves/test_wave_input.py        (exit 0 = pass)

Also: a scene without a load never calls into it (no evaluation, a zero pressure_field stage), a
failed step leaves the engine's results as they were, O.saveTmp / O.loadTmp keep waveAction and
its two values, and the load is evaluated once per step with background remeshes while the main
thread queries the engine during O.run().
"""
import math
import warnings

import numpy as np

from pfv_testing import robustness as rb
from pfv_testing.robustness import expect_error
from yade import O  # noqa: E402
from pfv import FlowEngine, waves  # noqa: E402

warnings.simplefilter("ignore")
NAN = float("nan")

# The permeameter along y (pressure 1 on ymin, 0 on ymax): the load goes on ymax.
flow = rb.fresh()
rb.run(1)
rb.check(
    "no load: the field is never evaluated",
    flow.core.field_evaluations == 0 and flow.core.step_times()["pressure_field"] == 0.0,
)
q_ref = flow.getBoundaryFlux(2)
p_ref = np.array(flow.core.pressure())


def step():
    """One step outside O.run: the step's own exception (inside O.run YADE reports any error of an
    engine as RuntimeError "PyRunner error" with the message)."""
    flow.emulateAction()


def unchanged(what):
    rb.check(
        f"{what}: the last results are kept",
        np.array_equal(np.array(flow.core.pressure()), p_ref) and flow.getBoundaryFlux(2) == q_ref,
    )


# 1. set_boundary_pressure: wall and callable.
expect_error("wall as a string", TypeError, "wall", lambda: flow.set_boundary_pressure("ymax", lambda *a: 0.0))
expect_error("wall as a float", TypeError, "wall", lambda: flow.set_boundary_pressure(3.0, lambda *a: 0.0))
expect_error("wall 6", ValueError, "0..5", lambda: flow.set_boundary_pressure(6, lambda *a: 0.0))
expect_error("wall -1", ValueError, "0..5", lambda: flow.set_boundary_pressure(-1, lambda *a: 0.0))
expect_error("a number, not a callable", TypeError, "callable", lambda: flow.set_boundary_pressure(3, 5.0))
expect_error("None, not a callable", TypeError, "callable", lambda: flow.set_boundary_pressure(3, None))
rb.check("refused loads are not kept", flow.boundary_pressure is None and flow.core.pressure_field_wall == -1)

# 2. Callables that return the wrong thing: refused at the step, naming the load, results kept.
n_top = int((np.asarray(flow.core.cell_sources()) == flow.ymax).sum())  # the Dirichlet cells of ymax
bad = [
    ("wrong length", ValueError, f"shape ({n_top},)", lambda x, y, z, t: np.zeros(3)),
    ("two-dimensional", ValueError, "one pressure per cell", lambda x, y, z, t: np.zeros((len(x), 2))),
    ("NaN", ValueError, "not finite", lambda x, y, z, t: np.where(x > 0.5, NAN, 0.0)),
    ("infinite", ValueError, "not finite", lambda x, y, z, t: np.full(len(x), math.inf)),
    ("strings", TypeError, "must return numbers", lambda x, y, z, t: ["a"] * len(x)),
    ("None", TypeError, "must return numbers", lambda x, y, z, t: None),
    # What numpy would convert: a number as a string, bools as 0 and 1, complex numbers without their
    # imaginary part.
    ("a number as a string", TypeError, "must return numbers", lambda x, y, z, t: "5.0"),
    ("numbers as strings", TypeError, "must return numbers", lambda x, y, z, t: ["5.0"] * len(x)),
    ("a bool", TypeError, "must return numbers", lambda x, y, z, t: True),
    ("bools", TypeError, "must return numbers", lambda x, y, z, t: x > 0.5),
    ("a complex number", TypeError, "must return numbers", lambda x, y, z, t: 5.0 + 0j),
    ("complex numbers", TypeError, "must return numbers", lambda x, y, z, t: x + 0j),
]
for what, kind, fragment, function in bad:
    flow.set_boundary_pressure(flow.ymax, function)
    expect_error(f"load returning {what}", kind, fragment, step)
    expect_error(f"load returning {what}: names it", kind, "set_boundary_pressure(ymax)", step)
    expect_error(f"load returning {what}, in O.run", RuntimeError, fragment, rb.run)
    unchanged(f"load returning {what}")
flow.set_boundary_pressure(flow.ymax, lambda x: x)
expect_error("load of the wrong signature", TypeError, "argument", step)
flow.set_boundary_pressure(flow.ymax, lambda x, y, z, t: 1 / 0)
expect_error("load raising its own error", ZeroDivisionError, "division", step)
unchanged("load raising")
# A load that queries the engine would wait for the lock its own step holds: it raises instead.
flow.set_boundary_pressure(flow.ymax, lambda x, y, z, t: 0.0 * x + flow.getPorePressure((0.5, 0.5, 0.5)))
expect_error("load calling the engine (no hang)", RuntimeError, "inside its own step", step)
expect_error("load calling the engine, in O.run (no hang)", RuntimeError, "inside its own step", rb.run)
unchanged("load calling the engine")
flow.set_boundary_pressure(flow.xmax, lambda x, y, z, t: 0.0 * x)
expect_error("load on an impermeable wall", ValueError, "bndCondIsPressure[1]", step)
flow.clear_boundary_pressure()
rb.run(1)
rb.check("usable once the load is cleared", flow.getBoundaryFlux(2) == q_ref)
flow.set_boundary_pressure(flow.ymax, lambda x, y, z, t: 0.0)  # a number: broadcast
rb.run(1)
rb.check("a load returning a number holds everywhere", abs(flow.getBoundaryFlux(2) - q_ref) <= 1e-12 * abs(q_ref))

with warnings.catch_warnings(record=True) as caught:
    warnings.simplefilter("always")
    O.saveTmp("function")
rb.check(
    "O.saveTmp with a function set warns that it is not saved",
    any("set_boundary_pressure is not saved" in str(w.message) for w in caught),
)

# 3. waveAction and its values.
expect_error(
    "waveAction while a function is set",
    ValueError,
    "clear_boundary_pressure",
    lambda: setattr(flow, "waveAction", True),
)
flow.clear_boundary_pressure()
expect_error("waveAction = 'yes'", TypeError, "waveAction", lambda: setattr(flow, "waveAction", "yes"))
expect_error("waveAction = None", TypeError, "waveAction", lambda: setattr(flow, "waveAction", None))
expect_error("sineMagnitude = NaN", ValueError, "sineMagnitude", lambda: setattr(flow, "sineMagnitude", NAN))
expect_error("sineMagnitude = '1'", TypeError, "sineMagnitude", lambda: setattr(flow, "sineMagnitude", "1"))
expect_error("sineAverage = inf", ValueError, "sineAverage", lambda: setattr(flow, "sineAverage", math.inf))
flow.waveAction = True
expect_error(
    "set_boundary_pressure while waveAction is on",
    ValueError,
    "waveAction",
    lambda: flow.set_boundary_pressure(flow.ymax, lambda *a: 0.0),
)
flow.bndCondIsPressure = [False, False, True, False, False, False]
expect_error("waveAction with ymax impermeable", ValueError, "bndCondIsPressure[3]", step)
flow.bndCondIsPressure = [False, False, True, True, False, False]
flow.sineAverage, flow.sineMagnitude = 0.25, 0.5
rb.run(1)
top = np.nonzero(np.asarray(flow.core.cell_sources()) == flow.ymax)[0].tolist()
deviation = max(abs(flow.getCellPressure(c) - (0.25 + 0.5 * math.cos(math.pi * flow.getCellCenter(c)[0]))) for c in top)
rb.check("waveAction: the top cells hold YADE's formula at their own x", deviation <= 1e-14, f"({deviation:.2g})")
O.saveTmp("wave")
O.loadTmp("wave")
loaded = [e for e in O.engines if isinstance(e, FlowEngine)][0]
rb.check(
    "O.saveTmp / O.loadTmp keep waveAction and its values",
    (loaded.waveAction, loaded.sineAverage, loaded.sineMagnitude) == (True, 0.25, 0.5),
)
flow = loaded
flow.waveAction = False
rb.run(1)
rb.check(
    "waveAction off: bndCondValue again",
    flow.getBoundaryFlux(2) == q_ref or abs(flow.getBoundaryFlux(2) - q_ref) <= 1e-12 * abs(q_ref),
)

# 4. A background remesh (multithread) and queries from the main thread while O.run() steps.
flow = rb.fresh(multithread=True, meshUpdateInterval=4)
rb.run(1)
wave = waves.StandingWave(0.5, period=30 * O.dt, length=1.0, mean=0.25)
flow.set_boundary_pressure(flow.ymax, wave)
meshes, evaluations = flow.core.remesh_count, flow.core.field_evaluations
for _ in range(12):
    rb.run(1)
    flow.core.wait_for_remesh()  # adopted at the next step, whatever the machine's speed
rb.check(
    "background remeshes: one evaluation per step",
    flow.core.field_evaluations - evaluations == 12 and flow.core.remesh_count >= meshes + 2,
    f"({flow.core.field_evaluations - evaluations} evaluations, {flow.core.remesh_count - meshes} remeshes)",
)
evaluations = flow.core.field_evaluations
O.run(16)
queries = 0
while O.running:
    flow.getPorePressure((0.5, 0.5, 0.5))
    queries += 1
O.wait()
rb.check(
    "queries during O.run(): no deadlock, one evaluation per step",
    flow.core.field_evaluations - evaluations == 16,
    f"({queries} queries)",
)
t = O.time - O.dt
top = np.nonzero(np.asarray(flow.core.cell_sources()) == flow.ymax)[0].tolist()
deviation = max(abs(flow.getCellPressure(c) - float(wave(np.array(flow.getCellCenter(c)[0]), 0, 0, t))) for c in top)
rb.check("background remeshes: the top holds the load of the last step", deviation <= 1e-14, f"({deviation:.2g})")

# 5. The profiles' parameters.
expect_error("HalfWave length = -1", ValueError, "length", lambda: waves.HalfWave(amplitude=1, length=-1))
expect_error("HalfWave length = 0", ValueError, "length", lambda: waves.HalfWave(amplitude=1, length=0))
expect_error("HalfWave rate = NaN", ValueError, "rate", lambda: waves.HalfWave(rate=NAN))
expect_error("HalfWave amplitude = '1'", TypeError, "amplitude", lambda: waves.HalfWave(amplitude="1"))
expect_error("StandingWave period = -1", ValueError, "period", lambda: waves.StandingWave(1.0, period=-1))
expect_error("StandingWave period = 0", ValueError, "period", lambda: waves.StandingWave(1.0, period=0))
expect_error("StandingWave period = inf", ValueError, "period", lambda: waves.StandingWave(1.0, period=math.inf))
expect_error("StandingWave amplitude = None", TypeError, "amplitude", lambda: waves.StandingWave(None, period=1))
expect_error("StandingWave origin = True", TypeError, "origin", lambda: waves.StandingWave(1, period=1, origin=True))

rb.report("wave input")
