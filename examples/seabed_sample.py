# -*- coding: utf-8 -*-
"""A seabed sample by dry gravity deposition (thesis section 6.3.1, Tables 6.2 and 6.3).

    yade-double -n -x examples/seabed_sample.py [--quick] [--friction=1|30] [--out=FILE]

Grains rain from a loose cloud onto the floor of a box of length L = 2 h (h the bed's height), under
gravity, with the preparation friction angle phi_c1: 1 deg gives a dense sample (thesis n = 0.368),
30 deg a loose one (n = 0.436). Once at rest the friction is set to the simulation's phi_c2 = 30 deg
(phi_c1 <= phi_c2 keeps the packing stable). The porosity is measured in the bed's interior (away from
the walls, the floor and the surface by two diameters) with YADE's voxelPorosity.

Grains as Table 6.2/6.3: d50 = 0.06 m, dmax/dmin = 1.22, E = 15 MPa, kt/kn = 0.5, rho_s = 2600 kg/m3.
5000 grains (--quick: 1000). The sample is cached (PFV_CACHE_DIR or /tmp/pfv-seabed-cache) under its
parameters: the wave examples load it instead of depositing again. `prepare()` is what they call.
"""
import hashlib
import json
import math
import os
import sys

from yade import O, pack, utils
from yade.wrapper import (
    Bo1_Box_Aabb,
    Bo1_Sphere_Aabb,
    ForceResetter,
    FrictMat,
    Ig2_Box_Sphere_ScGeom,
    Ig2_Sphere_Sphere_ScGeom,
    InsertionSortCollider,
    InteractionLoop,
    Ip2_FrictMat_FrictMat_FrictPhys,
    Law2_ScGeom_FrictPhys_CundallStrack,
    NewtonIntegrator,
)

GRAINS = dict(d50=0.06, size_ratio=1.22, young=15e6, kt_kn=0.5, density=2600.0)
SIMULATION_FRICTION = 30.0  # deg, phi_c2
GRAVITY = 9.81
FORMAT = 1


def box_for(num, porosity_guess=0.40):
    """Bed of num grains with L = 2 h and depth (z) h / 2: the thesis' proportions (2 x 1 x ~0.5 m at 5000)."""
    solid = num * math.pi / 6 * GRAINS["d50"] ** 3
    h = (solid / (1 - porosity_guess)) ** (1 / 3)  # L * h * h / 2 = h^3
    return 2 * h, h, 0.5 * h


def _key(num, friction):
    text = json.dumps(dict(num=num, friction=friction, grains=GRAINS, format=FORMAT), sort_keys=True)
    return hashlib.sha1(text.encode()).hexdigest()[:12]


def cache_path(num, friction):
    folder = os.environ.get("PFV_CACHE_DIR", "/tmp/pfv-seabed-cache")
    os.makedirs(folder, exist_ok=True)
    return os.path.join(folder, f"seabed_n{num}_f{friction:g}_{_key(num, friction)}.json")


def _engines():
    return [
        ForceResetter(),
        InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Box_Aabb()]),
        InteractionLoop(
            [Ig2_Sphere_Sphere_ScGeom(), Ig2_Box_Sphere_ScGeom()],
            [Ip2_FrictMat_FrictMat_FrictPhys()],
            [Law2_ScGeom_FrictPhys_CundallStrack()],
        ),
        NewtonIntegrator(damping=0.3, gravity=(0, -GRAVITY, 0)),
    ]


def _materials(friction):
    O.materials.append(
        FrictMat(
            young=GRAINS["young"],
            poisson=GRAINS["kt_kn"],
            frictionAngle=math.radians(friction),
            density=GRAINS["density"],
            label="grains",
        )
    )
    O.materials.append(
        FrictMat(young=GRAINS["young"], poisson=GRAINS["kt_kn"], frictionAngle=0, density=0, label="walls")
    )


def interior_porosity(L, h_bed, W):
    """voxelPorosity in the bed less two diameters at every side and below the surface."""
    m = 2 * GRAINS["d50"]
    lo, hi = (m, m, m), (L - m, h_bed - m, W - m)
    if not all(b > a for a, b in zip(lo, hi)):
        raise ValueError("the bed is too small to measure its interior porosity")
    return utils.voxelPorosity(160, lo, hi)


def deposit(num, friction, seed=1, max_iter=400000):
    """Rain num grains in the reset scene; returns (spheres [(x, y, z, r)], box, interior porosity)."""
    L, h, W = box_for(num)
    O.reset()
    _materials(friction)
    top = 3.0 * h  # the cloud is loose: three bed heights
    O.bodies.append(utils.aabbWalls([(0, 0, 0), (L, top, W)], thickness=0, material="walls"))
    sp = pack.SpherePack()
    rel_fuzz = (GRAINS["size_ratio"] - 1) / (GRAINS["size_ratio"] + 1)  # r in [r50 (1 - f), r50 (1 + f)]
    made = sp.makeCloud((0, 0, 0), (L, top, W), GRAINS["d50"] / 2, rel_fuzz, num, False, seed=seed)
    if made < num:
        raise RuntimeError(f"makeCloud placed {made} of {num} grains")
    sp.toSimulation(material="grains")
    O.engines = _engines()
    O.dt = 0.5 * utils.PWaveTimeStep()
    while O.iter < max_iter:
        O.run(2000, True)
        if O.iter > 20000 and utils.unbalancedForce() < 0.005 and utils.kineticEnergy() < 1e-6 * num:
            break
    else:
        raise RuntimeError("the grains did not come to rest")
    for b in O.bodies:  # phi_c2 for the simulation; a few steps let the contacts take it
        if b.material.label == "grains":
            b.material.frictionAngle = math.radians(SIMULATION_FRICTION)
    for i in O.interactions:
        if i.isReal and hasattr(i.phys, "tangensOfFrictionAngle"):
            i.phys.tangensOfFrictionAngle = math.tan(math.radians(SIMULATION_FRICTION))
    O.run(2000, True)
    spheres = [(tuple(b.state.pos), b.shape.radius) for b in O.bodies if b.shape.__class__.__name__ == "Sphere"]
    h_bed = max(p[1] + r for p, r in spheres)
    return [(p[0], p[1], p[2], r) for p, r in spheres], (L, h_bed, W), interior_porosity(L, h_bed, W)


def prepare(num, friction):
    """The cached sample of num grains deposited at phi_c1 = friction (deg): dict with spheres, box
    (L, bed height, W), porosity, friction; deposited first if not cached."""
    path = cache_path(num, friction)
    if os.path.exists(path):
        with open(path) as f:
            return json.load(f)
    spheres, box, porosity = deposit(num, friction)
    sample = dict(spheres=spheres, box=box, porosity=porosity, friction=friction, num=num, grains=GRAINS)
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        json.dump(sample, f)
    os.replace(tmp, path)  # concurrent batch jobs never read half a file
    return sample


def load_into_scene(sample, friction=SIMULATION_FRICTION):
    """Reset the scene and build the sample's grains with friction phi_c2 inside rigid walls at the bed's
    box (the top wall at the bed's surface: the fluid boundary where the wave acts)."""
    O.reset()
    _materials(friction)
    L, h_bed, W = sample["box"]
    O.bodies.append(utils.aabbWalls([(0, 0, 0), (L, h_bed, W)], thickness=0, material="walls"))
    for x, y, z, r in sample["spheres"]:
        O.bodies.append(utils.sphere((x, y, z), r, material="grains"))
    O.engines = _engines()


THESIS_POROSITY = {1.0: 0.368, 30.0: 0.436}


def main(argv):
    quick = "--quick" in argv
    num = 1000 if quick else 5000
    frictions = [float(a.split("=", 1)[1]) for a in argv if a.startswith("--friction=")] or [1.0, 30.0]
    out = next((a.split("=", 1)[1] for a in argv if a.startswith("--out=")), None)
    rows = []
    for friction in frictions:
        s = prepare(num, friction)
        thesis = THESIS_POROSITY.get(friction)
        rows.append(dict(friction=friction, num=num, porosity=s["porosity"], thesis=thesis, box=s["box"]))
        print(
            f"seabed sample: {num} grains, phi_c1 = {friction:g} deg: interior porosity {s['porosity']:.3f}"
            + (f" (thesis {thesis})" if thesis else "")
            + f", bed {s['box'][0]:.3f} x {s['box'][1]:.3f} x "
            f"{s['box'][2]:.3f} m"
        )
    if out:
        with open(out, "w") as f:
            json.dump(rows, f, indent=1)


if __name__ == "__main__":
    main(sys.argv[1:])
    sys.exit(0)
