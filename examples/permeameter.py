"""Darcy permeameter: a first example of pfv.FlowEngine in YADE.

    yade-double -n -x examples/permeameter.py

A cloud of fixed spheres fills a 1 cm box closed by six walls. Water pressure dP is imposed on the ymin wall and 0
on the ymax wall; the four other walls are impermeable. Printed: the flux through both pressure walls, the
permeability K from Darcy's law Q = K A dP / (mu L), the mean pressure across the sample, and all that again with
the pressure drop doubled (Darcy: Q doubles, K stays). For a deforming, coupled sample see examples/oedometer.py.
"""
from yade import O, pack, utils
from yade.wrapper import (
    Bo1_Box_Aabb,
    Bo1_Sphere_Aabb,
    ForceResetter,
    Ig2_Box_Sphere_ScGeom,
    Ig2_Sphere_Sphere_ScGeom,
    InsertionSortCollider,
    InteractionLoop,
    Ip2_FrictMat_FrictMat_FrictPhys,
    Law2_ScGeom_FrictPhys_CundallStrack,
    NewtonIntegrator,
)
from pfv import FlowEngine

L = 0.01  # side of the cubic box [m]
MU = 1.0e-3  # viscosity of water [Pa s]
DP = 100.0  # pressure drop along y [Pa]
YMIN, YMAX = 2, 3  # utils.aabbWalls gives the walls in the order xmin, xmax, ymin, ymax, zmin, zmax

# The walls first: the flow engine expects them to be bodies 0..5 (its default wallIds).
O.bodies.append(utils.aabbWalls([(0, 0, 0), (L, L, L)], thickness=0))
# 600 spheres at random places without overlap (porosity about 0.7: makeCloud cannot place them much denser);
# the fixed seed gives the same packing on every run.
cloud = pack.SpherePack()
cloud.makeCloud((0, 0, 0), (L, L, L), rRelFuzz=0.3, num=600, porosity=0.7, seed=1)
for centre, radius in cloud:
    sphere = utils.sphere(centre, radius)
    sphere.state.blockedDOFs = 'xyzXYZ'  # fixed skeleton: no pore volume changes, so inflow = outflow exactly
    O.bodies.append(sphere)
print('%d spheres, mean diameter %.4e m, box side %g m' % (len(cloud), 2 * sum(r for c, r in cloud) / len(cloud), L))

flow = FlowEngine(label='flow')
flow.viscosity = MU
flow.boundaryUseMaxMin = [False] * 6  # the flow domain ends at the walls, not at the outermost spheres
flow.bndCondIsPressure = [False, False, True, True, False, False]  # pressure on ymin and ymax, no flow elsewhere

# The usual DEM loop, with the flow engine where YADE's own FlowEngine goes: after the contact forces, before the
# integrator, which then moves the bodies under contact + fluid forces.
O.engines = [
    ForceResetter(),
    InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Box_Aabb()]),
    InteractionLoop(
        [Ig2_Sphere_Sphere_ScGeom(), Ig2_Box_Sphere_ScGeom()],
        [Ip2_FrictMat_FrictMat_FrictPhys()],
        [Law2_ScGeom_FrictPhys_CundallStrack()],
    ),
    flow,
    NewtonIntegrator(damping=0.2),
]
O.dt = 0.5 * utils.PWaveTimeStep()

for dp in (DP, 2 * DP):
    flow.bndCondValue = [0, 0, dp, 0, 0, 0]  # new pressures apply from the next step on
    O.run(3, True)  # the spheres are fixed: every step gives the same steady flow
    q_in, q_out = flow.getBoundaryFlux(YMIN), flow.getBoundaryFlux(YMAX)  # YADE's sign: > 0 leaves the sample
    K = abs(q_in) * MU * L / (L * L * dp)  # intrinsic permeability [m^2]
    print(
        'dP = %g Pa: Q_in = %.15e m3/s, Q_out = %.15e m3/s, Q_in + Q_out = %.3e m3/s, K = %.6e m2'
        % (dp, q_in, q_out, q_in + q_out, K)
    )
    for y in (0.25, 0.5, 0.75):
        print(
            '  mean pressure at y/L = %.2f: %.6f Pa (linear: %.6f Pa)'
            % (y, flow.averageSlicePressure(y * L, 1), dp * (1 - y))
        )
