"""Medians over the rounds of the trials' raw data: what the reports print."""
from pfv_testing.flow_bench.scene import DP
from pfv_testing.flow_bench.trials import WINDOW
from pfv_testing.timing import median


STEP_STAGES = ('volumes', 'solve', 'forces')


def _engine_columns(trials):
    """One engine's medians over its trials: flow step, remesh, first step, coupled step, their spread."""
    flow_step, remesh, first, coupled = [], [], [], []
    for x in trials:
        fs = median(x['steady']['exec'])
        flow_step.append(fs)
        coupled.append(median(x['steady']['wall']))
        remesh.append(sum(x['remesh']['exec']) - (WINDOW - 1) * fs)
        first.append(sum(x['first']['exec']) - (WINDOW - 1) * fs)
    return dict(
        flow=median(flow_step),
        remesh=median(remesh),
        first=median(first),
        cpu_share=median([x['steady'].get('cpu_share') for x in trials]),
        coupled=median(coupled),
        flow_range=(min(flow_step), max(flow_step)),
        remesh_range=(min(remesh), max(remesh)),
        cells=trials[0]['n_cells'] if trials else None,
    )


def _agreement(row, tr):
    """Pressure agreement (first round of each engine: same number of steps from the same state)."""
    if tr['yade'] and tr['pfv']:
        py, pp = tr['yade'][0]['probes'], tr['pfv'][0]['probes']
        diffs = [abs(a - b) / DP for a, b in zip(py, pp)]
        fy, fp = tr['yade'][0]['flux'], tr['pfv'][0]['flux']
        row['agreement'] = dict(
            max_dp=max(diffs),
            mean_dp=sum(diffs) / len(diffs),
            flux_in_rel=abs(fp[0] - fy[0]) / abs(fy[0]) if fy[0] else float('nan'),
            flux_out_rel=abs(fp[1] - fy[1]) / abs(fy[1]) if fy[1] else float('nan'),
            flux_yade=fy,
            flux_pfv=fp,
            probe_yade=py[13],
            probe_pfv=pp[13],
        )
    if tr['pfv'] and tr.get('pfv-double'):
        # the default (32-bit factor, refined) against the direct double solve, same steps from the same state
        pp, pd = tr['pfv'][0]['probes'], tr['pfv-double'][0]['probes']
        row['double_agreement'] = dict(max_dp=max(abs(a - b) / DP for a, b in zip(pp, pd)))
        row['default_factor'] = '32-bit' if tr['pfv'][0].get('reduced') else 'double'


def _pfv_remesh_stages(x):
    """PFV's remesh step of one trial, by stage."""
    rt = x['remesh']['remesh_times']
    rem_stages = [k2 for k2 in rt if k2 not in STEP_STAGES]  # whatever stages the core reports
    counts = x['remesh'].get('remesh_count', [])
    base = x['first']['remesh_count'][-1] if x['first'].get('remesh_count') else None
    # the window step in which PFV remeshed
    k = next((i for i, c in enumerate(counts) if base is not None and c > base), 0)
    stt = x['remesh']['step_times'][k]
    d = {s: rt[s] for s in rem_stages}
    d.update({'first ' + s: stt[s] for s in STEP_STAGES})
    cpp = sum(d.values())
    d['python + exchange'] = x['remesh']['exec'][k] - (x['remesh']['core_step'][k] if x['core_timer'] else cpp)
    if x['core_timer']:
        d['C++ untimed'] = x['remesh']['core_step'][k] - cpp
    d['total (engine exec)'] = x['remesh']['exec'][k]
    return d


def _pfv_steady_stages(x):
    """PFV's steady step of one trial, by stage (medians over its steps)."""
    steps = x['steady']['step_times']
    s = {k2: median([q[k2] for q in steps]) for k2 in STEP_STAGES}
    cpp = [sum(q[k2] for k2 in STEP_STAGES) for q in steps]
    ex = x['steady']['exec']
    if x['core_timer']:
        cs = x['steady']['core_step']
        s['C++ untimed'] = median([c - p for c, p in zip(cs, cpp)])
        s['python + exchange'] = median([e - c for e, c in zip(ex, cs)])
    else:
        s['python + exchange'] = median([e - p for e, p in zip(ex, cpp)])
    s['total (engine exec)'] = median(ex)
    return s


def _pfv_breakdown(trials):
    br = {'remesh': {}, 'steady': {}}
    per_trial_r = [_pfv_remesh_stages(x) for x in trials]
    per_trial_s = [_pfv_steady_stages(x) for x in trials]
    for key, lst in (('remesh', per_trial_r), ('steady', per_trial_s)):
        if lst:
            br[key] = {k2: median([q.get(k2) for q in lst]) for k2 in lst[0]}
    return br


def _yade_breakdown(trials):
    """YADE's own timingDeltas breakdown."""
    yb = {'steady': {}, 'remesh': {}}
    ys, yr = [], []
    for x in trials:
        S = len(x['steady']['exec'])
        s = {k2: v / S for k2, v in x.get('td_steady', {}).items()}
        ys.append(s)
        yr.append({k2: v - (WINDOW - 1) * s.get(k2, 0.0) for k2, v in x.get('td_remesh', {}).items()})
    for key, lst in (('steady', ys), ('remesh', yr)):
        if lst and lst[0]:
            yb[key] = {k2: median([q.get(k2) for q in lst]) for k2 in lst[0]}
    return yb


def _size_row(ns, sd):
    """The medians of one size's trials."""
    tr = sd['trials']
    row = dict(n=int(ns))
    dry = [median(x['steady_wall']) for x in tr['dry']]
    row['dry'] = median(dry)
    dry_dem = [median(x['steady_dem']) for x in tr['dry'] if x.get('steady_dem')]
    row['dry_dem'] = median(dry_dem) if dry_dem else None
    row['dry_range'] = (min(dry), max(dry)) if dry else None
    row['vmax'] = {k: max([x.get('vmax', float('nan')) for x in tr[k]] or [float('nan')]) for k in tr}
    for kind in [k for k in ('yade', 'pfv', 'pfv-double') if tr.get(k)]:
        row[kind] = _engine_columns(tr[kind])
        row[kind]['coupled_minus_dry'] = row[kind]['coupled'] - row['dry']
        dem = [median(x['steady']['dem']) for x in tr[kind] if x['steady'].get('dem')]
        row[kind]['dem'] = median(dem) if dem else None
    _agreement(row, tr)
    row['pfv_breakdown'] = _pfv_breakdown(tr['pfv'])
    row['yade_breakdown'] = _yade_breakdown(tr['yade'])
    row['exchange_reference'] = sd['exchange_reference']
    row['info'] = sd['info']
    return row


def _oedometer_row(ns, od):
    tr = od['trials']
    dry = median([x['seconds'] / x['steps'] for x in tr['dry']])
    r = dict(n=int(ns), steps=od['steps'], interval=od['interval'], dry=dry)
    for kind in [k for k in ('yade', 'pfv', 'yade-mt', 'pfv-mt') if tr.get(k)]:
        c = median([x['seconds'] / x['steps'] for x in tr[kind]])
        r[kind] = dict(
            coupled=c,
            ratio=c / dry if dry else float('nan'),
            exec=median([x['exec'] / x['steps'] for x in tr[kind]]),
            p_mid=tr[kind][0].get('p_mid'),
            remeshes=tr[kind][0].get('remeshes'),
            settlement=tr[kind][0].get('settlement'),
        )
    r['dry_settlement'] = tr['dry'][0]['settlement'] if tr['dry'] else None
    return r


def summarise(timing, memory):
    """Per threads and size: medians. Returns nested dict used by the report and stored in the JSON."""
    summ = {}
    for t, data in timing.items():
        st = {ns: _size_row(ns, sd) for ns, sd in data['sizes'].items()}
        oe = {ns: _oedometer_row(ns, od) for ns, od in data.get('oedometer', {}).items()}
        summ[t] = dict(sizes=st, oedometer=oe, load=(data.get('load_start'), data.get('load_end')))
    mem = {}
    for m in memory:
        mem.setdefault(str(m['n']), {})[m['kind']] = m
    return summ, mem


def _window_cost(record, flow_step):
    """Engine time of a WINDOW-step window minus WINDOW-1 steady flow steps (the summary's definition)."""
    return sum(record['exec']) - (WINDOW - 1) * flow_step


def startup_summary(data):
    """Per size: medians over rounds of the per-trial first step, remesh, their ratio and PFV's breakdown."""
    rows = {}
    for n, d in sorted(data['sizes'].items(), key=lambda kv: int(kv[0])):
        row = dict(cells=None)
        for kind, trials in d['trials'].items():
            first, remesh, ratio, cpu = [], [], [], []
            parts = {}
            for x in trials:
                fs = median(x['steady']['exec'])
                f, r = _window_cost(x['first'], fs), _window_cost(x['remesh'], fs)
                first.append(f)
                remesh.append(r)
                ratio.append(f / r)
                cpu.append(x['steady'].get('cpu_share', float('nan')))
                if kind != 'pfv':
                    continue
                row['cells'] = x['n_cells']
                tf, tr = x['first']['remesh_times'], x['remesh']['remesh_times']
                cold = [g for g in x['guard'] if g['remesh_count'] == 1]
                warm = [g for g in x['guard'] if g['remesh_count'] == 2]
                for key, a, b in (
                    ('ordering', tf['analysis'], tr['analysis']),
                    ('factorization', tf['factorization'], tr['factorization']),
                    (
                        'triangulation + geometry',
                        tf['triangulation'] + tf['geometry'],
                        tr['triangulation'] + tr['geometry'],
                    ),
                    ('time-step guard', sum(g['seconds'] for g in cold), sum(g['seconds'] for g in warm)),
                    (
                        'python + exchange',
                        x['first']['exec'][0] - x['first']['core_step'][0],
                        x['remesh']['exec'][0] - x['remesh']['core_step'][0],
                    ),
                ):
                    parts.setdefault(key, []).append((a, b))
                parts.setdefault('applications', []).append(
                    (sum(g['iterations'] for g in cold), sum(g['iterations'] for g in warm))
                )
                parts.setdefault('methods', []).append(
                    ('+'.join(g.get('method', '?') for g in cold), '+'.join(g.get('method', '?') for g in warm))
                )
                parts.setdefault('factor nonzeros', []).append((x['factor_nonzeros'], x['factor_nonzeros']))
            pair_medians = {
                k: v[0] if k == 'methods' else (median([a for a, _ in v]), median([b for _, b in v]))
                for k, v in parts.items()
            }
            row[kind] = dict(
                first=median(first),
                remesh=median(remesh),
                ratio=median(ratio),
                first_per_round=first,
                first_range=(min(first), max(first)),
                ratio_range=(min(ratio), max(ratio)),
                cpu_share=median(cpu),
                parts=pair_medians,
            )
        row['pfv_over_yade_first'] = row['pfv']['first'] / row['yade']['first']
        # Per round: the two engines' trials of one round ran next to each other, at the same machine speed.
        per_round = [p / y for y, p in zip(row['yade']['first_per_round'], row['pfv']['first_per_round'])]
        row['pfv_over_yade_range'] = (min(per_round), max(per_round))
        rows[n] = row
    return rows
