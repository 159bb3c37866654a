"""PFV's periodic flow (pfv._core.PeriodicFlow) beside YADE's PeriodicFlowEngine, and where YADE's cannot run.

    yade-double -n -x tests/yade/flow/test_periodic_vs_yade.py        (exit 0 = pass)

1. Simple cubic array, radius 0.4995, spacing 1, 6 x 6 x 6 spheres, centres jittered by up to 1e-4 (YADE's engine
   gives NaN on the exact, cospherical array), gradP = (0, 1, 0), viscosity 1: the same positions in both engines.
   Both implement the thesis' hydraulic-radius model; they differ in how they clamp the near-zero-length throats
   inside each cube of the lattice (PFV: 100 x the median conductance, YADE: relative to the mean), which moves the
   permeability by a fraction of a per cent (measured: PFV 2.4878e-3, YADE 2.4933e-3). Checked: kappa within 1 %,
   every sphere's force within 1 % of its magnitude, the pressure differences between five probes within 1 % of the
   drop gradP L across the cell, and PFV's total force -gradP V to 1e-8.
2. The exact array: PFV joins the cells of each cube into one pore (zero-length throats), which makes it isotropic:
   kappa along x, y, z the same to 1e-9. (Regular arrays against Zick & Homsy (1982), at their solid fractions:
   test_periodic_references.py.)
3. The same array in a cell sheared by one spacing (O.cell.hSize with an off-diagonal 6: the same lattice), where
   YADE's engine reports "periodicity is broken" and crashes: PFV gives the unsheared kappa to 1e-8.
4. A dense random periodic packing made by YADE's own pack.randomPeriPack (297 spheres, solid fraction 0.62; YADE's
   engine fails on these with locateCell errors): PFV's total force is -gradP V to 1e-8, its kappa is positive, and
   the packing tiled 2 x 2 x 2 (a cell twice as large, eight copies) gives the same kappa to 1e-8.
"""
import numpy as np

from pfv_testing import checks
from pfv_testing.periodic_scene import RADIUS, build, cell_matrix, cubic_array, dem_engines
from yade import O, pack  # noqa: E402
from yade.minieigenHP import Vector3  # noqa: E402
from yade.wrapper import PeriodicFlowEngine  # noqa: E402
import pfv._core as core  # noqa: E402

SIDE, JITTER = 6, 1e-4
GRADIENT = (0.0, 1.0, 0.0)


def pfv_flow(centres, radii, h, gradient=GRADIENT):
    flow = core.PeriodicFlow()
    flow.set_settings(viscosity=1.0, permeability_factor=1.0, gradient=gradient, bulk_modulus=0.0)
    flow.step(np.asarray(centres, dtype=float), np.asarray(radii, dtype=float), h, 1e-5)
    return flow


# 1. Side by side on the jittered array.
centres = build(SIDE, JITTER)
yade_flow = PeriodicFlowEngine(gradP=Vector3(*GRADIENT), viscosity=1.0, useSolver=3)
O.engines = dem_engines(yade_flow)
O.step()
O.step()
yade_kappa = -yade_flow.averageVelocity()[1]
yade_force = np.array([tuple(O.forces.f(i)) for i in range(len(centres))])
radii = np.full(len(centres), RADIUS)
ours = pfv_flow(centres, radii, cell_matrix())
kappa = -ours.mean_velocity()[1]
print(f"simple cubic, jittered: kappa PFV {kappa:.6g}, YADE {yade_kappa:.6g}")
checks.check(
    "jittered array: kappa within 1 % of YADE's", abs(kappa / yade_kappa - 1) < 0.01, f"{kappa} vs {yade_kappa}"
)
force = ours.forces()
scale = np.linalg.norm(yade_force, axis=1)
worst = float((np.linalg.norm(force - yade_force, axis=1) / scale).max())
checks.check("jittered array: every sphere's force within 1 % of YADE's", worst < 0.01, f"worst {worst:.2e}")
# Probe pressures, in pores away from the lattice's cube centres (where the clamped throats sit), relative to the
# first probe (each engine fixes the constant of p~ its own way), against the drop gradP L across the cell.
PROBES = [(0.5, 1.0, 0.5), (2.5, 3.0, 1.5), (4.5, 5.0, 3.5), (1.0, 2.5, 5.5), (5.5, 0.5, 3.0)]
ours_p = np.array([ours.pressure_at(x) for x in PROBES])
yade_p = np.array([yade_flow.getPorePressure(Vector3(*x)) for x in PROBES])
drop = GRADIENT[1] * SIDE
worst_p = float(np.abs((ours_p - ours_p[0]) - (yade_p - yade_p[0])).max() / drop)
print(f"probe pressures PFV {list(ours_p - ours_p[0])}, YADE {list(yade_p - yade_p[0])}")
checks.check(
    "jittered array: probe pressure differences within 1 % of gradP L of YADE's", worst_p < 0.01, f"{worst_p:.2e}"
)
volume = SIDE**3
total = force.sum(axis=0)
checks.check(
    "jittered array: PFV's total force is -gradP V",
    np.abs(total + np.array(GRADIENT) * volume).max() < 1e-8 * volume,
    f"{total}",
)

# 2. The exact array, along each axis.
exact = cubic_array(SIDE)
kappas = []
for axis in range(3):
    g = np.zeros(3)
    g[axis] = 1.0
    kappas.append(-pfv_flow(exact, radii, cell_matrix(), tuple(g)).mean_velocity()[axis])
print(f"simple cubic, exact: kappa PFV {kappas}")
checks.check("exact array: isotropic", max(kappas) - min(kappas) < 1e-9 * kappas[0], f"{kappas}")

# 3. Sheared by one spacing: the same lattice.
sheared = cell_matrix()
sheared[0, 1] = SIDE
kappa_sheared = -pfv_flow(exact, radii, sheared).mean_velocity()[1]
checks.check(
    "exact array in a cell sheared by one period: the same kappa",
    abs(kappa_sheared - kappas[1]) < 1e-8 * kappas[1],
    f"{kappa_sheared} vs {kappas[1]}",
)

# 4. A dense random periodic packing of YADE's making, and eight copies of it.
dense = pack.randomPeriPack(radius=0.5, initSize=(8, 8, 8), seed=1, noPrint=True)
centres = np.array([tuple(s[0]) for s in dense])
radii = np.array([s[1] for s in dense])
h = np.diag(np.array(tuple(dense.cellSize)))
volume = abs(np.linalg.det(h))
flow = pfv_flow(centres, radii, h)
total = flow.forces().sum(axis=0)
checks.check(
    f"randomPeriPack, {len(radii)} spheres: total force -gradP V",
    np.abs(total + np.array(GRADIENT) * volume).max() < 1e-8 * volume,
    f"{total}",
)
kappa_dense = -flow.mean_velocity()[1]
shifts = [h @ np.array([i, j, k]) for i in range(2) for j in range(2) for k in range(2)]
tiled = pfv_flow(np.concatenate([centres + t for t in shifts]), np.tile(radii, 8), 2 * h)
kappa_tiled = -tiled.mean_velocity()[1]
print(f"randomPeriPack: kappa {kappa_dense:.6g}, 2 x 2 x 2 copies {kappa_tiled:.6g}")
checks.check("randomPeriPack: kappa positive", kappa_dense > 0, f"{kappa_dense}")
checks.check(
    "randomPeriPack: 2 x 2 x 2 copies give the same kappa",
    abs(kappa_tiled - kappa_dense) < 1e-8 * kappa_dense,
    f"{kappa_tiled} vs {kappa_dense}",
)
checks.report("periodic_vs_yade")
