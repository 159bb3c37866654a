"""Every condition that belongs to a mesh holds on every mesh from its first step, whether the mesh was
built in the step (serial) or in the background (multithread) and adopted later.

    yade-double -n -x tests/yade/robustness/test_mesh_conditions.py        (exit 0 = pass)

The conditions (CONDITIONS): cells blocked by blockHook (with and without zero pressure), cells whose
pressure blockHook imposes, flat cells (flatThreshold), points with an imposed pressure or flux, and
blocked cells carried to the next mesh (doInterpolate). On frozen spheres every mesh is the same, so the
outflow and the probe pressures must be the same at every step, in both modes, and differ from the
scene without the condition (else the test would not see a condition dropped). A background mesh used
to be adopted without blockHook's conditions for a step, so the flux alternated with the remeshes.
"""
import warnings

from pfv import FlowEngine
from pfv_testing import scenes
from pfv_testing.robustness import check, report, run

warnings.simplefilter("ignore")

STEPS = 8
INTERVAL = 2  # meshUpdateInterval: a new mesh every other step
PROBES = scenes.probe_points(n=2)
RTOL = 1e-10  # the same mesh and conditions: round-off only


def block_slab(zero_pressure):
    for c in range(_flow.nCells()):
        if _flow.getCellCenter(c)[0] < 0.3:
            _flow.blockCell(c, zero_pressure)


def impose_centre():
    for c in range(_flow.nCells()):
        x = _flow.getCellCenter(c)
        if all(abs(x[k] - 0.5) < 0.12 for k in range(3)):
            _flow.setCellPImposed(c, True)
            _flow.setCellPressure(c, 0.8)


def hook(code):
    def apply(flow):
        flow.blockHook = code

    return apply


def flat_cells(flow):
    flow.flatThreshold = 1e-4  # a fifth of the mean cell volume of this packing


def impose_pressure(flow):
    flow.imposePressure((0.5, 0.5, 0.5), 0.8)


def impose_flux(flow):
    flow.imposeFlux((0.5, 0.5, 0.5), 1e-5)


def carried_blocks(flow):
    flow.doInterpolate = True
    run(1)
    for c in range(flow.nCells()):
        if flow.getCellCenter(c)[0] < 0.3:
            flow.blockCell(c, True)


CONDITIONS = (
    ("blockHook blocks cells at zero pressure", hook("block_slab(True)")),
    ("blockHook blocks cells", hook("block_slab(False)")),
    ("blockHook imposes cell pressures", hook("impose_centre()")),
    ("flat cells (flatThreshold)", flat_cells),
    ("an imposed pressure (imposePressure)", impose_pressure),
    ("an imposed flux (imposeFlux)", impose_flux),
    ("blocked cells carried over (doInterpolate)", carried_blocks),
)


def observe(flow):
    return [flow.getBoundaryFlux(3)] + [flow.getPorePressure(p) for p in PROBES]


def history(condition, background):
    """What each of STEPS steps gives under the condition (None: without any)."""
    global _flow
    scenes.build_permeameter(num=300, frozen=True)
    _flow = flow = FlowEngine(label="flow", multithread=background, meshUpdateInterval=INTERVAL)
    scenes.configure_flow(flow, axis=1, dp=1.0)
    scenes.insert_flow(flow)
    if condition is not None:
        condition(flow)
    seen = []
    while len(seen) < STEPS:
        run(1)
        flow.core.wait_for_remesh()  # a background remesh in flight is adopted by the next step
        seen.append(observe(flow))
    return seen, flow.core.remesh_count


def close(a, b, rtol=RTOL):
    return all(abs(x - y) <= rtol * max(abs(x), abs(y), 1e-12) for x, y in zip(a, b))


def main():
    plain, _ = history(None, False)
    cases = 0
    for name, condition in CONDITIONS:
        serial, _ = history(condition, False)
        first = serial[-1]
        check(f"{name}: it changes the flow", not close(first, plain[-1], 1e-3), f"outflow {first[0]:.6g}")
        for background in (False, True):
            seen, remeshes = (serial, None) if not background else history(condition, True)
            mode = "background" if background else "serial"
            bad = [k for k, s in enumerate(seen) if not close(s, first)]
            check(
                f"{name}, {mode}: every step on every mesh as on the first",
                not bad,
                f"steps differing: {bad}; outflow {[round(s[0], 12) for s in seen]}",
            )
            if background:
                check(f"{name}, background: meshes were adopted from the background", remeshes >= 2, str(remeshes))
            cases += 1
    print(f"{cases} cases")
    report("mesh-condition")


_flow = None
main()
