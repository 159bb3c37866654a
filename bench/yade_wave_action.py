"""What YADE's own FlowEngine does with waveAction (the facts doc/waves.md states), measured.

    yade-double -j1 -n -x bench/yade_wave_action.py

Scene: the shipped 1000-sphere packing in the unit cube (pfv_testing.scenes), frozen, ymax the only pressure wall,
waveAction on with sineAverage = 10, sineMagnitude = 5. Prints probe pressures after the first step, after changing
sineMagnitude to 20 (no remesh), after updateBCs(), and after a retriangulation; then how the imposed top cells'
pressures compare with the cosine at their own x and with the 30 levels cos(pi k / 30) of YADE's bins.
"""
import math

from pfv_testing import scenes
from yade import O  # noqa: E402
from yade.wrapper import FlowEngine  # noqa: E402

PROBES = [(0.1, 0.5, 0.5), (0.5, 0.5, 0.5), (0.9, 0.5, 0.5), (0.1, 0.95, 0.5), (0.9, 0.95, 0.5)]


def probes(flow, what):
    print(f"yade_wave_action: {what:28s}", " ".join(f"{flow.getPorePressure(p):8.4f}" for p in PROBES))


scenes.build_permeameter(num=1000, frozen=True)
flow = FlowEngine(
    label="flow",
    wallIds=list(range(6)),
    bndCondIsPressure=[0, 0, 0, 1, 0, 0],
    bndCondValue=[0] * 6,
    boundaryUseMaxMin=[0] * 6,
    waveAction=True,
    sineAverage=10,
    sineMagnitude=5,
)
scenes.insert_flow(flow)
O.run(1, True)
probes(flow, "first step (mag 5)")
flow.sineMagnitude = 20
O.run(1, True)
probes(flow, "mag 20, no remesh")
flow.updateBCs()
O.run(1, True)
probes(flow, "after updateBCs()")
flow.updateTriangulation = True
O.run(2, True)
probes(flow, "after a retriangulation")
top = [(flow.getCellCenter(c)[0], flow.getCellPressure(c)) for c in range(flow.nCells()) if flow.getCellPImposed(c)]
own = max(abs(p - (10 + 20 * math.cos(math.pi * x))) for x, p in top)
levels = [10 + 20 * math.cos(math.pi * k / 30) for k in range(30)]
level = [min(range(30), key=lambda k: abs(p - levels[k])) for _, p in top]
off_level = max(abs(p - levels[k]) for (_, p), k in zip(top, level))
floor = sum(k == min(max(math.floor(30 * x), 0), 29) for (x, _), k in zip(top, level))
lag = max(abs(k - 30 * x) for (x, _), k in zip(top, level) if 0 < x < 1)
print(f"yade_wave_action: {len(top)} imposed top cells; max |p - cos at own x| = {own:.4f}")
print(
    f"yade_wave_action: every cell at one of the levels 10 + 20 cos(pi k / 30), k = 0..29, to {off_level:.1e}; "
    f"k = floor(30 x) for {floor} of {len(top)} (x: getCellCenter), |k - 30 x| <= {lag:.3f}"
)
