"""PFV's and YADE's viscousShear forces on the identical scene (informative: the two definitions differ).

    PYTHONPATH=build/python OMP_NUM_THREADS=1 yade-double -n -x bench/viscous_shear_vs_yade.py

The shipped 1000-sphere packing, spheres free, no gravity, drained top, viscosity 1, every sphere started with
v = 0.05 y e_x; two steps in each engine with viscousShear=True, then shearLubForce(id) of every sphere is compared
(norm ratio and cosine over all spheres and over the interior ones). Nothing is asserted.
"""

import math
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(sys.argv[0])), "..", "tests", "yade"))
import scenes
from yade import O
import pfv
res = {}
for name in ('yade', 'pfv'):
    info = scenes.build_permeameter(num=1000, frozen=False)
    flow = (FlowEngine if name == 'yade' else pfv.FlowEngine)(label='flow')
    scenes.configure_flow(flow, axis=1, dp=0.0, viscosity=1.0)
    flow.bndCondIsPressure = [False, False, False, True, False, False]
    flow.viscousShear = True
    scenes.insert_flow(flow)
    for i in info['spheres']:
        O.bodies[i].state.vel = (0.05 * O.bodies[i].state.pos[1], 0, 0)
    O.run(2, True)
    res[name] = [flow.shearLubForce(i) for i in info['spheres']]
    pos = [O.bodies[i].state.pos for i in info['spheres']]

a, b = res['yade'], res['pfv']
dot = sum(x.dot(y) for x, y in zip(a, b)); na = math.sqrt(sum(x.squaredNorm() for x in a)); nb = math.sqrt(sum(y.squaredNorm() for y in b))
print('norm yade %.4g pfv %.4g ratio pfv/yade %.3f cosine %.4f' % (na, nb, nb / na, dot / (na * nb)))
inner = [k for k, p in enumerate(pos) if all(0.15 < p[d] < 0.85 for d in range(3))]
na = math.sqrt(sum(a[k].squaredNorm() for k in inner)); nb = math.sqrt(sum(b[k].squaredNorm() for k in inner)); dot = sum(a[k].dot(b[k]) for k in inner)
print('interior %d spheres: ratio %.3f cosine %.4f' % (len(inner), nb / na, dot / (na * nb)))
