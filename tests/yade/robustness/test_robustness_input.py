"""Nothing silently wrong, and messages that name the problem: the abuse a careless user commits.

    yade-double -n -x tests/yade/robustness/test_robustness_input.py        (exit 0 = pass)

Each refused input names the attribute, body or point and leaves the scene usable (checked at
the end against the flux of the untouched scene). Scenes that change under a reused engine
(a new scene, a dead engine, spheres moving through the mesh) give the fresh engine's answer.
"""
import math
import warnings

import numpy as np

from pfv_testing import robustness as rb
from pfv_testing.robustness import expect_error
from yade import O, utils  # noqa: E402
from yade.minieigenHP import Vector3  # noqa: E402
from pfv import FlowEngine  # noqa: E402

warnings.simplefilter("ignore")
NAN = float("nan")

flow = rb.fresh()
expect_error("query before the first step", RuntimeError, "not run yet", lambda: flow.getPorePressure((0.5, 0.5, 0.5)))
expect_error("slice before the first step", RuntimeError, "not run yet", lambda: flow.averageSlicePressure(0.5))
rb.check("time-step query before the first step", flow.critical_time_step > 0)
rb.run(1)
q_ref = flow.getBoundaryFlux(2)

# 1. Imposed points: not finite or outside the pore space (now, and at the first step).
expect_error("imposePressure at NaN", ValueError, "finite point", lambda: flow.imposePressure((NAN, 0.5, 0.5), 1.0))
expect_error("imposePressure outside", ValueError, "no pore cell", lambda: flow.imposePressure((5, 5, 5), 1.0))
expect_error("imposePressure NaN value", ValueError, "finite", lambda: flow.imposePressure((0.5, 0.5, 0.5), NAN))
expect_error("imposeFlux outside", ValueError, "no pore cell", lambda: flow.imposeFlux((0.5, -1, 0.5), 1e-3))
expect_error("imposeFlux at a string", TypeError, "point", lambda: flow.imposeFlux("abc", 1e-3))
rb.check(
    "refused points are not kept",
    len(flow.core.bnd_is_pressure) == 6 and flow.nCells() > 0 and abs(flow.getBoundaryFlux(2) - q_ref) == 0,
)
before = FlowEngine()
rb.scenes.configure_flow(before, axis=1, dp=1.0)
before.imposePressure((5, 5, 5), 1.0)  # no mesh yet: refused at the first step
rb.scenes.insert_flow(before)
expect_error("imposePressure outside, before any mesh", RuntimeError, "imposed pressure 0 at (5, 5, 5)", rb.run)
before.clearImposedPressure()
rb.run(1)
rb.check("usable once the point is cleared", abs(before.getBoundaryFlux(2) - q_ref) <= 1e-12 * abs(q_ref))
flow = before

# 2. Solver settings that would run forever or not at all; values out of range or of the wrong type.
for value in (0.0, -1e-6, NAN):
    expect_error(f"tolerance = {value}", ValueError, "tolerance", lambda v=value: setattr(flow, "tolerance", v))
expect_error("maxKdivKmean = 0", ValueError, "maxKdivKmean", lambda: setattr(flow, "maxKdivKmean", 0.0))
expect_error("maxKdivKmean = NaN", ValueError, "maxKdivKmean", lambda: setattr(flow, "maxKdivKmean", NAN))
expect_error("minKdivKmean above max", ValueError, "maxKdivKmean", lambda: setattr(flow, "minKdivKmean", 1e3))
expect_error("pZero = NaN", ValueError, "pZero", lambda: setattr(flow, "pZero", NAN))
expect_error("relax = 2.5", ValueError, "relax", lambda: setattr(flow, "relax", 2.5))
expect_error("useSolver = 2", ValueError, "useSolver", lambda: setattr(flow, "useSolver", 2))
expect_error("ompThreads = 2**40", ValueError, "ompThreads", lambda: setattr(flow, "ompThreads", 2**40))
expect_error("ompThreads = 'many'", TypeError, "ompThreads", lambda: setattr(flow, "ompThreads", "many"))
expect_error("viscosity = 'abc'", TypeError, "viscosity", lambda: setattr(flow, "viscosity", "abc"))
expect_error(
    "meshUpdateInterval = 1.5", TypeError, "meshUpdateInterval", lambda: setattr(flow, "meshUpdateInterval", 1.5)
)
expect_error("slipBoundary = 'no'", TypeError, "slipBoundary", lambda: setattr(flow, "slipBoundary", "no"))
for name, value in (
    ("bndCondIsPressure", "abcdef"),
    ("bndCondIsPressure", [1, 0, "x", None, 0, 0]),
    ("boundaryUseMaxMin", "abcdef"),
    ("wallIds", [0, 1, 2, 3, 4, 5.7]),
    ("bndCondValue", [0, 0, "1", 0, 0, 0]),
    ("bndCondValue", None),
):
    expect_error(f"{name} = {value!r}", TypeError, name, lambda n=name, v=value: setattr(flow, n, v))
expect_error("bndCondValue with NaN", ValueError, "bndCondValue", lambda: setattr(flow, "bndCondValue", [NAN] * 6))
expect_error("bndCondIsPressure of 5", ValueError, "6 values", lambda: setattr(flow, "bndCondIsPressure", [1] * 5))
rb.check(
    "settings unchanged by the refusals",
    flow.tolerance == 1e-6
    and flow.maxKdivKmean == 100.0
    and flow.bndCondIsPressure == [False, False, True, True, False, False]
    and flow.wallIds == list(range(6)),
)

# An iterative solve stopped by its iteration cap says so.
gs = rb.fresh(useSolver=0)
gs.core.max_iterations = 3
with warnings.catch_warnings(record=True) as caught:
    warnings.simplefilter("always")
    rb.run(2)
capped = [w for w in caught if "not converged" in str(w.message)]
rb.check("an unconverged Gauss-Seidel solve warns, once", len(capped) == 1 and not gs.core.converged)
flow = rb.fresh()
rb.run(1)

# 3. Queries out of range.
expect_error("fluidForce(10**6)", ValueError, "not coupled", lambda: flow.fluidForce(10**6))
expect_error("getCellPressure(10**9)", IndexError, "no pore cell", lambda: flow.getCellPressure(10**9))
expect_error("getCellPressure(-1)", IndexError, "no pore cell", lambda: flow.getCellPressure(-1))
expect_error("getPorePressure outside", ValueError, "no pore cell", lambda: flow.getPorePressure((5, 5, 5)))
expect_error("getPorePressure at NaN", ValueError, "finite", lambda: flow.getPorePressure((NAN, 0, 0)))
expect_error("averageSlicePressure outside", ValueError, "outside", lambda: flow.averageSlicePressure(5.0))
expect_error("getBoundaryFlux(99)", ValueError, "not one of the boundaries", lambda: flow.getBoundaryFlux(99))

# 4. Bodies that cannot be walls, or spheres, as they are.
spheres = [b for b in O.bodies if b.id >= 6]
top = max(spheres, key=lambda b: b.state.pos[1])
flow.wallIds = [0, 1, 2, top.id, 4, 5]
expect_error("wallIds naming the topmost sphere", RuntimeError, f"wallIds[3] = {top.id} names a Sphere", rb.run)
flow.wallIds = list(range(6))
mass = O.bodies[70].state.mass
O.bodies[70].state.mass = math.inf
O.bodies[70].state.blockedDOFs = ""
flow.updateTriangulation = True
expect_error("infinite mass", RuntimeError, "sphere #70 has mass inf", rb.run)
O.bodies[70].state.mass = mass
O.bodies[70].state.blockedDOFs = "xyzXYZ"
flow.boundaryUseMaxMin = [True] * 6
good = tuple(O.bodies[60].state.pos)
O.bodies[60].state.pos = (good[0], 1e150, good[2])
expect_error("sphere sent to y = 1e150", RuntimeError, "placed by sphere #60", rb.run)
O.bodies[60].state.pos = good
flow.boundaryUseMaxMin = [False] * 6
rb.run(1)
rb.check(
    "usable after the refusals",
    abs(flow.getBoundaryFlux(2) - q_ref) <= 1e-12 * abs(q_ref),
    f"(Qin {flow.getBoundaryFlux(2):.9g} vs {q_ref:.9g})",
)

# 5. Scenes too small or empty: an error or an answer, never a crash.
for n in (1, 2, 4):
    O.reset()
    O.bodies.append(utils.aabbWalls([(0, 0, 0), (1, 1, 1)], thickness=0))
    for k in range(n):
        O.bodies.append(utils.sphere((0.2 + 0.6 * k / max(n - 1, 1), 0.5, 0.4 + 0.05 * k), 0.1))
    small = FlowEngine()
    rb.scenes.configure_flow(small, axis=1, dp=1.0)
    O.engines = [small]
    O.dt = 1e-5
    try:
        rb.run(1)
        rb.check(f"{n} spheres: a step", math.isfinite(small.getBoundaryFlux(2)))
    except RuntimeError as error:
        rb.check(f"{n} spheres: a named error", "pfv.FlowEngine" in str(error), str(error).splitlines()[-1][:100])
O.reset()
O.bodies.append(utils.aabbWalls([(0, 0, 0), (1, 1, 1)], thickness=0))
O.engines = [FlowEngine()]
O.dt = 1e-5
expect_error("walls only", RuntimeError, "no sphere to couple", rb.run)


# 6. A reused engine notices a new scene with as many bodies (O.reset, then another packing: the
# same centres with smaller spheres, which the old mesh knows nothing of).
def thinner():
    rb.scenes.build_permeameter(num=1000)
    for b in O.bodies:
        if b.id >= 6:
            b.shape.radius *= 0.9


flow = rb.fresh()
rb.run(2)
thinner()
rb.scenes.insert_flow(flow)
rb.run(1)
q_reused, f_reused = flow.getBoundaryFlux(2), max(abs(flow.fluidForce(i)[1]) for i in range(6, 1006))
thinner()
new = FlowEngine(label="flow")
rb.scenes.configure_flow(new, axis=1, dp=1.0)
rb.scenes.insert_flow(new)
rb.run(1)
q_fresh, f_fresh = new.getBoundaryFlux(2), max(abs(new.fluidForce(i)[1]) for i in range(6, 1006))
rb.check(
    "new scene, reused engine: the fresh engine's flux",
    abs(q_reused - q_fresh) <= 1e-12 * abs(q_fresh),
    f"({q_reused:.9g} vs {q_fresh:.9g})",
)
rb.check(
    "new scene, reused engine: no force spike",
    abs(f_reused - f_fresh) <= 1e-9 * f_fresh,
    f"(max |F_y| {f_reused:.4g} vs {f_fresh:.4g})",
)


# 7. A dead engine restarts its dV/dt history when it comes back (the top wall moving down: the
# pores lose volume at a steady rate).
flow = rb.fresh()
rates = []
for k in range(25):
    flow.dead = 3 <= k < 23
    O.bodies[3].state.pos = O.bodies[3].state.pos - Vector3(0, 1e-6, 0)
    rb.run(1)
    rates.append(flow.core.volume_rate_total())
rb.check("dead engine back: no dV/dt spanning the dead steps", rates[23] == 0.0, f"(sum dV/dt {rates[23]:.3g})")
rb.check(
    "dead engine back: then the one-step rate again",
    abs(rates[24] / rates[2] - 1) < 0.05,
    f"({rates[24]:.4g} vs {rates[2]:.4g} before)",
)

# 8. Spheres moving 0.6 radius per step with remeshing off: cells turned inside out run on with signed volumes
# (fluxes conserved) until 2 % of the volume is inside out; then the mesh is rebuilt, not trusted.
rng = np.random.default_rng(5)
flow = rb.fresh(meshUpdateInterval=10**6)
O.dt = 1e10  # dV/dt negligible: the flux is a property of the positions alone
rb.run(1)
ids = list(range(6, len(O.bodies)))
radius = np.array([O.bodies[i].shape.radius for i in ids])
ran_on_inverted = False  # a step ran on the old mesh with cells inside out
worst_balance = 0.0  # |Q_in + Q_out + sum dV/dt| / |Q_in| over the steps
with warnings.catch_warnings(record=True) as caught:
    warnings.simplefilter("always")
    for step in range(20):
        pos = np.array([tuple(O.bodies[i].state.pos) for i in ids])
        for k in range(len(ids)):  # each sphere 0.6 radius in a random direction, no centre inside another
            for attempt in range(20):
                move = rng.normal(size=3)
                trial = np.clip(pos[k] + 0.6 * radius[k] * move / np.linalg.norm(move), 0.02, 0.98)
                d = np.linalg.norm(pos - trial, axis=1)
                d[k] = np.inf
                if (d > 1.2 * np.maximum(radius, radius[k])).all():
                    pos[k] = trial
                    break
        for i, x in zip(ids, pos):
            O.bodies[i].state.pos = tuple(x)
        rb.run(1)
        q_in, q_out = flow.getBoundaryFlux(2), flow.getBoundaryFlux(3)
        worst_balance = max(worst_balance, abs(q_in + q_out + flow.core.volume_rate_total()) / abs(q_in))
        if flow.core.inversion_remeshes:
            break
        ran_on_inverted |= flow.core.inverted_cells > 0
q_moved = flow.getBoundaryFlux(2)
inverted_warnings = [w for w in caught if "turned inside out" in str(w.message)]
rb.check("cells turned inside out first run on with the old mesh", ran_on_inverted)
rb.check("conserving the flux on every step", worst_balance <= 1e-8, f"(worst {worst_balance:.2g})")
rb.check(
    "until 2 % of the volume inside out forces a remesh",
    flow.core.inversion_remeshes == 1,
    f"({flow.core.inversion_remeshes} forced remeshes in {step + 1} steps)",
)
rb.check("and one warning says so", len(inverted_warnings) == 1)
new = FlowEngine(label="flow")
rb.scenes.configure_flow(new, axis=1, dp=1.0)
rb.scenes.insert_flow(new)
rb.run(1)
rb.check(
    "the flux is that of a fresh mesh",
    abs(q_moved - new.getBoundaryFlux(2)) <= 1e-6 * abs(q_moved),
    f"({q_moved:.9g} vs fresh {new.getBoundaryFlux(2):.9g})",
)

rb.report("bad-input and silent-error")
