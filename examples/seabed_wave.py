# -*- coding: utf-8 -*-
"""A wave on a granular seabed (thesis chapter 6): the run shared by wave_ramp.py and wave_standing.py.

The bed of examples/seabed_sample.py (dense: phi_c1 = 1 deg, loose: 30 deg; phi_c2 = 30 deg) lies in
a rigid box of length L = 2 h: lateral walls and floor impermeable (symmetry, no flux: thesis 6.2),
the wave's pressure on the top boundary, gravity with buoyancy (PFV's fluid_density; the engine
solves the excess pressure). Every `record` seconds pfv.diagnostics.Monitor records the 5 x 6
sensors, the gradient ratios grad H / i_c (i_c from the initial porosity, thesis 6.28), the top
height, porosity, kinetic energy and unbalanced force into plot.data; at the end the outputs are
written to --out: timeseries.csv (plot.saveDataTxt), profiles.json (sigma'_yy and p along the
symmetry axis, horizontal displacements on it against depth), summary.json, waves.png.

The sample is liquefied (thesis 6.4: grad H / i_c > 0.8) when the mean ratio over all sensor pairs,
averaged over one load period (or 1 s for the ramp), exceeds 0.8 at some time after the first period.
"""
import json
import math
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))  # imported by the wave examples
import seabed_sample  # noqa: E402
from yade import O, plot, utils  # noqa: E402
from yade.wrapper import NewtonIntegrator, PyRunner  # noqa: E402
from pfv import FlowEngine, diagnostics  # noqa: E402

RHO_F = 1000.0
VISCOSITY = 100.0  # Pa.s, thesis Tables 6.2/6.3 (0.1 kPa.s)
LIQUEFIED = 0.8  # grad H / i_c (thesis 6.4)


def options(argv, defaults):
    """--name=value for every key of defaults (numbers parsed), --quick as a flag."""
    o = dict(defaults)
    o["quick"] = "--quick" in argv
    for a in argv:
        if a.startswith("--") and "=" in a:
            k, v = a[2:].split("=", 1)
            if k not in o:
                raise SystemExit(f"unknown option --{k} (known: {', '.join(sorted(o))})")
            o[k] = type(defaults[k])(v) if defaults[k] is not None else v
    return o


def build(sample, settings=None):
    """The bed with its flow engine (FlowEngine attributes in `settings` set on top of this
    example's); returns (flow, box, time_steps), the last the first step's O.dt and the limits it
    was chosen from."""
    seabed_sample.load_into_scene(sample)
    L, h, W = sample["box"]
    flow = FlowEngine(
        label="flow",
        viscosity=VISCOSITY,
        fluid_density=RHO_F,
        meshUpdateInterval=200,
        bndCondIsPressure=[0, 0, 0, 1, 0, 0],
        bndCondValue=[0] * 6,
        boundaryUseMaxMin=[0] * 6,
    )
    for name, value in (settings or {}).items():
        setattr(flow, name, value)
    engines = list(O.engines)
    newton = [e for e in engines if isinstance(e, NewtonIntegrator)][0]
    newton.damping = 0.0  # the fluid damps
    engines.insert(engines.index(newton), flow)
    O.engines = engines
    # The collective viscous limit of the bed (below the single-grain dt_MV) is known once the engine
    # has a mesh: one short step, then 0.6 of the engine's critical step (it warns above 0.8). The
    # short step stays below the guard's 0.8 x limit for collective limits down to 0.125 dt_MV; the
    # dense 5000-grain bed has 0.31 dt_MV, the loose one 0.55 (summary.json "time_steps" of
    # wave_standing.py --duration=0.002, with --friction=1 for the dense bed).
    first = 0.1 * min(utils.PWaveTimeStep(), flow.viscous_time_step)
    O.dt = first
    O.run(1, True)
    O.dt = 0.6 * flow.critical_time_step
    time_steps = dict(
        first_step=first,
        viscous=flow.viscous_time_step,
        collective_viscous=flow.collective_viscous_time_step,
        p_wave=utils.PWaveTimeStep(),
    )
    return flow, (L, h, W), time_steps


def run(load_name, load, sample, duration, out, period, settings=None):
    """Run the bed under `load` (a pfv.waves profile) for `duration` s and write the outputs."""
    flow, (L, h, W), time_steps = build(sample, settings)
    flow.set_boundary_pressure(flow.ymax, load)
    n0 = sample["porosity"]
    grid = diagnostics.SensorGrid.in_box((0, 0, 0), (L, h, W), verticals=5, levels=6)
    monitor = diagnostics.Monitor(
        flow,
        grid,
        n0,
        seabed_sample.GRAINS["density"],
        RHO_F,
        L * W,
        bottom=0.0,
        amplitude=load.amplitude_at,
        t_end=duration,
        report_every=25,
    )
    import builtins

    builtins.seabed_monitor = monitor
    record = max(1, int(round(duration / 400 / O.dt)))
    O.engines = O.engines + [PyRunner(command="seabed_monitor()", iterPeriod=record)]
    # Long runs keep the record on disk as they go, so a run stopped early still leaves its time series.
    os.makedirs(out, exist_ok=True)
    builtins.seabed_checkpoint = lambda: plot.saveDataTxt(os.path.join(out, "timeseries.csv"))
    O.engines = O.engines + [PyRunner(command="seabed_checkpoint()", iterPeriod=25 * record)]
    start = np.array([tuple(b.state.pos) for b in O.bodies if b.shape.__class__.__name__ == "Sphere"])
    plot.reset()
    wall = time.time()
    O.run(int(math.ceil(duration / O.dt)), True)
    wall = time.time() - wall
    plot.saveDataTxt(os.path.join(out, "timeseries.csv"))
    diagnostics.save_plots(plot.data, os.path.join(out, "waves.png"), LIQUEFIED)

    ids, pos, rad, _, _ = diagnostics.sphere_arrays(O.bodies)
    top = diagnostics.top_height(pos, rad, 0.99)
    heights, sigma = diagnostics.effective_stress_profile(
        utils.bodyStressTensors(), ids, pos, rad, 0.0, top, 6, L * W, x_band=(0.4 * L, 0.6 * L)
    )
    depth, dx = diagnostics.horizontal_displacements(pos, start, 0.5 * L, 0.1 * L)
    profiles = dict(
        heights=heights.tolist(),
        sigma_eff_yy=sigma.tolist(),
        pore_pressure=diagnostics.pressure_profile(flow, 0.5 * L, 0.5 * W, heights).tolist(),
        axis_initial_height=depth.tolist(),
        axis_dx=dx.tolist(),
    )
    with open(os.path.join(out, "profiles.json"), "w") as f:
        json.dump(profiles, f, indent=1)

    t = np.asarray(plot.data["t"])
    ratio = np.mean([plot.data[k] for k in plot.data if k.startswith("r_")], axis=0)
    window = max(1, int(round(period / (t[1] - t[0])))) if len(t) > 1 else 1
    smooth = np.convolve(ratio, np.ones(window) / window, mode="valid")
    after = t[window - 1 :] >= period
    peak = float(np.max(smooth[after])) if np.any(after) else float("nan")
    summary = dict(
        load=load_name,
        profile=repr(load),
        grains=sample["num"],
        friction_prep=sample["friction"],
        settings=settings or {},
        porosity0=n0,
        i_c=monitor.i_c,
        duration=duration,
        dt=O.dt,
        steps=O.iter,
        time_steps=time_steps,
        wall_seconds=wall,
        peak_mean_ratio=peak,
        liquefied=bool(peak > LIQUEFIED),
        final_porosity=plot.data["porosity"][-1],
        settlement=plot.data["top"][0] - plot.data["top"][-1],
        max_axis_dx=float(np.max(np.abs(dx))) if len(dx) else 0.0,
    )
    with open(os.path.join(out, "summary.json"), "w") as f:
        json.dump(summary, f, indent=1)
    state = "liquefied" if summary["liquefied"] else "stable"
    print(
        f"{load_name}: peak period-mean grad H / i_c {peak:.3f} -> {state}; "
        f"n {n0:.3f} -> {summary['final_porosity']:.3f}; {O.iter} steps in {wall:.0f} s; outputs in {out}"
    )
    return summary
