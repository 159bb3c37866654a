"""Buoyancy: with fluid_density the engine adds -fluid_density V g to every sphere's fluid force,
g the NewtonIntegrator's gravity; the pressures stay excess (piezometric) pressures.

    yade-double -n -x tests/yade/flow/test_buoyancy.py        (exit 0 = pass)

Archimedes on a still fluid: every sphere gets its displaced weight upwards; the absolute pressure
is hydrostatic; a sphere as dense as the fluid does not move off under gravity and one twice as
dense sinks at g/2 on its first step (before any drag); off, nothing changes.
"""
import math
import warnings

import numpy as np

from pfv_testing import robustness as rb
from yade import O  # noqa: E402
from yade.wrapper import NewtonIntegrator  # noqa: E402

warnings.simplefilter("ignore")
RHO_F, G = 1000.0, np.array([0.0, -9.81, 0.0])


def still(frozen=True, **kw):
    flow = rb.fresh(frozen=frozen, **kw)
    flow.bndCondValue = [0.0] * 6  # both pressure walls at 0: no flow
    newton = [e for e in O.engines if isinstance(e, NewtonIntegrator)][0]
    newton.gravity = tuple(G)
    newton.damping = 0.0
    return flow


ids = range(6, 1006)
flow = still()
rb.run(1)
off = np.array([tuple(flow.fluidForce(i)) for i in ids])
flow = still(fluid_density=RHO_F)
rb.run(1)
forces = np.array([tuple(flow.fluidForce(i)) for i in ids])
volumes = np.array([4 / 3 * math.pi * O.bodies[i].shape.radius ** 3 for i in ids])
expected = -RHO_F * volumes[:, None] * G
err = np.abs(forces - off - expected).max() / np.abs(expected).max()
rb.check("every sphere gets its displaced weight upwards", err < 1e-12, f"(max rel. diff {err:.1e})")
total = forces.sum(axis=0)[1] / (RHO_F * 9.81 * volumes.sum())
rb.check("total: the weight of the displaced fluid", abs(total - 1) < 1e-9, f"(ratio {total:.12f})")
top = O.bodies[3].state.pos[1]
for y in (0.1, 0.5, 0.9):
    p = flow.absolute_pressure((0.5, y, 0.5))
    rb.check(
        f"absolute pressure hydrostatic at y = {y}",
        abs(p - RHO_F * 9.81 * (top - y)) < 1e-9 * RHO_F * 9.81,
        f"({p:.6f} vs {RHO_F * 9.81 * (top - y):.6f})",
    )
rb.check("the excess pressure stays zero", abs(flow.getPorePressure((0.5, 0.5, 0.5))) < 1e-12)

# One sphere free to move among frozen ones: neutral, then twice as dense as the fluid.
for density, expected_acc in ((RHO_F, 0.0), (2 * RHO_F, -9.81 / 2)):
    flow = still(fluid_density=RHO_F)
    ball = O.bodies[500]
    ball.state.blockedDOFs = ""
    ball.state.mass = density * 4 / 3 * math.pi * ball.shape.radius**3
    for i in O.interactions.withBody(500) if hasattr(O.interactions, "withBody") else []:
        O.interactions.erase(i.id1, i.id2)
    O.engines = [e for e in O.engines if type(e).__name__ != "InteractionLoop"]  # no contacts: fluid and gravity only
    rb.run(1)
    acc = ball.state.vel[1] / O.dt
    rb.check(
        f"sphere of density {density:g}: first-step acceleration {expected_acc:g}",
        abs(acc - expected_acc) < 1e-6 * 9.81,
        f"({acc:.9f})",
    )

flow = still(fluid_density=0.0)
rb.run(1)
again = np.array([tuple(flow.fluidForce(i)) for i in ids])
rb.check("fluid_density = 0 changes nothing", np.array_equal(again, off))
rb.report("buoyancy")
