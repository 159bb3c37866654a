"""Ending a scene with pfv engines in it: never a hang, and the engines' memory freed.

    yade-double -n -x tests/yade/robustness/test_reset_cycles.py        (exit 0 = pass)

1. Every way a scene ends while O.run() runs in the background (O.reset(), O.pause() then O.reset(),
   O.resetThisScene(), O.resetCurrentScene(), O.resetAllScenes(), O.load), with one pfv engine, two, or a plain
   PyRunner beside one, or a plain PyRunner alone (pfv imported): the call returns, and the next scene runs. YADE's
   O.reset() waits for the run thread while it holds Python's GIL, which a Python engine in that thread needs: on
   main it waits forever. A watchdog (faulthandler, which needs no GIL) ends a hung process after WATCHDOG seconds
   with a traceback: it detects a deadlock and times nothing.
2. Which engines an end frees: O.resetThisScene() frees the engines of the current scene and no other (two scenes,
   O.switchToScene); O.resetAllScenes() and O.reset() all of them.
3. Memory over many cycles of a new 300-sphere scene with a new engine, two steps and the end of the scene, for each
   way of ending it (O.reset() 200 times, each other way 40 times, and O.reset() while O.run() runs): the resident
   memory may grow per cycle by at most a tenth of what one engine of this scene holds (measured here: four engines
   stepped in one scene), over what the same cycles without the engine grow (YADE's own). On main every reset
   scene's engine stays (YADE keeps a reference to every engine put into O.engines): a whole footprint per cycle.
4. The end of the process while O.run() runs (the script's end, after O.pause(), sys.exit), one or two engines
   (pfv_testing/exit_child.py): YADE exits with 0. On main the run thread takes the GIL back inside a step while
   Python finalizes, is ended on the spot and the C++ of the step cannot survive it: std::terminate, exit 134.
"""
import faulthandler
import gc
import time
import warnings

import subprocess

import pfv  # noqa: F401  (its wrappers of YADE's resets)
from pfv_testing import checks, lattice_scene, memory, paths
from yade import O

warnings.simplefilter("ignore")
WATCHDOG = 120.0  # seconds: the calls return in milliseconds, a deadlock never
SPHERES = 300


def build(engines=1, plain=False):
    return lattice_scene.build_box(SPHERES, engines, plain)


def run_in_background(iterations=3):
    """O.run() without end, returning once `iterations` are done (the run goes on)."""
    start = O.iter
    O.run()
    while O.iter < start + iterations:
        time.sleep(0.005)


def guarded(what, call):
    """call(); a deadlock ends the process with a traceback after WATCHDOG seconds."""
    print(f"     {what} ...", flush=True)
    faulthandler.dump_traceback_later(WATCHDOG, exit=True)
    try:
        call()
    finally:
        faulthandler.cancel_dump_traceback_later()


def pause_then_reset():
    O.pause()  # returns at once; the run thread finishes its iteration, which needs the GIL
    O.reset()


def load_empty():
    O.loadTmp("empty")


ENDS = {
    "O.reset()": lambda: O.reset(),
    "O.pause(), O.reset()": pause_then_reset,
    "O.resetThisScene()": lambda: O.resetThisScene(),
    "O.resetCurrentScene()": lambda: O.resetCurrentScene(),
    "O.resetAllScenes()": lambda: O.resetAllScenes(),
    "O.loadTmp() of another scene": load_empty,
}
SCENES = {  # what runs: (pfv engines, a plain PyRunner)
    "one pfv engine": (1, False),
    "two pfv engines": (2, False),
    "a pfv engine and a plain PyRunner": (1, True),
    "a plain PyRunner alone, pfv imported": (0, True),
}


def hang_cases():
    O.reset()
    O.saveTmp("empty")
    cases = 0
    for end_name, end in ENDS.items():
        for scene_name, (engines, plain) in SCENES.items():
            O.reset()
            build(engines, plain)
            run_in_background()
            guarded(f"{end_name} while O.run() runs, {scene_name}", end)
            checks.check(f"{end_name} while O.run() runs, {scene_name}: returns", not O.running)
            O.reset()
            (flow,) = build(1)
            O.run(2, True)
            checks.check(f"{end_name} while O.run() runs, {scene_name}: the next scene runs", flow.nCells() > 0)
            cases += 1
    return cases


def scoping_cases():
    """O.resetThisScene() frees the current scene's engines only; O.resetAllScenes() and O.reset() all."""
    for end_name in ("O.resetAllScenes()", "O.reset()"):
        O.reset()
        (first,) = build(1)
        O.run(2, True)
        O.switchToScene(O.addScene())
        (second,) = build(1)
        O.run(2, True)
        O.resetThisScene()
        checks.check(
            "O.resetThisScene() frees the engine of the current scene, not the other scene's",
            second.nCells() == 0 and first.nCells() > 0,
            f"({second.nCells()} and {first.nCells()} cells)",
        )
        O.switchToScene(0)
        O.run(1, True)
        checks.check("the other scene's engine runs on", first.nCells() > 0)
        ENDS[end_name]()
        checks.check(f"{end_name} frees every engine", first.nCells() == 0, f"({first.nCells()} cells)")
    return 3


def reset_while_running():
    run_in_background(2)
    O.reset()


def cycle_growth(cycles, engines, end, running=False):
    """kB of resident memory per cycle of: a new scene with `engines` engines, two steps, the end of the scene."""
    gc.collect()
    before = memory.rss_kb()
    for _ in range(cycles):
        build(engines)
        if running:
            reset_while_running()
        else:
            O.run(2, True)
            end()
    gc.collect()
    return (memory.rss_kb() - before) / cycles


def engine_footprint(engines=4):
    """kB of resident memory that one engine of the scene holds once it has stepped (`engines` in one scene)."""
    O.reset()
    gc.collect()
    before = memory.rss_kb()
    build(engines)
    O.run(1, True)
    gc.collect()
    footprint = (memory.rss_kb() - before) / engines
    O.reset()
    return footprint


MEMORY_CASES = [  # (name, cycles, end, while running)
    ("O.reset()", 200, ENDS["O.reset()"], False),
    ("O.reset() while O.run() runs", 40, None, True),
    ("O.resetThisScene()", 40, ENDS["O.resetThisScene()"], False),
    ("O.resetCurrentScene()", 40, ENDS["O.resetCurrentScene()"], False),
    ("O.resetAllScenes()", 40, ENDS["O.resetAllScenes()"], False),
    ("O.loadTmp() of another scene", 40, load_empty, False),
]


def memory_cases(footprint):
    O.reset()
    O.saveTmp("empty")
    for _ in range(5):  # allocator warm-up: the first cycles fill caches and pools
        cycle_growth(1, 1, ENDS["O.reset()"])
        cycle_growth(1, 0, ENDS["O.reset()"])
    for name, cycles, end, running in MEMORY_CASES:
        yade_only = cycle_growth(cycles, 0, end or ENDS["O.reset()"], running)
        with_engine = cycle_growth(cycles, 1, end, running)
        checks.check(
            f"{cycles} cycles ended by {name}: the engines are freed",
            with_engine - yade_only < footprint / 10,
            f"({with_engine:.1f} kB per cycle with the engine, {yade_only:.1f} without; one engine holds"
            f" {footprint:.0f} kB)",
        )
    return len(MEMORY_CASES)


def exit_cases():
    """The script ends while O.run() runs: YADE exits with 0 (on main: std::terminate, exit 134)."""
    cases = 0
    for engines in (1, 2):
        for how in ("end", "pause", "exit"):
            out = subprocess.run(
                ["yade-double", "-n", "-x", paths.tool("exit_child.py"), str(engines), how],
                capture_output=True,
                text=True,
                timeout=WATCHDOG,
            )
            ran = "RUNNING" in out.stdout
            checks.check(
                f"the script ends ({how}) while O.run() runs with {engines} pfv engine(s): exit 0",
                ran and out.returncode == 0,
                f"(exit {out.returncode}{'' if ran else ', did not run: ' + out.stderr[-300:]})",
            )
            cases += 1
    return cases


footprint = engine_footprint()  # first: later, freed memory is reused and the growth measured is less
count = hang_cases()
count += scoping_cases()
count += memory_cases(footprint)
count += exit_cases()
print(f"{count} cases")
checks.report("reset cycles")
