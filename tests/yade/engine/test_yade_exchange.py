"""The fast exchange with YADE gives what YADE's Python interface gives, bit for bit.

    yade-double -n -x tests/yade/engine/test_yade_exchange.py        (exit 0 = pass)

Positions.

pfv reads the centres each step from a yade.pack.SpherePack filled by YADE's C++ fromSimulation()
(yade_sphere_pack.hpp), after checking at each scan of the bodies that the pack gives every
centre and radius YADE's Python interface gives; otherwise from the coordinate lists of
yade._utils.coordsAndDisplacements. On a permeameter whose spheres move under the drag, both
readers must give identical pressures and forces at every step, also across the erasure of a
sphere (which leaves len(O.bodies) unchanged: the engine must notice it by the count of what it
reads, rescan and remesh). The low-level functions must reject what they cannot read.
"""

import numpy as np

from pfv_testing import checks, scenes
from yade import O  # noqa: E402
from yade.minieigenHP import Vector3  # noqa: E402
from yade.wrapper import Sphere  # noqa: E402
from yade._packSpheres import SpherePack  # noqa: E402
from pfv import FlowEngine, _core  # noqa: E402


STEPS, ERASE_AT = 12, 6
info = scenes.build_permeameter(num=1000, frozen=False)
victim = info["spheres"][len(info["spheres"]) // 2]
O.saveTmp("reader")


def run(use_pack):
    O.loadTmp("reader")
    flow = FlowEngine()
    scenes.configure_flow(flow, axis=1, dp=1.0e3, useSolver=3, meshUpdateInterval=1000000, defTolerance=0)
    flow._bodies.use_sphere_pack = use_pack
    scenes.insert_flow(flow)
    start = np.array([tuple(b.state.pos) for b in O.bodies if isinstance(b.shape, Sphere)])
    steps = []
    for k in range(STEPS):
        if k == ERASE_AT:
            O.bodies.erase(victim)
        O.run(1, True)
        steps.append(
            dict(
                p=np.array(flow.core.pressure()),
                f=np.array(flow.core.forces()),
                remeshes=flow.core.remesh_count,
                spheres=len(flow._bodies.scan.ids),
            )
        )
    centres = flow._bodies.read_positions()[0]
    python = np.array([tuple(O.bodies[int(i)].state.pos) for i in flow._bodies.scan.ids])
    moved = np.abs(python[:ERASE_AT] - start[:ERASE_AT]).max()
    return dict(
        flow=flow,
        source=flow.position_source,
        steps=steps,
        centres=centres,
        python=python,
        moved=moved,
        ids=list(flow._bodies.scan.ids),
    )


checks.check(
    "this build reads YADE's SpherePack (Boost.Python found and the layout recognised)",
    _core.sphere_pack_size(SpherePack()) == 0,
)
fast, lists = run(True), run(False)
checks.check(f"default reader: {fast['source']}", fast["source"] == "SpherePack")
checks.check(f"reader with the pack switched off: {lists['source']}", lists["source"] == "coordinate lists")
checks.check(f"the spheres move under the drag (largest displacement {fast['moved']:.3g})", fast["moved"] > 1e-9)
for name, run_ in (("SpherePack", fast), ("coordinate lists", lists)):
    checks.check(
        f"{name}: every centre read equals b.state.pos after the run", np.array_equal(run_["centres"], run_["python"])
    )
    before, after = run_["steps"][ERASE_AT - 1], run_["steps"][ERASE_AT]
    checks.check(
        f"{name}: erasing sphere #{victim} (len(O.bodies) unchanged) -> rescan and remesh "
        f"({before['spheres']} -> {after['spheres']} spheres, remesh {before['remeshes']} -> {after['remeshes']})",
        after["remeshes"] == before["remeshes"] + 1 and after["spheres"] == before["spheres"] - 1,
    )
    checks.check(f"{name}: the erased sphere is out of the flow", victim not in run_["ids"])
same = all(
    np.array_equal(a["p"], b["p"]) and np.array_equal(a["f"], b["f"]) for a, b in zip(fast["steps"], lists["steps"])
)
checks.check(f"pressures and forces identical to the bit at all {STEPS} steps of both readers", same)

# The low-level functions refuse what they cannot read.
checks.check(
    "sphere_pack_size is -1 for objects that are no SpherePack",
    _core.sphere_pack_size(O.forces) == -1 and _core.sphere_pack_size(3.0) == -1,
)
pack = SpherePack()
pack.fromSimulation()
n = _core.sphere_pack_size(pack)


def raises(kind, action):
    """The message of the `kind` exception action() raises, None if it raises none (others propagate)."""
    try:
        action()
    except kind as error:
        return str(error)
    return None


message = raises(ValueError, lambda: _core.gather_sphere_pack(O.forces, np.arange(2), np.empty((2, 3))))
checks.check(f"gather from a non-pack: ValueError ({message})", message is not None and "SpherePack" in message)
out = np.full((2, 3), 7.0)
checks.check(
    "gather with the wrong expected size returns False and writes nothing; with the right one True",
    not _core.gather_sphere_pack(pack, np.arange(2), out, None, n + 1)
    and (out == 7.0).all()
    and _core.gather_sphere_pack(pack, np.arange(2), out, None, n)
    and (out != 7.0).any(),
)
message = raises(IndexError, lambda: _core.gather_sphere_pack(pack, np.array([n]), np.empty((1, 3))))
checks.check(f"index beyond the pack: IndexError ({message})", message is not None and "outside the pack" in message)
message = raises(ValueError, lambda: _core.gather_sphere_pack(pack, np.arange(3), np.empty((2, 3))))
checks.check(f"centres of the wrong shape: ValueError ({message})", message is not None and "shape" in message)
message = raises(
    ValueError, lambda: _core.gather_sphere_pack(pack, np.arange(2), np.empty((2, 3)), np.empty(2, dtype=np.float32))
)
checks.check(f"radii not float64: ValueError ({message})", message is not None and "radii" in message)

# Forces: the bridge calls YADE's force_add (the function O.forces.addF is bound to) directly;
# O.forces must end up exactly as with one addF call per body, and as with the bridge's own
# fallback (addF with its Vector3s) when handed something that is not a bound addF.
# Each write on a fresh scene: YADE 2023.02a's O.forces.reset() segfaults once a body has been
# erased, and called between steps (tried here) it left sums off by one pass of addF.
scenes.build_permeameter(num=1000, frozen=False)
n_bodies = len(O.bodies)
ids = np.array([b.id for b in O.bodies], dtype=np.int64)
rows = np.arange(len(ids), dtype=np.int64)[::-1].copy()  # any row order
F = (
    np.random.default_rng(7).normal(size=(len(ids), 3))
    * 10.0 ** np.random.default_rng(8).integers(-6, 6, len(ids))[:, None]
)
bridge = _core.YadeForceBridge(Vector3, ids, rows)
checks.check("the bridge found YADE's force_add", bridge.calls_yade_directly)


def forces_after(write):
    scenes.build_permeameter(num=1000, frozen=False)
    add = O.forces.addF
    for _ in range(2):  # twice: addF accumulates
        write(add)
    return np.array([tuple(O.forces.f(int(i))) for i in ids])


direct = forces_after(lambda add: bridge.apply(add, F))
python = forces_after(lambda add: [add(int(i), tuple(F[r])) for i, r in zip(ids, rows)])
fallback = forces_after(lambda add: bridge.apply(lambda i, f: add(i, f), F))
checks.check("direct force_add: O.forces identical to addF from Python", np.array_equal(direct, python))
checks.check("fallback (addF with the bridge's Vector3s): identical too", np.array_equal(fallback, python))
checks.check("and equal to the forces given, added twice", np.array_equal(direct, 2 * F[rows]))
bad = _core.YadeForceBridge(Vector3, np.array([n_bodies + 5], dtype=np.int64), np.array([0], dtype=np.int64))
message = raises(IndexError, lambda: bad.apply(O.forces.addF, np.zeros((1, 3))))
checks.check(
    f"a body id beyond the scene: YADE's IndexError ({message})", message is not None and "out of range" in message
)

# The engine's overload reads the C++ force array itself (no numpy copy): the same sums.
scenes.build_permeameter(num=1000, frozen=False)
spheres = [b for b in O.bodies if isinstance(b.shape, Sphere)]
pos = np.array([tuple(b.state.pos) for b in spheres])
rad = np.array([b.shape.radius for b in spheres])
low, high = (pos - rad[:, None]).min(0) - 1e-3, (pos + rad[:, None]).max(0) + 1e-3
engine = _core.Engine()
engine.bnd_is_pressure = [False, False, True, True, False, False]
engine.bnd_value = [0.0, 0.0, 1.0, 0.0, 0.0, 0.0]
engine.step(pos, rad, [low[0], high[0], low[1], high[1], low[2], high[2]], 1e-4)
sphere_bridge = _core.YadeForceBridge(
    Vector3, np.array([b.id for b in spheres], dtype=np.int64), np.arange(len(spheres), dtype=np.int64)
)
from_engine = forces_after(lambda add: sphere_bridge.apply(add, engine))
from_array = forces_after(lambda add: sphere_bridge.apply(add, engine.forces()))
checks.check(
    "apply(addF, engine) writes what apply(addF, engine.forces()) writes",
    np.array_equal(from_engine, from_array) and np.abs(from_engine).max() > 0,
)
message = raises(ValueError, lambda: bridge.apply(O.forces.addF, engine))  # one force row per body of the scene
checks.check("an engine with enough force rows is accepted", message is None)
message = raises(ValueError, lambda: bad.apply(O.forces.addF, _core.Engine()))
checks.check(f"an engine without forces: ValueError ({message})", message is not None and "does not match" in message)

checks.report("YADE exchange")
