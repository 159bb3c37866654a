"""Fixed skeleton under the half-wave load on its top: pfv.FlowEngine against the analytic solution
of thesis eqs. (6.24)-(6.26), and against YADE's FlowEngine with waveAction on the same packing.

    yade-double -n -x tests/yade/waves/test_wave_halfwave.py        (exit 0 = pass)

The sample is the box 0 < x < L = 2, 0 < y < h = 1, 0 < z < 0.5 (L = 2h, as the thesis' 2-D check)
filled with static spheres on a jittered cubic lattice of n layers over h (spacing s = h / n, centres
moved by up to 0.03 s, radii 0.42 s +- 10 %, seed 1). The top (ymax) carries p = A (1 + cos(pi x / L))
(eq. 6.20, A = 1 Pa; YADE: sineAverage = sineMagnitude = A), the five other walls are impermeable
(slip walls). Laplace's equation then gives (6.24) p = A [1 + cosh(pi y / L) / cosh(pi h / L)
cos(pi x / L)] and (6.26) the Darcy velocity v = -Kd A (pi / L) sinh(pi y / L) / cosh(pi h / L)
cos(pi x / L), Kd measured by a permeameter along x on the same packing with the same engine.

Errors, relative to A (head) or to the largest interval flux (velocity):
* head_rms: RMS of p - (6.24) over the cells whose power centre lies inside the box (no imposed cell);
* head_probe: max |p - (6.24)| at 5 verticals x = (0.1 .. 0.9) L times 6 levels y = h k / 7 (getPorePressure);
* velocity: RMS over 7 intervals of x of (flux into the sample through the top there - W times the
  integral of v(x, h)), the flux being minus the sum of getCellFluxFromId over the top cells whose
  centre lies in the interval.

Measured (yade-double -j1, WAVE_SIZES=8,12,16,20 yade-double -n -x tests/yade/waves/test_wave_halfwave.py):

    layers  spheres  engine  head_rms  head_probe  velocity
       8       512   PFV     0.0149    0.0471      0.0515
       8       512   YADE    0.0448    0.0825      0.0630
      12      1728   PFV     0.0121    0.0514      0.0635
      12      1728   YADE    0.0324    0.0863      0.0847
      16      4096   PFV     0.0064    0.0387      0.0594
      16      4096   YADE    0.0325    0.0734      0.0907
      20      8000   PFV     0.0053    0.0175      0.0440
      20      8000   YADE    0.0349    0.0510      0.1197

PFV's errors fall with the grain size (pore-scale scatter, and the boundary layer of cells whose
thickness is the grain size); YADE's head error stays at about 0.03 A and its flux error grows: its
load is stepped over 30 bins of x, each at the cosine of the bin's lower edge (p = 54.9 where 50 is
exact in a measured case, /work/shared/yade-notes.md), a bias no refinement removes. The test runs
12 and 20 layers; its tolerances are 1.5 times PFV's figures there, PFV's head_rms must fall from
12 to 20 layers, and PFV must be no worse than YADE on every measure. Also checked, on 12 layers:
waveAction in PFV equals pfv.waves.HalfWave (same formula), a ramped amplitude and a standing wave
change the right-hand side only (system_builds and remesh_count unchanged, one evaluation per
step), the interior pressures follow the load linearly, and clearing the load restores bndCondValue.
"""
import math
import os
import time
import warnings

import numpy as np  # noqa: E402
from yade import O, utils  # noqa: E402
from yade.wrapper import FrictMat, ForceResetter, NewtonIntegrator  # noqa: E402
from yade.wrapper import FlowEngine as YadeFlowEngine  # noqa: E402
import pfv  # noqa: E402
from pfv import waves  # noqa: E402
from pfv_testing import checks  # noqa: E402

warnings.simplefilter("ignore")
L, H, W = 2.0, 1.0, 0.5
A = 1.0
SIZES = tuple(int(v) for v in os.environ.get('WAVE_SIZES', '12,20').split(','))  # layers over h
# 1.5 x PFV's measured errors (module docstring), per number of layers: head_rms, head_probe, velocity.
TOLERANCE = {
    8: (0.022, 0.071, 0.077),
    12: (0.018, 0.077, 0.095),
    16: (0.0096, 0.058, 0.089),
    20: (0.0080, 0.026, 0.066),
}


def build(per_height):
    """The box with its six walls (ids 0..5), then static spheres on a jittered cubic lattice of
    `per_height` layers (spacing s = h / per_height, centres moved by up to 0.03 s, radii 0.42 s +- 10 %,
    seed 1: no sphere touches another or a wall)."""
    s = H / per_height
    shape = (round(L / s), per_height, round(W / s))
    sites = np.stack(np.meshgrid(*[np.arange(n) for n in shape], indexing="ij"), axis=-1).reshape(-1, 3)
    rng = np.random.default_rng(1)
    centres = (sites + 0.5 + rng.uniform(-0.03, 0.03, size=sites.shape)) * s
    radii = 0.42 * s * (1 + rng.uniform(-0.1, 0.1, size=len(sites)))
    O.reset()
    O.materials.append(FrictMat(young=1e6, poisson=0.5, frictionAngle=0.5, density=2600, label="spheres"))
    O.bodies.append(utils.aabbWalls([(0, 0, 0), (L, H, W)], thickness=0))
    spheres = [utils.sphere(tuple(c), float(r), material="spheres") for c, r in zip(centres, radii)]
    for b in spheres:
        b.state.blockedDOFs = "xyzXYZ"
    O.bodies.append(spheres)
    O.engines = [ForceResetter(), NewtonIntegrator(damping=0)]
    O.dt = 1e-6
    return len(spheres)


def insert(flow):
    O.engines = [O.engines[0], flow, O.engines[-1]]


def configure(flow, pressure_walls, values):
    flow.wallIds = list(range(6))
    flow.boundaryUseMaxMin = [False] * 6
    flow.bndCondIsPressure = [w in pressure_walls for w in range(6)]
    flow.bndCondValue = values
    flow.useSolver = 3
    flow.viscosity = 1.0
    return flow


def head(x, y):
    return A * (1 + np.cosh(math.pi * y / L) / math.cosh(math.pi * H / L) * np.cos(math.pi * x / L))


def top_flux(x0, x1, kd):
    """Flux out through the top over x0 < x < x1: W times the integral of (6.26) at y = h."""
    return -kd * A * math.tanh(math.pi * H / L) * W * (math.sin(math.pi * x1 / L) - math.sin(math.pi * x0 / L))


def conductivity(kind):
    """Kd = Darcy velocity / pressure gradient of a permeameter along x on the current packing."""
    flow = configure(kind(), (0, 1), [1.0, 0, 0, 0, 0, 0])
    insert(flow)
    O.run(1, True)
    return abs(flow.getBoundaryFlux(1)) * L / (H * W * 1.0)


def errors(flow, kd):
    inside, head_sq, top = 0, 0.0, []
    for c in range(flow.nCells()):
        x = flow.getCellCenter(c)
        if flow.getCellPImposed(c):
            # What the cell sends into the sample: the flux in through the top there.
            top.append((x[0], -flow.getCellFluxFromId(c)))
        elif 0 < x[0] < L and 0 < x[1] < H and 0 < x[2] < W:
            inside += 1
            head_sq += (flow.getCellPressure(c) - head(x[0], x[1])) ** 2
    head_rms = math.sqrt(head_sq / inside) / A
    probes = [(L * a, H * b, W / 2) for a in (0.1, 0.3, 0.5, 0.7, 0.9) for b in np.arange(1, 7) / 7]
    head_probe = max(abs(flow.getPorePressure(p) - head(p[0], p[1])) for p in probes) / A
    top = np.array(top)
    # 7 intervals: none of their edges is an edge of YADE's 30 bins, across which its stepped load drives
    # large fluxes between neighbouring top cells (they cancel within an interval, not across its edge).
    nx = 7
    diffs, peak = [], 0.0
    for i in range(nx):
        x0, x1 = L * i / nx, L * (i + 1) / nx
        sel = (top[:, 0] >= x0) & (top[:, 0] < x1)
        if i == 0:
            sel |= top[:, 0] < 0  # centres of wall cells may lie beyond the side walls
        if i == nx - 1:
            sel |= top[:, 0] >= L
        exact = top_flux(x0, x1, kd)
        peak = max(peak, abs(exact))
        diffs.append(top[sel, 1].sum() - exact)
    velocity = math.sqrt(np.mean(np.square(diffs))) / peak
    return head_rms, head_probe, velocity


def wave_engine(kind):
    flow = configure(kind(), (3,), [0.0] * 6)
    if kind is YadeFlowEngine:
        flow.waveAction = True
        flow.sineAverage = A
        flow.sineMagnitude = A
    else:
        flow.set_boundary_pressure(flow.ymax, waves.HalfWave(amplitude=A, length=L))
    insert(flow)
    O.run(1, True)
    return flow


def run_size(num):
    start = time.time()
    n = build(num)
    measured = {}
    for name, kind in (("YADE", YadeFlowEngine), ("PFV", pfv.FlowEngine)):
        kd = conductivity(kind)
        flow = wave_engine(kind)
        measured[name] = errors(flow, kd)
        print(
            f"{n} spheres, {name}: Kd = {kd:.5g}, head_rms = {measured[name][0]:.4f}, head_probe = "
            f"{measured[name][1]:.4f}, velocity = {measured[name][2]:.4f}"
        )
    tol = TOLERANCE[num]
    for k, what in enumerate(("head_rms", "head_probe", "velocity")):
        checks.check(
            f"{n} spheres: PFV {what} within {tol[k]}", measured["PFV"][k] <= tol[k], f"({measured['PFV'][k]:.4f})"
        )
        checks.check(
            f"{n} spheres: PFV {what} no larger than YADE's",
            measured["PFV"][k] <= measured["YADE"][k],
            f"({measured['PFV'][k]:.4f} vs {measured['YADE'][k]:.4f})",
        )
    print(f"({time.time() - start:.1f} s)")
    return measured


def time_dependence():
    """On the small packing: waveAction equals HalfWave; a ramp and a standing wave touch the
    right-hand side only, once per step, and the pressures follow the load linearly."""
    build(SIZES[0])
    flow = configure(pfv.FlowEngine(), (3,), [0.0] * 6)
    flow.waveAction = True
    flow.sineAverage = flow.sineMagnitude = A
    insert(flow)
    O.run(1, True)
    p_yade_form = np.array(flow.core.pressure())
    flow.waveAction = False
    ramp = waves.HalfWave(amplitude=A, length=L, rate=1e5)  # A(t) = A + 1e5 t: doubles over 10 steps
    flow.set_boundary_pressure(flow.ymax, ramp)
    O.run(1, True)
    p_halfwave = np.array(flow.core.pressure()) * ramp.amplitude_at(0) / ramp.amplitude_at(O.time - O.dt)
    checks.check(
        "waveAction equals HalfWave(A, L) (same formula)",
        np.max(np.abs(p_yade_form - p_halfwave)) <= 1e-12 * A,
        f"({np.max(np.abs(p_yade_form - p_halfwave)):.2g})",
    )
    builds, meshes, evaluations = flow.core.system_builds, flow.core.remesh_count, flow.core.field_evaluations
    ratios = []
    for step in range(10):
        t = O.time
        O.run(1, True)
        ratios.append(np.max(np.abs(np.array(flow.core.pressure()) * A / ramp.amplitude_at(t) - p_yade_form)))
    checks.check(
        "ramp: no new system nor mesh over 10 steps",
        (flow.core.system_builds, flow.core.remesh_count) == (builds, meshes),
        f"(system_builds {builds} -> {flow.core.system_builds}, remesh_count {meshes} -> {flow.core.remesh_count})",
    )
    checks.check("ramp: one evaluation per step", flow.core.field_evaluations - evaluations == 10)
    checks.check("ramp: pressures scale with A(t)", max(ratios) <= 1e-10 * A, f"(max deviation {max(ratios):.2g})")
    standing = waves.StandingWave(amplitude=A, period=40 * O.dt, length=L, mean=0.5 * A)
    flow.set_boundary_pressure(flow.ymax, standing)
    O.run(1, True)
    top = [c for c in range(flow.nCells()) if flow.getCellPImposed(c)]
    t = O.time - O.dt
    deviation = max(
        abs(
            flow.getCellPressure(c)
            - (
                0.5 * A
                + A * math.sin(2 * math.pi * t / standing.period) * math.cos(math.pi * flow.core.cell_center(c)[0] / L)
            )
        )
        for c in top
    )
    checks.check(
        "standing wave: the top cells hold the load of their own x", deviation <= 1e-12 * A, f"({deviation:.2g})"
    )
    checks.check("standing wave: still no new system", flow.core.system_builds == builds)
    flow.clear_boundary_pressure()
    O.run(1, True)
    checks.check("cleared: the top holds bndCondValue again", max(abs(flow.getCellPressure(c)) for c in top) == 0.0)


start = time.time()
time_dependence()
head_rms = [run_size(num)["PFV"][0] for num in SIZES]
checks.check(
    f"PFV's head error falls with the grain size ({SIZES[0]} -> {SIZES[-1]} layers)",
    head_rms[-1] < head_rms[0],
    f"({head_rms[0]:.4f} -> {head_rms[-1]:.4f})",
)
print(f"total {time.time() - start:.1f} s")
checks.report("half-wave")
