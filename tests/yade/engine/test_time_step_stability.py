"""Coupled time-step limit (thesis 4.15-4.22): dt_MV, the warning, the strict option, blow-up and stability.

    yade-double -n -x tests/yade/engine/test_time_step_stability.py        (exit 0 = pass, 1 = fail)

Scene: the shipped 1000-sphere dense packing (tests/yade/data, bit-identical everywhere), spheres free, no gravity,
drained top and impermeable other walls, a very viscous fluid (mu = 1000 Pa.s) so that dt_MV = pi rho d^2 / (1200 mu)
is ~55 times smaller than the DEM P-wave step: the viscous limit alone decides. Every sphere gets a small random
velocity (seeded) and the translational kinetic energy is followed step by step.

Checks
1. flow.viscous_time_step is pi rho d^2 / (1200 mu) at the smallest rho d^2 of the dynamic spheres and
   flow.critical_time_step = min(dt_MV, P-wave step).
2. O.dt = 1.5 dt_MV: the engine warns (TimeStepWarning, once) at the first coupled step, before the kinetic energy has
   grown, and then the kinetic energy grows without bound (x1e6 within 60 steps, or the run breaks down).
3. strict_time_step = True at 1.5 dt_MV: the step raises (ValueError from the engine, RuntimeError through O.run)
   naming the limit, O.iter does not advance, and nothing was warned.
4. Control: O.dt = 0.25 dt_MV is stable (over 300 steps the kinetic energy never exceeds twice its initial value
   and ends below it), so the scene and the criterion are sound.
5. After one coupled step the engine knows its collective viscous limit (Arnoldi on its linearised fluid
   operator, 2 / lambda_max of M^-1 V), which is below dt_MV on this dense packing (the thesis' 0.8 dt_MV blows up
   here within 20 steps), and collective_viscous_bound lies between 0.1 x and 1 x that limit. O.dt =
   time_step_safety * critical_time_step, the largest step the engine accepts silently, is stable by the same
   criterion, and no warning is given.
6. The collective limit is recomputed at every remesh (warm-started power iteration) where its certified
   bound (asked first, about one solve) cannot show O.dt safe; at 1e-4 dt_MV the bound suffices, no limit is
   computed. The packing compacted by 1 % (positions scaled about the centre, walls with them, relaxed without
   fluid) has a lower limit. A run at the step
   the engine accepted silently on the loose packing is moved onto the compacted one and remeshed: the engine warns
   once, at that step (it had been safe until then), and the run then blows up; with strict_time_step the remesh
   step raises; time_step_safety * critical_time_step of the compacted packing is stable without a warning.
"""
import math
import random
import warnings

from pfv_testing import checks, scenes
from yade import O, utils  # noqa: E402
from yade.wrapper import NewtonIntegrator, Sphere  # noqa: E402
from yade.minieigenHP import Vector3  # noqa: E402
from pfv import FlowEngine  # noqa: E402
from pfv.flow_engine import TimeStepWarning  # noqa: E402

MU = 1000.0
V0 = 1e-4  # m/s, initial random velocity scale (spheres of radius ~0.05 m)


_relaxed = []
COMPACTION = 0.99  # scale factor of the positions (walls included) about the centre of the box


def relax_and_save(name, what):
    """1000 damped steps without fluid, then at rest, saved as O.saveTmp(name)."""
    newton = [e for e in O.engines if isinstance(e, NewtonIntegrator)][0]
    newton.damping = 0.5
    O.run(1000, True)
    print("     %s relaxed without fluid: unbalanced force %.2g" % (what, utils.unbalancedForce()))
    newton.damping = 0.0
    for b in O.bodies:
        b.state.vel = Vector3(0, 0, 0)
        b.state.angVel = Vector3(0, 0, 0)
    O.saveTmp(name)


def build():
    """The packing relaxed once without fluid (a rebuilt packing starts with unbalanced contact forces that would
    keep feeding kinetic energy), then the flow engine and the random velocities."""
    if not _relaxed:
        scenes.build_permeameter(num=1000, frozen=False)
        O.dt = 0.8 * utils.PWaveTimeStep()
        relax_and_save("relaxed", "packing")
        # The same packing compacted: positions (walls included) scaled about the centre, relaxed again.
        centre = Vector3(0.5, 0.5, 0.5)
        for b in O.bodies:
            b.state.pos = centre + (b.state.pos - centre) * COMPACTION
        relax_and_save("compacted", "compacted packing")
        _relaxed.append(True)
    O.loadTmp("relaxed")
    flow = FlowEngine(label="flow")
    scenes.configure_flow(flow, axis=1, dp=0.0, viscosity=MU, meshUpdateInterval=1000)
    flow.bndCondIsPressure = [False, False, False, True, False, False]  # drained top only
    flow.bndCondValue = [0.0] * 6
    scenes.insert_flow(flow)
    random_velocities()
    return flow


def compact(flow):
    """Replace the scene by the compacted packing (at rest, its own contacts), keep the same flow engine and O.dt and
    have it remesh there; the jump is not a pore-volume change (no dV/dt term for it)."""
    dt = O.dt
    O.loadTmp("compacted")
    scenes.insert_flow(flow)
    O.dt = dt
    flow.updateTriangulation = True
    flow.core.reset_history()


def random_velocities():
    rng = random.Random(7)
    for b in O.bodies:
        if isinstance(b.shape, Sphere):
            b.state.vel = Vector3(rng.gauss(0, V0), rng.gauss(0, V0), rng.gauss(0, V0))


def kinetic():
    """Translational kinetic energy of the spheres (rotations are not damped by the fluid model)."""
    e = 0.0
    for b in O.bodies:
        if isinstance(b.shape, Sphere):
            v = b.state.vel
            e += 0.5 * b.state.mass * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
    return e


def run_steps(n, ke0, stop_ratio=None):
    """Step one at a time; returns (history of KE/KE0, warnings seen [(iter, message)], error text or None)."""
    hist, seen, error = [], [], None
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        for _ in range(n):
            try:
                O.step()
            except Exception as e:  # noqa: BLE001  (a broken-down run: spheres leave the box, NaN...)
                error = str(e).strip().splitlines()[-1][:160] if str(e).strip() else type(e).__name__
                break
            for w in caught[len(seen) :]:
                seen.append((O.iter, w))
            ke = kinetic()
            hist.append(ke / ke0 if math.isfinite(ke) else float("inf"))
            if stop_ratio is not None and hist[-1] > stop_ratio:
                break
    return hist, seen, error


# 1. dt_MV --------------------------------------------------------------------------------------------------------
flow = build()
rho_d2 = min(
    b.material.density * (2 * b.shape.radius) ** 2 for b in O.bodies if isinstance(b.shape, Sphere) and b.dynamic
)
dt_mv_formula = math.pi * rho_d2 / (1200 * MU)
dt_mv = flow.viscous_time_step
dt_dem = utils.PWaveTimeStep()
checks.check(
    "dt_MV = %.6g s = pi rho d^2 / (1200 mu) = %.6g s" % (dt_mv, dt_mv_formula), abs(dt_mv / dt_mv_formula - 1) < 1e-9
)
checks.check(
    "critical_time_step %.6g s = min(dt_MV, P-wave %.6g s); dt_DEM / dt_MV = %.1f"
    % (flow.critical_time_step, dt_dem, dt_dem / dt_mv),
    abs(flow.critical_time_step / min(dt_mv, dt_dem) - 1) < 1e-9,
)

# 2. 1.5 dt_MV: warned first, then blows up -----------------------------------------------------------------------
O.dt = 1.5 * dt_mv
ke0 = kinetic()
it0 = O.iter
hist, seen, error = run_steps(60, ke0, stop_ratio=1e12)
dt_warnings = [(i - it0, w) for i, w in seen if issubclass(w.category, TimeStepWarning)]
grown = [k for k, r in enumerate(hist, 1) if r > 10]
print(
    "     1.5 dt_MV: KE/KE0 after steps 1..%d: %s%s"
    % (len(hist), " ".join("%.3g" % r for r in hist[:25]), (" ... run stopped: " + error) if error else "")
)
checks.check("one TimeStepWarning at 1.5 dt_MV (got %d)" % len(dt_warnings), len(dt_warnings) == 1)
if dt_warnings:
    step_w, w = dt_warnings[0]
    checks.check("warned at coupled step %d (the first): %s" % (step_w, str(w.message)[:120]), step_w == 1)
    checks.check(
        "warned (step %d) before the kinetic energy grew tenfold (step %s)" % (step_w, grown[0] if grown else "never"),
        not grown or step_w < grown[0],
    )
blew = max(hist, default=0) > 1e6 or (error is not None and max(hist, default=0) > 10)
checks.check(
    "1.5 dt_MV blows up: max KE/KE0 = %.3g within %d steps%s"
    % (max(hist, default=0), len(hist), (" (then: %s)" % error) if error else ""),
    blew,
)

# 3. strict_time_step raises ---------------------------------------------------------------------------------------
flow = build()
flow.strict_time_step = True
O.dt = 1.5 * flow.viscous_time_step
it0 = O.iter
with warnings.catch_warnings(record=True) as caught:
    warnings.simplefilter("always")
    try:
        O.step()
        raised = None
    except RuntimeError as e:
        raised = str(e)
checks.check(
    "strict_time_step: the step raises naming the limit (%s)"
    % ((raised or "no error").strip().splitlines()[-1][:110] if raised else "no error"),
    raised is not None and "exceeds the coupled stability limit" in raised,
)
checks.check("strict_time_step: O.iter did not advance (%d -> %d)" % (it0, O.iter), O.iter == it0)
checks.check(
    "strict_time_step: raises instead of warning", not [w for w in caught if issubclass(w.category, TimeStepWarning)]
)
try:
    flow._time_step.check(O.dt)
    direct = None
except ValueError as e:
    direct = str(e)
checks.check("strict_time_step: the engine's check raises ValueError", direct is not None)
flow.strict_time_step = False


# 4. a small enough step is stable (control: the scene and the criterion are sound) --------------------------------
def stable_run(factor, label, flow=None):
    if flow is None:
        flow = build()
    else:
        random_velocities()
    O.dt = factor * flow.viscous_time_step
    ke0 = kinetic()
    hist, seen, error = run_steps(300, ke0, stop_ratio=1e12)
    print(
        "     %.3g dt_MV: KE/KE0 at steps 1, 10, 50, 100, 300: %s%s"
        % (
            factor,
            " ".join("%.3g" % hist[k - 1] for k in (1, 10, 50, 100, 300) if k <= len(hist)),
            (" ... run stopped: " + error) if error else "",
        )
    )
    ok = error is None and len(hist) == 300 and max(hist) < 2 and hist[-1] < 1
    checks.check(
        "%s: O.dt = %.3g dt_MV is stable (max KE/KE0 %.3g over %d steps, final %.3g)"
        % (label, factor, max(hist, default=float('nan')), len(hist), hist[-1] if hist else float('nan')),
        ok,
    )
    return ok, seen


stable_run(0.25, "control")

# 5. the largest step the engine accepts silently is stable ---------------------------------------------------------
# The engine's limit includes the collective viscous limit, known once the first mesh exists: take one tiny step first.
flow = build()
O.dt = 1e-3 * flow.viscous_time_step
O.step()
dt_collective = flow.collective_viscous_time_step
print(
    "     collective viscous limit 2 / lambda_max(M^-1 V) = %.4g s = %.3f dt_MV (Arnoldi on the engine's "
    "linearised fluid operator; the thesis' single-particle dt_MV is not a safe bound for collective modes)"
    % (dt_collective, dt_collective / dt_mv)
)
checks.check("the collective limit is below dt_MV on this dense packing", dt_collective < dt_mv)
bound = flow.collective_viscous_bound
checks.check(
    "collective_viscous_bound %.3g dt_MV: certified below the limit, within an order of magnitude of it"
    % (bound / dt_mv),
    0.1 * dt_collective < bound <= dt_collective,
)
factor = flow.time_step_safety * flow.critical_time_step / flow.viscous_time_step
ok, seen = stable_run(factor, "engine limit")
checks.check(
    "no TimeStepWarning at O.dt = time_step_safety * critical_time_step = %.3g dt_MV" % factor,
    not [w for w in seen if issubclass(w[1].category, TimeStepWarning)],
)

# 6. the limit follows the compaction: recomputed at the remesh, warned there ------------------------------------------
flow = build()
O.dt = 1e-4 * flow.viscous_time_step  # far below the limit: the guard's bound suffices, no limit computed
first_dt = O.dt
O.step()
loose = flow.collective_viscous_time_step
O.dt = flow.time_step_safety * flow.critical_time_step  # accepted silently on the loose packing (stable, check 5)
factor = O.dt / dt_mv
random_velocities()
hist, seen, error = run_steps(5, kinetic())
checks.check(
    "loose packing at %.3g dt_MV: no warning" % factor,
    not [w for w in seen if issubclass(w[1].category, TimeStepWarning)],
)
compact(flow)
random_velocities()
ke0 = kinetic()
it0 = O.iter
hist, seen, error = run_steps(100, ke0, stop_ratio=1e12)
records = flow.collective_viscous_history
history = [h for h in records if h["method"] != "bound"]  # the computations of the limit itself
dt_warnings = [(i - it0, w) for i, w in seen if issubclass(w.category, TimeStepWarning)]
print(
    "     collective limit: %s"
    % "; ".join(
        "%.3f dt_MV at iter %d (%d iterations, %s, %.1f ms)"
        % (h["limit"] / dt_mv, h["iter"], h["iterations"], "warm" if h["warm"] else "cold", 1e3 * h["seconds"])
        for h in history
    )
)
remesh = sum(flow.core.remesh_times().values())
print(
    "     last remesh %.1f ms; warm-started limit on the compacted packing %.1f ms (%.0f %% of it)"
    % (1e3 * remesh, 1e3 * history[-1]["seconds"], 100 * history[-1]["seconds"] / remesh)
)
# history[0]: the first mesh; history[1]: the remesh onto the compacted packing (a blown-up run may remesh again later)
checks.check(
    "the limit was recomputed (warm start) on the new mesh, at the remesh step",
    len(history) >= 2 and history[1]["warm"] and history[1]["iter"] == it0,
)
compacted = history[1]["limit"] if len(history) >= 2 else loose
# The guard asks the certified bound first: on the loose packing at 1e-4 dt_MV it sufficed (no limit computed by
# the guard at that step, only by the query after it), on the compacted one at the step near the limit it did not.
bounds = [h for h in records if h["method"] == "bound"]
checks.check(
    "the guard's order: bound on the first mesh (sufficed at 1e-4 dt_MV), the limit when queried; bound on the "
    "compacted mesh (not enough at %.3g dt_MV), then the limit (got %s)"
    % (factor, [(h["method"], h["iter"]) for h in records[:4]]),
    len(records) >= 4
    and records[0]["method"] == "bound"
    and records[1]["method"] == "arnoldi"
    and records[1]["iter"] == records[0]["iter"] + 1
    and first_dt <= flow.time_step_safety * records[0]["limit"]
    and records[2]["method"] == "bound"
    and records[3]["method"] == "power"
    and O.dt > 0.8 * records[2]["limit"],
)
checks.check(
    "each bound lies below the limit of its mesh (%s)"
    % "; ".join("%.3g <= %.3g dt_MV" % (b["limit"] / dt_mv, h["limit"] / dt_mv) for b, h in zip(bounds, history)),
    all(0 < b["limit"] <= h["limit"] for b, h in zip(bounds[:2], history[:2])),
)
checks.check(
    "compaction by %g %% lowers the collective limit from %.3f to %.3f dt_MV"
    % (100 * (1 - COMPACTION), loose / dt_mv, compacted / dt_mv),
    compacted < 0.85 * loose,
)
checks.check(
    "one TimeStepWarning, at the remesh step (got %s)" % [k for k, _ in dt_warnings],
    len(dt_warnings) == 1 and dt_warnings[0][0] == 1,
)
grown = [k for k, r in enumerate(hist, 1) if r > 10]
checks.check(
    "the compacted packing at %.3g dt_MV (%.2f x its limit) blows up: max KE/KE0 %.3g, after the warning"
    % (factor, O.dt / compacted, max(hist, default=0)),
    max(hist, default=0) > 1e6 and (not dt_warnings or not grown or dt_warnings[0][0] < grown[0]),
)

flow = build()
O.dt = 1e-3 * flow.viscous_time_step
O.step()
O.dt = flow.time_step_safety * flow.critical_time_step
O.step()
flow.strict_time_step = True
compact(flow)
it0 = O.iter
try:
    O.step()
    raised = None
except RuntimeError as e:
    raised = str(e)
checks.check(
    "strict_time_step: the remesh step on the compacted packing raises, O.iter unchanged",
    raised is not None and "collective viscous limit" in raised and O.iter == it0,
)

flow = build()
O.dt = 1e-3 * flow.viscous_time_step
O.step()
compact(flow)
O.step()
ok, seen = stable_run(flow.time_step_safety * flow.critical_time_step / dt_mv, "compacted, its engine limit", flow)
checks.check(
    "no TimeStepWarning at time_step_safety * critical_time_step of the compacted packing",
    not [w for w in seen if issubclass(w[1].category, TimeStepWarning)],
)

checks.report("time step stability")
