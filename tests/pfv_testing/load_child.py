"""A fresh YADE process that loads a scene saved with pfv engines, run by tests/yade/robustness/test_load_takeover.py:

    yade-double -n -x tests/pfv_testing/load_child.py SCENE MODE SETTINGS

MODE is when the script imports pfv: "before" the load, "after" it, or "never" (the restored PyRunner's command
imports it at the first step); "refused" is "never" with viscosity = -1 set on the first label before the first
step, which must fail naming it, and then the viscosity set to its saved value. SETTINGS is JSON, label ->
[bndCondValue, inlet wall, saved viscosity]: each label gets its bndCondValue after the load (and after the import),
before the first step. Prints one line "RESULT <json>": what each label named before the step, whether a query on it
answered then, how many iterations ran until every label named a pfv.FlowEngine (at most 3), and after one more
iteration without pfv imported, the label's type, viscosity, pore pressures and inlet flux.
Nothing of pfv nor pfv_testing is imported here, so that "never" means never.
"""
import builtins
import json
import sys

from yade import O

PROBES = [(0.5, 0.5, 0.5), (0.3, 0.2, 0.7), (0.8, 0.9, 0.2)]


def sample(engine, inlet):
    return {
        "type": type(engine).__name__,
        "viscosity": engine.viscosity,
        "pressures": [engine.getPorePressure(p) for p in PROBES],
        "flux": engine.getBoundaryFlux(inlet),
    }


def before_step(settings, out):
    """What each label names and answers after the load; its new boundary pressures."""
    for label, (values, _, _) in settings.items():
        engine = getattr(builtins, label)
        out["before_step"][label] = type(engine).__name__
        try:
            engine.getPorePressure(PROBES[0])
            out["query_before_step"][label] = "answered"
        except AttributeError as error:
            out["query_before_step"][label] = f"AttributeError: {error}"
        engine.bndCondValue = values


def refused_step(settings, out):
    """viscosity = -1 on the first label, a step (which must fail), then the saved viscosity."""
    first = next(iter(settings))
    getattr(builtins, first).viscosity = -1.0
    out["refused"] = "no error"
    # The runner's first run: in the first iteration, or in the second for a scene saved in the middle
    # of an iteration in which it had run (YADE runs that iteration again without it).
    for _ in range(2):
        try:
            O.run(1, True)
        except Exception as error:  # noqa: BLE001
            out["refused"] = f"{type(error).__name__}: {error}"
            break
    out["refused_label"] = type(getattr(builtins, first)).__name__
    getattr(builtins, first).viscosity = settings[first][2]


def main(path, mode, settings):
    if mode == "before":
        import pfv  # noqa: F401
    O.load(path)
    if mode == "after":
        import pfv  # noqa: F401, F811
    out = {"pfv_imported_before_step": "pfv" in sys.modules, "before_step": {}, "query_before_step": {}, "after": {}}
    before_step(settings, out)
    if mode == "refused":
        refused_step(settings, out)
    # Without pfv the restored PyRunners take over at their first run, which YADE defers by an iteration
    # for a scene saved in the middle of an iteration if they had run in it (their schedule says so); an
    # engine taken over by another's run steps in the next iteration.
    out["iterations_to_take_over"] = 0
    while out["iterations_to_take_over"] < 3:
        O.run(1, True)
        out["iterations_to_take_over"] += 1
        if all(type(getattr(builtins, label)).__name__ == "FlowEngine" for label in settings):
            break
    if mode in ("never", "refused"):
        O.run(1, True)
    for label, (_, inlet, _) in settings.items():
        out["after"][label] = sample(getattr(builtins, label), inlet)
    print("RESULT " + json.dumps(out), flush=True)


main(sys.argv[1], sys.argv[2], json.loads(sys.argv[3]))
