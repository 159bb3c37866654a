"""The optional viscous shear force (viscousShear, thesis 6.29-6.30) through YADE.

    yade-double -n -x tests/yade/flow/test_viscous_shear.py        (exit 0 = pass, 1 = fail)

Scene: the shipped 1000-sphere dense packing, spheres free, no gravity, impermeable walls but a drained top; every
sphere starts with the simple-shear velocity v = gamma_dot * y * e_x.

Checks
1. FlowEngine(viscousShear=True) is accepted and runs.
2. Two identical runs, shear on and off: the positions agree after one step (the first coupled step has no velocity
   yet, so no shear), and on the second step fluidForce(id) - shearLubForce(id) (on) = fluidForce(id) (off), and
   O.forces.f(id) differs by shearLubForce(id): the shear reaches YADE with the fluid force.
3. The shear forces sum to zero over spheres and walls (each pair acts with +F and -F).
4. The lower half of the packing is dragged forward (+x), the upper half held back.
5. Thesis claim 30 (section 6.3.5): with water (mu = 1e-3 Pa.s) the shear term changes the motion negligibly. Here
   under gravity with a drained top over 500 steps: the largest position difference between the runs with and
   without shear is below 1e-3 of the largest displacement (printed).
"""
from pfv_testing import checks, scenes
from yade import O  # noqa: E402
from yade.minieigenHP import Vector3  # noqa: E402
from pfv import FlowEngine  # noqa: E402


def scene(shear, viscosity=1.0, gamma_dot=0.05, gravity=False):
    info = scenes.build_permeameter(num=1000, frozen=False)
    flow = FlowEngine(label="flow", viscousShear=shear)
    scenes.configure_flow(flow, axis=1, dp=0.0, viscosity=viscosity)
    flow.bndCondIsPressure = [False, False, False, True, False, False]  # drained top only
    scenes.insert_flow(flow)
    if gravity:
        O.engines[-1].gravity = (0, -9.81, 0)
    for i in info["spheres"]:
        b = O.bodies[i]
        b.state.vel = (gamma_dot * b.state.pos[1], 0, 0)
    return info["spheres"], flow


def positions(ids):
    return [Vector3(O.bodies[i].state.pos) for i in ids]


# 1-4: the bridge.
ids, flow = scene(True)
checks.check("viscousShear=True accepted", flow.viscousShear is True)
O.run(1, True)
pos_on = positions(ids)  # where the second step evaluates the fluid
O.run(1, True)
fluid_on = [flow.fluidForce(i) for i in ids]
shear_on = [flow.shearLubForce(i) for i in ids]
walls_on = [flow.shearLubForce(w) for w in range(6)]
total_on = [Vector3(O.forces.f(i)) for i in ids]
ids_off, flow_off = scene(False)
O.run(1, True)
pos_off = positions(ids_off)
O.run(1, True)
fluid_off = [flow_off.fluidForce(i) for i in ids_off]
total_off = [Vector3(O.forces.f(i)) for i in ids_off]
checks.check(
    "identical positions after the first step (no velocity yet: no shear)",
    max((a - b).norm() for a, b in zip(pos_on, pos_off)) == 0.0,
)
scale = max(f.norm() for f in fluid_off)
shear_scale = max(f.norm() for f in shear_on)
print(f"     largest fluid force {scale:.4g} N, largest shear force {shear_scale:.4g} N (mu = 1 Pa.s)")
checks.check("the shear force is not zero", shear_scale > 0)
checks.check(
    "fluidForce includes shearLubForce",
    max((a - s - b).norm() for a, s, b in zip(fluid_on, shear_on, fluid_off)) <= 1e-9 * scale,
)
checks.check(
    "the shear force reaches O.forces",
    max((a - s - b).norm() for a, s, b in zip(total_on, shear_on, total_off)) <= 1e-9 * scale,
)
total = sum(shear_on, Vector3.Zero) + sum(walls_on, Vector3.Zero)
checks.check(f"shear forces sum to zero ({total.norm():.2e})", total.norm() <= 1e-12 * sum(f.norm() for f in shear_on))
lower = sum(s[0] for s, p in zip(shear_on, pos_on) if p[1] < 0.5)
upper = sum(s[0] for s, p in zip(shear_on, pos_on) if p[1] >= 0.5)
checks.check(
    f"lower half dragged forward ({lower:.4g} N), upper half held back ({upper:.4g} N)", lower > 0 and upper < 0
)
flow_off.viscousShear = True  # switching on mid-run: the next step remeshes and adds the term
O.run(1, True)
checks.check("switched on mid-run", max(flow_off.shearLubForce(i).norm() for i in ids_off) > 0)

# 5: water.
runs = []
for shear in (False, True):
    ids, flow = scene(shear, viscosity=1e-3, gamma_dot=0.0, gravity=True)
    start = positions(ids)
    O.run(500, True)
    runs.append((start, positions(ids)))
moved = max((b - a).norm() for a, b in zip(*runs[0]))
diff = max((a - b).norm() for a, b in zip(runs[0][1], runs[1][1]))
print(f"     water, 500 steps: largest displacement {moved:.4g} m, largest difference with/without shear {diff:.4g} m")
checks.check("with water the shear term is negligible (thesis claim 30)", moved > 0 and diff <= 1e-3 * moved)

checks.report("viscous shear")
