"""A settings change rebuilds the same thing whichever API makes it: the table in
tests/data/settings_invalidation.csv, checked here through the bindings (pfv._core.Engine) and
through pfv.FlowEngine in a YADE scene, and by tests/cpp/settings_invalidation_test.cpp through
the C++ API. The core decides; neither Python layer requests a rebuild of its own for these.

    yade-double -n -x tests/yade/engine/test_settings_invalidation.py      (exit 0 = pass)
"""
import ast

import numpy as np  # noqa: E402
from pfv_testing import checks, scenes
from pfv_testing.settings_table import change, rows as read_table
from yade import O  # noqa: E402
import pfv  # noqa: E402
from pfv._core import Engine  # noqa: E402


def rebuilt(core, before):
    remeshes, systems = core.remesh_count - before[0], core.system_builds - before[1]
    return "remesh" if remeshes else "system" if systems else "none"


def through_core(row, centres, radii):
    e = Engine()
    e.bnd_is_pressure = [True, True, False, False, False, False]
    e.bnd_value = [1.0, 0.0, 0.0, 0.0, 0.0, 0.0]
    walls = [0.0, 1.0, 0.0, 1.0, 0.0, 1.0]
    for _ in range(2):
        e.step(centres, radii, walls, 1e-3)
    before = (e.remesh_count, e.system_builds)
    change(e, row["core"], ast.literal_eval(row["value"]))
    e.step(centres, radii, walls, 1e-3)
    return rebuilt(e, before)


def through_flow_engine(row):
    scenes.build_permeameter(num=1000)
    flow = pfv.FlowEngine(label="flow")
    scenes.configure_flow(flow, axis=0, dp=1.0)
    scenes.insert_flow(flow)
    O.dt = 1e-3
    O.run(2, True)
    core = flow.core
    before = (core.remesh_count, core.system_builds)
    value = row["value"] if row["yade_value"] == "=" else row["yade_value"]
    change(flow, row["yade"], ast.literal_eval(value))
    O.run(1, True)
    return rebuilt(core, before)


def main():
    spheres = np.array(scenes.packing(1000))
    centres, radii = np.ascontiguousarray(spheres[:, :3]), np.ascontiguousarray(spheres[:, 3])
    rows = read_table()
    for row in rows:
        seen = {"core": through_core(row, centres, radii)}
        if row["yade"] != "-":
            seen["FlowEngine"] = through_flow_engine(row)
        print(f"{row['core']:30s} expected {row['rebuild']:7s} seen {seen}")
        for api, got in seen.items():
            checks.check(f"{row['core']} through {api}: {got}, expected {row['rebuild']}", got == row["rebuild"])
    checks.check(f"the table has {len(rows)} rows (at least 20)", not len(rows) < 20)
    checks.report("settings invalidation")


main()
