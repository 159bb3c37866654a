"""The measurements, each run inside a yade child: timing trials on the saved permeameter, the oedometer runs, the
start-up trials and the memory of one engine."""
import gc
import os
import time

from pfv_testing.flow_bench.scene import (
    AXIS,
    OEDO_LOAD,
    build_scene,
    core_timer,
    insert_engine,
    log,
    make_engine,
    probe_points,
)
from pfv_testing.memory import reset_peak, rss_kb
from pfv_testing.timing import median

WINDOW = 3  # steps timed after a (forced) remesh


def _yade_td(flow):
    """YADE FlowEngine timingDeltas as {label: seconds} (cumulative)."""
    try:
        return {lab: t * 1e-9 for lab, t, c in flow.timingDeltas.data}
    except Exception:
        return {}


def _td_diff(a, b):
    return {k: b.get(k, 0.0) - a.get(k, 0.0) for k in b}


def _dem_exec(flow):
    """Seconds of execTime of every engine but the flow engine so far (O.timingEnabled): the DEM
    part of a step, to compare the DEM of the coupled steps with the dry steps."""
    from yade import O

    return sum(e.execTime for e in O.engines if e is not flow) * 1e-9


def _dry_trial(res, steady):
    """The dry trial (no flow engine): wall and DEM time of the steady steps."""
    from yade import O

    for _ in range(WINDOW):
        O.step()
    wall, dem = [], []
    for _ in range(steady):
        d0 = _dem_exec(None)
        t0 = time.perf_counter()
        O.step()
        wall.append(time.perf_counter() - t0)
        dem.append(_dem_exec(None) - d0)
    res['steady_wall'] = wall
    res['steady_dem'] = dem
    res['vmax'] = max(b.state.vel.norm() for b in O.bodies)
    O.reset()
    return res


def _step(flow, kind, proxy, record):
    """One O.step() with the engine, its wall time, engine time and DEM time added to `record` (and for pfv the
    core's stage times, remesh count and core step)."""
    from yade import O

    e0 = flow.execTime
    d0 = _dem_exec(flow)
    t0 = time.perf_counter()
    O.step()
    wall = time.perf_counter() - t0
    ex = (flow.execTime - e0) * 1e-9
    record['wall'].append(wall)
    record['exec'].append(ex)
    record.setdefault('dem', []).append(_dem_exec(flow) - d0)
    if kind.startswith('pfv'):
        core = flow.core
        record.setdefault('step_times', []).append(dict(core.step_times()))
        record.setdefault('remesh_count', []).append(core.remesh_count)
        if proxy is not None:
            record.setdefault('core_step', []).append(proxy.step_times()['total'])


def _windows(flow, kind, proxy, steady, res):
    """The first steps, the steady steps, a forced remesh and the tail of a trial, each timed step by step."""
    first = dict(wall=[], exec=[])
    td0 = _yade_td(flow)
    for _ in range(WINDOW):
        _step(flow, kind, proxy, first)
    if kind.startswith('pfv'):
        first['remesh_times'] = dict(flow.core.remesh_times())
    st = dict(wall=[], exec=[])
    td1 = _yade_td(flow)
    c0, w0 = time.process_time(), time.perf_counter()
    for _ in range(steady):
        _step(flow, kind, proxy, st)
    st['cpu_share'] = (time.process_time() - c0) / (time.perf_counter() - w0)
    td2 = _yade_td(flow)
    flow.updateTriangulation = True
    rem = dict(wall=[], exec=[])
    for _ in range(WINDOW):
        _step(flow, kind, proxy, rem)
    td3 = _yade_td(flow)
    if kind.startswith('pfv'):
        rem['remesh_times'] = dict(flow.core.remesh_times())
    tail = dict(wall=[], exec=[])
    for _ in range(3):
        _step(flow, kind, proxy, tail)
    res.update(first=first, steady=st, remesh=rem, tail=tail)
    return td0, td1, td2, td3


def _engine_state(res, flow, kind, proxy, info):
    """What the engine shows at the end of a trial: pressures at the probes, fluxes, and for pfv its factor and
    time-step guard."""
    from yade import O

    L = info['box']
    res['vmax'] = max(b.state.vel.norm() for b in O.bodies)
    res['probes'] = [flow.getPorePressure(p) for p in probe_points(L)]
    res['flux'] = [flow.getBoundaryFlux(2 * AXIS), flow.getBoundaryFlux(2 * AXIS + 1)]
    res['core_timer'] = proxy is not None
    if kind.startswith('pfv'):
        res['reduced'] = bool(flow.core.reduced_precision_factor())
        res['guard'] = [dict(h) for h in flow.collective_viscous_history]
        res['factor_nonzeros'] = flow.core.factor_nonzeros()


def run_trial(kind, info, steady, warnings_seen):
    """One trial on the saved permeameter scene. kind in yade, pfv, dry."""
    import warnings
    from yade import O

    O.loadTmp('bench')
    O.timingEnabled = True
    gc.collect()
    res = dict(kind=kind)
    if kind == 'dry':
        return _dry_trial(res, steady)

    flow = make_engine(kind)
    proxy = core_timer(flow) if kind.startswith('pfv') else None
    insert_engine(flow)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter('always')
        td0, td1, td2, td3 = _windows(flow, kind, proxy, steady, res)
    for w in caught:
        msg = '%s: %s' % (w.category.__name__, str(w.message)[:200])
        if msg not in warnings_seen:
            warnings_seen.append(msg)
            log('warning from %s engine: %s' % (kind, msg))
    res['n_cells'] = flow.nCells()
    if kind == 'yade':
        res['td_first'] = _td_diff(td0, td1)
        res['td_steady'] = _td_diff(td1, td2)
        res['td_remesh'] = _td_diff(td2, td3)
    _engine_state(res, flow, kind, proxy, info)
    # Release the engine before O.reset().
    flow = proxy = None
    O.engines = O.engines[:1]
    O.reset()
    gc.collect()
    return res


def exchange_reference(info):
    """Times of the primitive exchange operations on the dry scene (for reference)."""
    import numpy as np
    import yade
    from yade import O

    O.loadTmp('bench')
    cad = yade._utils.coordsAndDisplacements
    ids = list(range(6, len(O.bodies)))
    zero = (0.0, 0.0, 0.0)
    read, write = [], []
    for _ in range(7):
        t0 = time.perf_counter()
        np.array([cad(0)[0], cad(1)[0], cad(2)[0]]).T
        read.append(time.perf_counter() - t0)
        add = O.forces.addF
        t0 = time.perf_counter()
        for i in ids:
            add(i, zero)
        write.append(time.perf_counter() - t0)
    O.reset()
    return dict(read_positions=median(read), write_forces=median(write))


def oedometer_trial(kind, n, steps, interval):
    from yade import O

    O.loadTmp('oedo')
    triax = [e for e in O.engines if type(e).__name__ == 'TriaxialStressController'][0]
    triax.goal2 = OEDO_LOAD
    flow = None
    if kind != 'dry':
        engine, _, variant = kind.partition('-')
        flow = make_engine(engine, oedometer=True, oedo_interval=interval)
        insert_engine(flow)
    O.timingEnabled = True
    gc.collect()
    y0 = O.bodies[3].state.pos[1]
    t0 = time.perf_counter()
    if kind.endswith('-mt'):
        # Remesh in a background thread while the DEM runs, switched on after the first step: YADE 2023.02a
        # segfaults when multithread=True before its first triangulation. The first mesh is foreground in both.
        O.run(1, True)
        flow.multithread = True
        O.run(steps - 1, True)
    else:
        O.run(steps, True)
    wall = time.perf_counter() - t0
    res = dict(kind=kind, seconds=wall, steps=steps, settlement=y0 - O.bodies[3].state.pos[1])
    if flow is not None:
        res['exec'] = flow.execTime * 1e-9
        res['p_mid'] = flow.getPorePressure((0.5 * O.bodies[1].state.pos[0], 0.1 * y0, 0.5 * O.bodies[5].state.pos[2]))
        if kind.startswith('pfv'):
            res['remeshes'] = flow.core.remesh_count
    del flow
    O.reset()
    gc.collect()
    return res


def timing_child(opts):
    from yade import O

    out = dict(threads=O.numThreads, sizes={}, oedometer={}, warnings=[], load_start=os.getloadavg())
    rounds = opts['rounds']
    for n in opts['sizes']:
        info = build_scene(n)
        O.saveTmp('bench')
        steady = opts['steady'] if n <= 20000 else max(5, opts['steady'] // 2)
        log(
            'timing n=%d (%d bodies, dt %.3g, settled in %d steps to unbalanced force %.3g) threads=%d, %d rounds, '
            '%d steady steps'
            % (n, info['bodies'], info['dt'], info['settle_steps'], info['unbalanced'], O.numThreads, rounds, steady)
        )
        order = ['yade', 'pfv', 'dry'] + (['pfv-double'] if opts['double'] else [])
        trials = {kind: [] for kind in order}
        for r in range(rounds):
            k = r % 3
            for kind in order[k:] + order[:k]:
                t0 = time.time()
                trials[kind].append(run_trial(kind, info, steady, out['warnings']))
                log('  n=%d round %d %-4s done in %.1f s' % (n, r + 1, kind, time.time() - t0))
        ref = exchange_reference(info)
        out['sizes'][str(n)] = dict(info=info, trials=trials, exchange_reference=ref, steady=steady)
        O.reset()
        gc.collect()
    if opts['oedometer']:
        for n in opts['oedo_sizes']:
            build_scene(n, oedometer=True)
            O.saveTmp('oedo')
            log('oedometer n=%d threads=%d: %d steps per trial' % (n, O.numThreads, opts['oedo_steps']))
            order = ['yade', 'pfv', 'dry'] + (['yade-mt', 'pfv-mt'] if opts['multithread'] else [])
            trials = {kind: [] for kind in order}
            for r in range(rounds):
                k = r % len(order)
                for kind in order[k:] + order[:k]:
                    res = oedometer_trial(kind, n, opts['oedo_steps'], opts['oedo_interval'])
                    trials[kind].append(res)
                    log('  oedometer n=%d round %d %-4s %.2f s' % (n, r + 1, kind, res['seconds']))
            out['oedometer'][str(n)] = dict(trials=trials, steps=opts['oedo_steps'], interval=opts['oedo_interval'])
            O.reset()
    out['load_end'] = os.getloadavg()
    return out


def startup_child(opts):
    """YADE and PFV trials only (run_trial), the order swapped every round."""
    from yade import O

    out = dict(threads=O.numThreads, sizes={}, warnings=[], load_start=os.getloadavg())
    for n in opts['sizes']:
        info = build_scene(n)
        O.saveTmp('bench')
        log(
            'startup n=%d (%d bodies, settled in %d steps) threads=%d, %d rounds, %d steady steps'
            % (n, info['bodies'], info['settle_steps'], O.numThreads, opts['rounds'], opts['steady'])
        )
        trials = dict(yade=[], pfv=[])
        for r in range(opts['rounds']):
            for kind in ('yade', 'pfv') if r % 2 == 0 else ('pfv', 'yade'):
                t0 = time.time()
                trials[kind].append(run_trial(kind, info, opts['steady'], out['warnings']))
                log('  n=%d round %d %-4s done in %.1f s' % (n, r + 1, kind, time.time() - t0))
        out['sizes'][str(n)] = dict(info=info, trials=trials, steady=opts['steady'])
        O.reset()
        gc.collect()
    out['load_end'] = os.getloadavg()
    return out


def memory_child(opts):
    from yade import O

    n, kind = opts['size'], opts['engine']
    build_scene(n, settle=False)
    gc.collect()
    before = rss_kb()
    exact = reset_peak()
    if kind != 'dry':
        flow = make_engine(kind)
        insert_engine(flow)
    for _ in range(WINDOW + opts['steady']):
        O.step()
    peak_first, mid = rss_kb('VmHWM'), rss_kb()
    reset_peak()
    if kind != 'dry':
        flow.updateTriangulation = True
    for _ in range(WINDOW):
        O.step()
    peak_remesh, after = rss_kb('VmHWM'), rss_kb()
    if not exact:
        peak_remesh = max(peak_remesh, peak_first)
    return dict(
        n=n,
        kind=kind,
        rss_before_kb=before,
        peak_kb=max(peak_first, peak_remesh),
        peak_first_kb=peak_first,
        rss_mid_kb=mid,
        peak_remesh_kb=peak_remesh,
        rss_after_kb=after,
        peak_reset=exact,
        threads=O.numThreads,
    )
