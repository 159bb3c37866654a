"""Immersed granular deposition (thesis section 4.5, claim 20): a loose cloud of grains (n = 0.61,
not touching) settles under gravity in a closed box drained at the top. While the grains are in
suspension the fluid carries their whole submerged weight, so the excess-pressure gradient between
consecutive sensors equals the critical gradient i_c (0.624 for n = 0.61, rho_s/rho_f = 2.6); as
the bed forms from the bottom up, the contacts take the weight over and the gradient falls to 0,
lowest sensors first.

    yade-double -n -x tests/yade/waves/test_deposition.py [--plot=FILE.png]      (exit 0 = pass)

The scene is scaled down from the thesis' (5000 grains of 0.06 m in 2 x 1.5 x 0.75 m, mu = 100
Pa.s) to about 1000 grains of 0.01 m and mu = 0.15 Pa.s, so that the cloud settles in about a
second of simulated time; the claim is dimensionless (i / i_c) and holds at any scale where the
grains reach their settling velocity quickly (relaxation time ~0.02 s here). Checks:
  - once the grains have reached their settling velocity and before they collide: the fluid force
    on the grains less their buoyancy within 3 % of their submerged weight; the gradients (mean over
    5 verticals, the levels above the first) within 10 % of i_c and the excess pressure at the bottom
    sensor within 10 % of the submerged weight above it per unit area (point sensors read the
    pressure of the cell they lie in: pore-scale noise);
  - the gradient falls below i_c / 2 level after level from the bottom up (two level pairs falling within one
    smoothing window of each other count as falling together);
  - at the end every gradient is below 0.1 i_c and the bed's effective stress sigma'_yy (YADE's
    per-particle stress, thesis 2.18) at mid-depth carries the submerged weight above it within 15 %.
Buoyancy is PFV's fluid_density; the engine solves the excess pressure. Measured: fluid share
0.988, gradient ratio 0.935, bottom sensor 0.946, half-decay times 0.057, 0.524, 0.513, 0.599, 0.747 s
from the lowest level pair up, bed porosity 0.466, sigma'_yy at mid-depth 1.03 x the weight above.
"""
import builtins
import math
import sys
import warnings

import numpy as np

from pfv_testing import robustness as rb
from yade import O, plot, utils  # noqa: E402
from yade.wrapper import (
    Bo1_Box_Aabb,
    Bo1_Sphere_Aabb,
    ForceResetter,
    FrictMat,
    Ig2_Box_Sphere_ScGeom,  # noqa: E402
    Ig2_Sphere_Sphere_ScGeom,
    InsertionSortCollider,
    InteractionLoop,
    Ip2_FrictMat_FrictMat_FrictPhys,
    Law2_ScGeom_FrictPhys_CundallStrack,
    NewtonIntegrator,
    PyRunner,
)
from pfv import FlowEngine, diagnostics  # noqa: E402

warnings.simplefilter("ignore", category=UserWarning)
RHO_S, RHO_F, GRAVITY = 2600.0, 1000.0, 9.81
RADIUS, N0 = 0.005, 0.61
CELLS = (7, 20, 7)  # lattice of the cloud: x, y (vertical), z
VISCOSITY = 0.15
T_END = 1.8
RECORD_EVERY = 100  # steps
EARLY_END = 0.08  # s: the end of the collision-free settling


def build_cloud(seed=3):
    """Spheres on a jittered cubic lattice whose spacing gives porosity N0 in the box: not touching."""
    spacing = RADIUS * (4.0 * math.pi / 3.0 / (1.0 - N0)) ** (1.0 / 3.0)
    box = np.array(CELLS, float) * spacing
    O.reset()
    O.materials.append(FrictMat(young=5e6, poisson=0.5, frictionAngle=math.radians(30), density=RHO_S, label="grains"))
    O.materials.append(FrictMat(young=5e6, poisson=0.5, frictionAngle=0, density=0, label="walls"))
    O.bodies.append(utils.aabbWalls([(0, 0, 0), tuple(box)], thickness=0, material="walls"))
    rng = np.random.default_rng(seed)
    slack = 0.25 * (spacing - 2 * RADIUS)
    for i in range(CELLS[0]):
        for j in range(CELLS[1]):
            for k in range(CELLS[2]):
                centre = (np.array([i, j, k]) + 0.5) * spacing + rng.uniform(-slack, slack, 3)
                O.bodies.append(utils.sphere(tuple(centre), RADIUS, material="grains"))
    return box


def main():
    box = build_cloud()
    flow = FlowEngine(
        label="flow",
        viscosity=VISCOSITY,
        fluid_density=RHO_F,
        meshUpdateInterval=50,
        bndCondIsPressure=[0, 0, 0, 1, 0, 0],
        bndCondValue=[0] * 6,
        boundaryUseMaxMin=[0] * 6,
    )
    area = box[0] * box[2]
    # Sensors over the lower half of the cloud: the bed grows through them (the clear fluid that
    # appears at the top as the cloud's surface comes down does not reach them).
    grid = diagnostics.SensorGrid.in_box((0, 0, 0), (box[0], 0.55 * box[1], box[2]), verticals=5, levels=6)
    monitor = diagnostics.Monitor(
        flow, grid, N0, RHO_S, RHO_F, area, bottom=0.0, t_end=T_END, report_every=40, g=GRAVITY
    )
    O.engines = [
        ForceResetter(),
        InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Box_Aabb()]),
        InteractionLoop(
            [Ig2_Sphere_Sphere_ScGeom(), Ig2_Box_Sphere_ScGeom()],
            [Ip2_FrictMat_FrictMat_FrictPhys()],
            [Law2_ScGeom_FrictPhys_CundallStrack()],
        ),
        flow,
        NewtonIntegrator(damping=0.0, gravity=(0, -GRAVITY, 0)),
        PyRunner(command="monitor(); drag()", iterPeriod=RECORD_EVERY),
    ]
    carried = []  # mean over the grains between sensors 2 and 6 of (fluid force - buoyancy) / submerged weight

    def drag():
        volume = 4.0 / 3.0 * math.pi * RADIUS**3
        band = [b.id for b in O.bodies if b.id >= 6 and grid.heights[1] < b.state.pos[1] < grid.heights[5]]
        carried.append(
            np.mean([flow.fluidForce(i)[1] - RHO_F * GRAVITY * volume for i in band])
            / ((RHO_S - RHO_F) * GRAVITY * volume)
        )

    builtins.monitor, builtins.drag = monitor, drag  # PyRunner commands run in YADE's namespace
    O.dt = 0.5 * utils.PWaveTimeStep()
    plot.reset()
    O.run(int(T_END / O.dt), True)

    t = np.array(plot.data["t"])
    ratio = np.array(
        [[np.mean([plot.data[f"r_{v}_{k}"][n] for v in range(1, 6)]) for k in range(1, 6)] for n in range(len(t))]
    )  # (records, 5 level pairs)
    p_bottom = np.array([np.mean([plot.data[f"p_{v}_1"][n] for v in range(1, 6)]) for n in range(len(t))])
    gamma_prime = diagnostics.buoyant_unit_weight(N0, RHO_S, RHO_F, GRAVITY)

    # Point sensors read one cell's pressure each: smooth over 5 records (0.03 s) against the pore-scale noise.
    kernel = np.ones(5) / 5
    ratio = np.column_stack([np.convolve(ratio[:, k], kernel, mode="same") for k in range(ratio.shape[1])])
    # Suspension: after the grains' relaxation (under 0.01 s), before they collide (the cloud is
    # dense: grains a fraction of a radius apart; once the bed forms, collisions travel up through
    # the cloud and contacts take part of the weight).
    early = (t > 0.02) & (t < EARLY_END)
    fluid_share = np.mean(np.array(carried)[early])
    rb.check(
        "suspension: the fluid carries the grains' submerged weight",
        abs(fluid_share - 1) < 0.03,
        f"((fluid force - buoyancy) / submerged weight {fluid_share:.4f} over t = 0.02..{EARLY_END} s)",
    )
    suspended = ratio[early][:, 1:].mean()
    rb.check(
        "suspension: grad H / i_c of the levels above the first is about 1 (claim 20)",
        abs(suspended - 1) < 0.10,
        f"(mean {suspended:.3f} over t = 0.02..{EARLY_END} s)",
    )
    weight_above = gamma_prime * (np.array(plot.data["top"])[early] - grid.heights[0])  # the cloud's surface falls
    p_early = np.mean(p_bottom[early] / weight_above)
    rb.check(
        "suspension: the bottom sensor's excess pressure is the submerged weight above it",
        abs(p_early - 1) < 0.10,
        f"(ratio {p_early:.3f})",
    )

    # Bottom-up decay: the first record at which each level pair falls below i_c / 2, after the start.
    start = np.argmax(t > 0.02)
    drop = []
    for k in range(5):
        below = np.flatnonzero(ratio[start:, k] < 0.5)
        drop.append(t[start + below[0]] if len(below) else math.inf)
    # Two level pairs whose smoothed gradients cross i_c / 2 within one smoothing window of each other fall
    # together as far as this signal can tell: their order is below its resolution.
    window = t[min(len(kernel), len(t) - 1)] - t[0]
    rb.check(
        "the gradient falls level after level from the bottom up",
        all(np.isfinite(drop)) and all(a <= b + window for a, b in zip(drop, drop[1:])) and drop[0] < drop[-1],
        "(t_1/2 per level: " + ", ".join(f"{d:.3f}" for d in drop) + f" s; ties within the {window:.3f} s "
        "smoothing window allowed)",
    )
    final = ratio[-1]
    rb.check(
        "at the end the bed carries its weight: every gradient below 0.1 i_c",
        np.all(np.abs(final) < 0.1),
        "(" + ", ".join(f"{r:.3f}" for r in final) + ")",
    )

    ids, pos, rad, _, _ = diagnostics.sphere_arrays(O.bodies)
    top = diagnostics.top_height(pos, rad, 0.99)
    n_bed = diagnostics.porosity_below(rad, area, top, 0.0)
    stresses = utils.bodyStressTensors()
    heights, sigma = diagnostics.effective_stress_profile(stresses, ids, pos, rad, 0.0, top, 6, area)
    mid = 2  # the third of six slices: away from the bottom wall and the loose surface
    volume = 4.0 / 3.0 * math.pi * rad**3
    carried = (RHO_S - RHO_F) * GRAVITY * volume[pos[:, 1] > heights[mid]].sum() / area
    rb.check(
        "the bed's effective stress at mid-depth carries the submerged weight above it",
        abs(sigma[mid] / carried - 1) < 0.15,
        f"({sigma[mid]:.1f} Pa vs {carried:.1f} Pa; bed n = {n_bed:.3f})",
    )
    print(
        f"deposition: bed porosity {n_bed:.3f} (cloud {N0}), top {top:.4f} m of {box[1]:.4f} m; "
        f"{O.iter} steps, {len(t)} records"
    )
    for arg in sys.argv[1:]:
        if arg.startswith("--plot="):
            diagnostics.save_plots(plot.data, arg.split("=", 1)[1])
    rb.report("deposition")


main()
