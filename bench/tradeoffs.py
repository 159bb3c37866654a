"""Speed/accuracy study of the PFV engine's options: solver, tolerance, remesh schedule.

    PYTHONPATH=build/python OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 \\
        /usr/bin/python3.11 bench/tradeoffs.py [--quick] [--out=doc/tradeoffs.md] [--jobs=1]
        [--sizes=1000,5000] [--rounds=3] [--figure=doc/figures/tradeoffs.png] [--work=/tmp/trade]
        [--report-only]      (re-render the report from the part files in --work, no measurement)
        [--part=SCENE:N]     (internal: measure one scene at one size, write --work/part_SCENE_N.json)
        [--accuracy]         (the multigrid's tolerance against its error in the oedometers alone: below)

No DEM: every scene is driven kinematically from Python with the C++ core (pfv.Engine).

Packings: N spheres, radii uniform in [0.8, 1.2] x r, solid fraction 0.58, in a cube of side (N/1000)^(1/3) (so the
sphere size does not depend on N); random positions relaxed by 300 sweeps of pairwise overlap removal (scipy cKDTree),
which leaves overlaps of a few % of a radius, like a confined DEM packing. Seeded, cached in --work.

Scenes
  perm   permeameter, fixed skeleton: p = p_in on ymin, 0 on ymax, other walls impermeable. First step: mesh, set-up
         (factorisation / preconditioner) and a cold solve (p = 0 start) with p_in = 1. Then STEADY steps with
         p_in(k) = 1 + 0.5 sin(2 pi k / 40) (as a slowly varying wave load), warm-started, no remesh.
  slow   oedometer, "consolidation": bottom at y = 0, top wall at y = H(t) = L (1 - eps(t)), side walls fixed,
         drained top only (p = 0 on ymax), eps(t_k) = eps_f (1 - exp(-k / tau)); sphere centres follow the affine
         compression plus a smooth non-affine field eps(t) * delta_i (delta_i ~ N(0, d^2) per component, clipped at
         3 d, d = mean diameter), so dV/dt drives the pressure. eps_f = 1 %, tau = S/4 steps, S steps.
  fast   the same oedometer, eps_f = 5 %, tau = S/5, S/5 steps... (see SCENES below): 10x the strain per step.

Options (each an engine, all stepped in lockstep on the same positions)
  reference      CHOLMOD direct solve (useSolver 3), remesh every step (mesh_update_interval 1)
  remesh sweep   CHOLMOD, mesh_update_interval 10, 100, 1000, 5000 (def_tolerance 0); def_tolerance 0.001, 0.01,
                 0.1 (mesh_update_interval 0, i.e. the strain criterion alone). An interval at least the scene's
                 length remeshes only at the first step (1000 and 5000 then coincide: kept to show it)
  solver sweep   Gauss-Seidel/SOR (useSolver 0, relax 1.9, tolerance = max|dp|/max|p| per sweep) and incomplete-
                 Cholesky preconditioned CG (useSolver 1, warm-started, tolerance = relative residual) at
                 tolerances 1e-3 ... 1e-9, on the remesh schedule mesh_update_interval = SOLVER_INTERVAL
  mixed          CHOLMOD with mixed_precision on (the factor in 32 bits, each solve refined in double from
                 the previous pressures until the estimated error < refinement_tolerance * the pressure spread):
                 at the default refinement_tolerance 1e-10 and at 1e-6; in the oedometers on the interval-10 and
                 defTolerance-0.01 schedules, and compared also with the double CHOLMOD on the same schedule
                 ("same mesh")
  multigrid      CG preconditioned by one BoomerAMG V-cycle (solver 'multigrid', warm-started, stopped when the
                 estimated error < refinement_tolerance * the pressure spread): 1e-4 ... 1e-10 on the permeameter,
                 1e-6 and 1e-10 in the oedometers on the solver sweeps' schedule
  accuracy       (--accuracy, its own table) the double CHOLMOD and multigrid at refinement_tolerance 1e-4 ... 1e-10
                 in both oedometers on the solver sweeps' schedule: each multigrid's pressure error (max over cells
                 over the spread of the direct solve's pressures) and force error (|F - F_ref|_2 / |F_ref|_2 over the
                 spheres) against the direct solve on the same mesh, max over all steps; its iterations and cost
  background     CHOLMOD with background_remesh on (the mesh is built on a second thread); the driver waits for it
                 before the next step, so the new mesh is always one step old (deterministic)

Cost: thread CPU time (time.thread_time) of the calling thread around engine.step(), with OMP_NUM_THREADS=1 and
OPENBLAS_NUM_THREADS=1, so other processes on the machine hardly matter and a background remesh thread is not
counted (its work is reported separately). perm: medians over --rounds rounds, the options in a rotated order each
round. Oedometers: one run, options interleaved step by step (every step, each option in turn, rotated), cost per
step = total CPU / steps (remeshes amortised).

Errors (against the reference, which has the same positions at every step)
  perm   G_error = |Qin + Qout| / |Qin| (boundary_flux is negative for inflow), flux error |Qin - Qin_ref| / |Qin_ref|,
         pressure error max_cells |p - p_ref| / p_in, force error |F - F_ref|_2 / |F_ref|_2 over spheres
  oedo   e_base: RMS over steps of (p_base - p_base_ref) / max p_base_ref, p_base = fluid force on the bottom wall
         / its area; e_mid: the same for the slice average at mid-height (every SAMPLE steps); e_force: RMS over
         sampled steps of |F - F_ref|_2 / |F_ref|_2 over spheres; conservation: sum_k |Q_top + dV/dt| / sum_k |dV/dt|
"""
import json
import math
import os
import subprocess
import sys
import time

os.environ.setdefault('OMP_NUM_THREADS', '1')
os.environ.setdefault('OPENBLAS_NUM_THREADS', '1')

import numpy as np  # noqa: E402
from pfv_testing.cli import option  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
BEGIN_MARK = '<!-- BEGIN tradeoffs output (generated by bench/tradeoffs.py; edits inside are overwritten) -->'
END_MARK = '<!-- END tradeoffs output -->'
ACCURACY_BEGIN_MARK = (
    '<!-- BEGIN tradeoffs accuracy output (generated by bench/tradeoffs.py --accuracy; edits inside are '
    'overwritten) -->'
)
ACCURACY_END_MARK = '<!-- END tradeoffs accuracy output -->'
PACKING_VERSION = 1
PHI = 0.58
VISCOSITY = 1.0
DT = 1e-3
SAMPLE = 5  # oedometer: slice pressure and forces every SAMPLE steps
SOLVER_INTERVAL = 100  # oedometer: remesh interval of the solver sweeps
TOLS = [1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9]
MULTIGRID = 4  # the solver code of solver='multigrid' here (YADE has no number for it)
# multigrid: refinement_tolerance, relative to the pressure spread (permeameter: all; oedometers: every other)
AMG_TOLS = [1e-4, 1e-6, 1e-8, 1e-10]
# scene: (steps, eps_f, tau as a fraction of steps)
SCENES = {'slow': (1000, 0.01, 0.25), 'fast': (200, 0.05, 0.2)}
QUICK_SCENES = {'slow': (200, 0.01, 0.25), 'fast': (60, 0.05, 0.2)}
# oedometer solver sweeps: (scene, size class) -> {useSolver: tolerances}
SOLVER_TOLS = {
    ('slow', 'small'): {0: TOLS, 1: [1e-3, 1e-6, 1e-9]},
    ('slow', 'large'): {0: [1e-3, 1e-5], 1: [1e-3]},
    ('fast', 'small'): {0: [1e-4, 1e-6, 1e-8], 1: [1e-4, 1e-6, 1e-8]},
    ('fast', 'large'): {0: [1e-4, 1e-6], 1: [1e-6]},
    ('slow', 'quick'): {0: [1e-3, 1e-6], 1: [1e-3, 1e-6]},
    ('fast', 'quick'): {0: [1e-4, 1e-6], 1: [1e-6]},
}


def log(*a):
    print('tradeoffs:', *a, flush=True)


# ---------------------------------------------------------------------------------------------------------- packing
def packing(n, work, seed=1, iters=300):
    path = os.path.join(work, f'packing_v{PACKING_VERSION}_n{n}_s{seed}.npy')
    if os.path.exists(path):
        d = np.load(path)
        return d[:, :3].copy(), d[:, 3].copy()
    from scipy.spatial import cKDTree

    rng = np.random.default_rng(seed)
    side = (n / 1000) ** (1 / 3)
    r0 = rng.uniform(0.8, 1.2, n)
    r = r0 * (PHI * side**3 / (4 / 3 * np.pi * np.sum(r0**3))) ** (1 / 3)
    x = rng.uniform(0, side, (n, 3))
    x = np.clip(x, r[:, None], side - r[:, None])
    rmax = r.max()
    for _ in range(iters):
        pairs = cKDTree(x).query_pairs(2 * rmax, output_type='ndarray')
        d = x[pairs[:, 1]] - x[pairs[:, 0]]
        dist = np.linalg.norm(d, axis=1)
        ov = r[pairs[:, 0]] + r[pairs[:, 1]] - dist
        m = ov > 0
        if not m.any():
            break
        u = d[m] / dist[m][:, None]
        disp = np.zeros_like(x)
        np.add.at(disp, pairs[m, 0], -0.5 * ov[m, None] * u)
        np.add.at(disp, pairs[m, 1], 0.5 * ov[m, None] * u)
        x = np.clip(x + 0.9 * disp, r[:, None], side - r[:, None])
    tmp = path + f'.{os.getpid()}.npy'
    np.save(tmp, np.c_[x, r])
    os.replace(tmp, path)
    return x, r


def solver_iterations(e):
    """What the last solve iterated: Gauss-Seidel sweeps, CG iterations or refinement passes."""
    return e.sweeps + e.cg_iterations + e.refinement_passes


def packing_stats(x, r):
    from scipy.spatial import cKDTree

    side = (len(r) / 1000) ** (1 / 3)
    pairs = cKDTree(x).query_pairs(2 * r.max(), output_type='ndarray')
    ov = r[pairs[:, 0]] + r[pairs[:, 1]] - np.linalg.norm(x[pairs[:, 1]] - x[pairs[:, 0]], axis=1)
    return {
        'side': side,
        'porosity': 1 - np.sum(4 / 3 * np.pi * r**3) / side**3,
        'max_overlap_over_r': float(np.max(ov / np.minimum(r[pairs[:, 0]], r[pairs[:, 1]]))),
        'mean_diameter': float(2 * r.mean()),
    }


# ---------------------------------------------------------------------------------------------------------- engines
def make_engine(
    pfv, solver=3, tol=1e-6, interval=1, def_tol=0.0, background=False, drained=(True, True), mixed=False, ref_tol=None
):
    e = pfv.Engine()
    e.mixed_precision = mixed
    e.mixed_precision_min_entries = 0  # with mixed: the 32-bit factor at the study's sizes too
    if ref_tol is not None:
        e.refinement_tolerance = ref_tol
    e.viscosity = VISCOSITY
    e.solver = {0: 'gauss_seidel', 1: 'conjugate_gradient', 3: 'cholesky', MULTIGRID: 'multigrid'}[solver]
    e.tolerance = tol
    if solver == MULTIGRID:  # its stopping rule is the refinement's, relative to the pressure spread
        e.refinement_tolerance = tol
    e.mesh_update_interval = interval
    e.def_tolerance = def_tol
    e.background_remesh = background
    e.bnd_is_pressure = [False, False, drained[0], drained[1], False, False]
    e.bnd_value = [0.0] * 6
    return e


def solver_name(s):
    return {0: 'GS', 1: 'PCG', 3: 'CHOLMOD', MULTIGRID: 'AMG-PCG'}[s]


def perm_configs(quick):
    tols = TOLS[::2] if quick else TOLS
    cfgs = [dict(name='CHOLMOD', family='CHOLMOD', solver=3, tol=0.0)]
    cfgs += [
        dict(name='CHOLMOD mixed precision', family='mixed', solver=3, tol=0.0, mixed=True),
        dict(
            name='CHOLMOD mixed precision, refinement 1e-06',
            family='mixed',
            solver=3,
            tol=0.0,
            mixed=True,
            ref_tol=1e-6,
        ),
    ]
    cfgs += [dict(name=f'GS {t:.0e}', family='GS', solver=0, tol=t) for t in tols]
    cfgs += [dict(name=f'PCG {t:.0e}', family='PCG', solver=1, tol=t) for t in tols]
    cfgs += [dict(name=f'AMG-PCG {t:.0e}', family='AMG-PCG', solver=MULTIGRID, tol=t) for t in AMG_TOLS]
    return cfgs


def oedo_configs(scene, n, quick):
    c = [dict(name='reference (CHOLMOD, remesh every step)', family='reference', solver=3, interval=1)]
    ints = [10, 100, 1000, 5000]
    c += [dict(name=f'CHOLMOD, interval {i}', family='interval', solver=3, interval=i) for i in ints]
    c += [
        dict(name=f'CHOLMOD, defTolerance {d:g}', family='defTolerance', solver=3, interval=0, def_tol=d)
        for d in (0.001, 0.01, 0.1)
    ]
    si = SOLVER_INTERVAL if scene == 'slow' else 10
    # Tight tolerances of the iterative solvers cost up to seconds per step on the large packing: there the sweep is
    # thinned (the small packing has the full one, and the permeameter every decade at both sizes).
    tols = SOLVER_TOLS[(scene, 'quick' if quick else ('large' if n >= 4000 else 'small'))]
    for s in (0, 1):
        c += [
            dict(name=f'{solver_name(s)} {t:.0e}, interval {si}', family=solver_name(s), solver=s, tol=t, interval=si)
            for t in tols[s]
        ]
    c += [
        dict(name=f'AMG-PCG {t:.0e}, interval {si}', family='AMG-PCG', solver=MULTIGRID, tol=t, interval=si)
        for t in AMG_TOLS[1::2]
    ]
    c += [
        dict(name='CHOLMOD mixed precision, interval 10', family='mixed', solver=3, interval=10, mixed=True),
        dict(
            name='CHOLMOD mixed precision, refinement 1e-06, interval 10',
            family='mixed',
            solver=3,
            interval=10,
            mixed=True,
            ref_tol=1e-6,
        ),
        dict(
            name='CHOLMOD mixed precision, defTolerance 0.01',
            family='mixed',
            solver=3,
            interval=0,
            def_tol=0.01,
            mixed=True,
        ),
    ]
    c += [dict(name='CHOLMOD, interval 10, background', family='background', solver=3, interval=10, background=True)]
    if scene == 'slow' and n < 4000:
        c += [
            dict(
                name=f'CHOLMOD, interval {si}, background', family='background', solver=3, interval=si, background=True
            )
        ]
    return c


# ---------------------------------------------------------------------------------------------------------- permeameter
def run_perm(pfv, n, work, rounds, quick):
    x, r = packing(n, work)
    side = (n / 1000) ** (1 / 3)
    walls = [0, side, 0, side, 0, side]
    steady = 20 if quick else 40
    cfgs = perm_configs(quick)
    p_in = [1.0] + [1 + 0.5 * math.sin(2 * math.pi * k / 40) for k in range(1, steady + 1)]
    ref = None
    res = {c['name']: dict(c, first=[], step=[], iters_first=None, iters_steady=[]) for c in cfgs}
    for rnd in range(rounds):
        order = cfgs[rnd % len(cfgs) :] + cfgs[: rnd % len(cfgs)]
        if ref is None:  # the reference runs first in round 0: its results are needed by the others
            order = [cfgs[0]] + [c for c in order if c is not cfgs[0]]
        for c in order:
            e = make_engine(
                pfv,
                solver=c['solver'],
                tol=c['tol'] or 1e-6,
                interval=0,
                mixed=c.get('mixed', False),
                ref_tol=c.get('ref_tol'),
            )
            rec = res[c['name']]
            times, errs = [], []
            for k, p in enumerate(p_in):
                e.bnd_value = [0, 0, p, 0, 0, 0]
                t0 = time.thread_time()
                e.step(x, r, walls, DT)
                times.append(time.thread_time() - t0)
                if rnd == 0:
                    q_in, q_out = e.boundary_flux(2), e.boundary_flux(3)
                    pr, f = e.pressure().copy(), e.forces()[:n].copy()
                    if c is cfgs[0]:
                        ref = ref or []
                        ref.append((q_in, pr, f))
                    rq, rp, rf = ref[k]
                    errs.append(
                        dict(
                            g_error=abs(q_in + q_out) / abs(q_in),
                            q_error=abs(q_in - rq) / abs(rq),
                            p_error=float(np.max(np.abs(pr - rp))) / p,
                            f_error=float(np.linalg.norm(f - rf) / np.linalg.norm(rf)),
                            iters=solver_iterations(e),
                        )
                    )
            rec['first'].append(times[0])
            rec['step'].append(float(np.median(times[1:])))
            if rnd == 0:
                rec['err_first'] = errs[0]
                rec['err_steady'] = {k: max(er[k] for er in errs[1:]) for k in errs[0]}
                rec['iters_first'] = errs[0]['iters']
                rec['iters_steady'] = float(np.mean([er['iters'] for er in errs[1:]]))
                rec['n_cells'] = e.n_cells()
            log(
                f'perm n={n} round {rnd} {c["name"]}: first {times[0]*1e3:.1f} ms, '
                f'step {np.median(times[1:])*1e3:.2f} ms'
            )
            del e
    for rec in res.values():
        rec['first_median'] = float(np.median(rec['first']))
        rec['step_median'] = float(np.median(rec['step']))
    return dict(
        scene='perm', n=n, steady_steps=steady, rounds=rounds, packing=packing_stats(x, r), configs=list(res.values())
    )


# ---------------------------------------------------------------------------------------------------------- oedometer
def record_step(engines, k, n, box, out):
    """After step k: each engine's base stress, flux balance (from the second step), and every SAMPLE steps its
    mid-height pressure and its sphere forces' distance to the reference's (engine 0), into the arrays of `out`."""
    side, height = box
    f_ref = None
    for j, e in enumerate(engines):
        f = e.forces()
        out['base'][j, k] = -f[n + 2, 1] / (side * side)
        if k > 0:
            q, v = e.boundary_flux(3), e.volume_rate_total()
            out['cons'][j] += (abs(q + v), abs(v))
        if k % SAMPLE == 0:
            out['mid'][j, k // SAMPLE] = e.average_slice_pressure(1, height / 2)
            if j == 0:
                f_ref = f[:n].copy()
            out['ferr'][j, k // SAMPLE] = np.linalg.norm(f[:n] - f_ref) / max(np.linalg.norm(f_ref), 1e-300)


def schedule(c):
    """The remesh schedule of a configuration: (interval, defTolerance)."""
    return (c['interval'], c.get('def_tol', 0.0))


def oedo_state(x0, delta, side, eps):
    """Positions, walls and height of the oedometer at settlement eps."""
    height = side * (1 - eps)
    x = x0 + eps * delta
    x[:, 1] = x0[:, 1] * (1 - eps) + eps * delta[:, 1]
    return x, [0, side, 0, height, 0, side], height


def run_oedo(pfv, scene, n, work, quick):
    x0, r = packing(n, work)
    side = (n / 1000) ** (1 / 3)
    steps, eps_f, tau_frac = (QUICK_SCENES if quick else SCENES)[scene]
    tau = tau_frac * steps
    d = 2 * r.mean()
    rng = np.random.default_rng(12345)
    delta = np.clip(rng.normal(0, d, x0.shape), -3 * d, 3 * d)
    cfgs = oedo_configs(scene, n, quick)
    engines = [
        make_engine(
            pfv,
            solver=c['solver'],
            tol=c.get('tol', 1e-6),
            interval=c['interval'],
            def_tol=c.get('def_tol', 0.0),
            background=c.get('background', False),
            drained=(False, True),
            mixed=c.get('mixed', False),
            ref_tol=c.get('ref_tol'),
        )
        for c in cfgs
    ]
    nc = len(cfgs)
    cpu = np.zeros((nc, steps))
    remeshed = np.zeros((nc, steps), bool)
    iters = np.zeros((nc, steps))
    base = np.zeros((nc, steps))
    mid = np.zeros((nc, (steps + SAMPLE - 1) // SAMPLE))
    ferr = np.zeros((nc, (steps + SAMPLE - 1) // SAMPLE))
    cons = np.zeros((nc, 2))
    strain_max = 0.0
    t_wall = time.time()
    for k in range(steps):
        eps = eps_f * (1 - math.exp(-k / tau))
        x, walls, height = oedo_state(x0, delta, side, eps)
        order = [0] + [j for j in [(k + i) % nc for i in range(nc)] if j != 0]
        if k % 2:  # rotate the reference's position too
            order = order[1:] + order[:1]
        for j in order:
            e = engines[j]
            if e.remesh_pending():
                e.wait_for_remesh()  # background remesh: adopted at this step, i.e. one step late (untimed wait)
            before = e.remesh_count
            t0 = time.thread_time()
            e.step(x, r, walls, DT)
            cpu[j, k] = time.thread_time() - t0
            if cfgs[j].get('background') and k > 0:
                remeshed[j, k] = e.remesh_pending()  # launched this step (adopted, uncounted, at the next)
            else:
                remeshed[j, k] = e.remesh_count != before
            iters[j, k] = solver_iterations(e)
        record_step(engines, k, n, (side, height), dict(base=base, cons=cons, mid=mid, ferr=ferr))
        strain_max = max(strain_max, eps_f / tau * math.exp(-k / tau))
        if k % max(1, steps // 10) == 0:
            log(f'{scene} n={n} step {k}/{steps} ({time.time() - t_wall:.0f} s)')
    pb, pm = np.max(np.abs(base[0])), np.max(np.abs(mid[0]))
    out = []
    for j, c in enumerate(cfgs):
        rec = dict(c)
        rec.update(
            cost=float(cpu[j].sum() / steps),
            remeshes=int(remeshed[j].sum()),
            remesh_cpu=float(cpu[j][remeshed[j]].sum() / steps),
            step_cpu_median=float(np.median(cpu[j][~remeshed[j]])) if (~remeshed[j]).any() else None,
            iters_mean=float(iters[j].mean()),
            iters_max=float(iters[j].max()),
            e_base=float(np.sqrt(np.mean((base[j] - base[0]) ** 2)) / pb),
            e_base_max=float(np.max(np.abs(base[j] - base[0])) / pb),
            e_mid=float(np.sqrt(np.mean((mid[j] - mid[0]) ** 2)) / pm),
            e_force=float(np.sqrt(np.mean(ferr[j] ** 2))),
            conservation=float(cons[j, 0] / cons[j, 1]),
            n_cells=engines[j].n_cells(),
        )
        out.append(rec)

    # Pure solver error: each solver run against the double CHOLMOD on the same remesh schedule.
    by_schedule = {
        schedule(c): j for j, c in enumerate(cfgs) if c['family'] in ('interval', 'defTolerance', 'reference')
    }
    for j, c in enumerate(cfgs):
        if c['family'] in ('GS', 'PCG', 'AMG-PCG', 'mixed') and schedule(c) in by_schedule:
            b = by_schedule[schedule(c)]
            out[j]['e_base_same_mesh'] = float(np.sqrt(np.mean((base[j] - base[b]) ** 2)) / pb)
    return dict(
        scene=scene,
        n=n,
        steps=steps,
        eps_f=eps_f,
        tau=tau,
        max_strain_rate_per_step=strain_max,
        packing=packing_stats(x0, r),
        p_base_peak=float(pb),
        p_mid_peak=float(pm),
        history=dict(base_ref=base[0][:: max(1, steps // 200)].tolist()),
        configs=out,
    )


# ---------------------------------------------------------------------------------------------------------- accuracy
def accuracy_errors(e, ref, n):
    """Pressure error over the reference's spread (max over cells) and force error on the spheres of engine e."""
    p, pr = e.pressure(), ref.pressure()
    f, fr = e.forces()[:n], ref.forces()[:n]
    spread, size = np.max(pr) - np.min(pr), np.linalg.norm(fr)
    if not (spread > 0 and size > 0):  # the first step: no volume rates, no pressure in a drained oedometer
        return 0.0, 0.0
    return float(np.max(np.abs(p - pr)) / spread), float(np.linalg.norm(f - fr) / size)


def run_accuracy(pfv, scene, n, work, quick):
    """The oedometer `scene` with the double CHOLMOD and multigrid at every AMG_TOLS, all on the solver sweeps'
    remesh schedule: each multigrid's pressure and force error against the direct solve on the same mesh, at every
    step, its iterations and its cost."""
    x0, r = packing(n, work)
    side = (n / 1000) ** (1 / 3)
    steps, eps_f, tau_frac = (QUICK_SCENES if quick else SCENES)[scene]
    tau = tau_frac * steps
    d = 2 * r.mean()
    delta = np.clip(np.random.default_rng(12345).normal(0, d, x0.shape), -3 * d, 3 * d)
    si = SOLVER_INTERVAL if scene == 'slow' else 10
    tols = [None] + AMG_TOLS
    engines = [
        make_engine(pfv, solver=3 if t is None else MULTIGRID, tol=t or 1e-6, interval=si, drained=(False, True))
        for t in tols
    ]
    cpu, iters, perr, ferr = (np.zeros((len(tols), steps)) for _ in range(4))
    for k in range(steps):
        x, walls, _ = oedo_state(x0, delta, side, eps_f * (1 - math.exp(-k / tau)))
        for j in [(k + i) % len(tols) for i in range(len(tols))]:
            t0 = time.thread_time()
            engines[j].step(x, r, walls, DT)
            cpu[j, k] = time.thread_time() - t0
            iters[j, k] = solver_iterations(engines[j])
        for j in range(1, len(tols)):
            perr[j, k], ferr[j, k] = accuracy_errors(engines[j], engines[0], n)
    configs = [
        dict(
            tol=t,
            cost=float(cpu[j].mean()),
            iters_mean=float(iters[j].mean()),
            iters_late=float(iters[j, steps // 2 :].mean()),
            p_error=float(perr[j].max()),
            f_error=float(ferr[j].max()),
            remeshes=int(engines[j].remesh_count),
        )
        for j, t in enumerate(tols)
    ]
    return dict(scene=f'accuracy_{scene}', n=n, steps=steps, interval=si, configs=configs)


def accuracy_report(parts, command):
    L = [f'Produced by `{command}`.', '']
    L.append(
        '| scene | N | solver | CPU ms/step | mean iterations (second half) | max pressure error / spread | '
        'max force error |'
    )
    L.append('|---|---|---|---|---|---|---|')
    for p in sorted(parts, key=lambda q: (q['scene'], q['n'])):
        title = ('slow consolidation' if p['scene'].endswith('slow') else 'fast deformation') + (
            f", {p['steps']} steps, interval {p['interval']}"
        )
        for c in p['configs']:
            name = 'CHOLMOD (reference)' if c['tol'] is None else f"multigrid, refinement_tolerance {c['tol']:.0e}"
            errors = '– | –' if c['tol'] is None else f"{fmt(c['p_error'])} | {fmt(c['f_error'])}"
            L.append(
                f"| {title} | {p['n']} | {name} | {c['cost'] * 1e3:.2f} | {c['iters_mean']:.1f} "
                f"({c['iters_late']:.1f}) | {errors} |"
            )
    L.append('')
    return '\n'.join(L)


# ---------------------------------------------------------------------------------------------------------- report
def pareto(points):
    """Indices of the non-dominated (cost, error) points, by increasing cost."""
    idx = sorted(range(len(points)), key=lambda i: (points[i][0], points[i][1]))
    front, best = [], math.inf
    for i in idx:
        if points[i][1] < best:
            front.append(i)
            best = points[i][1]
    return front


def fmt(x, digits=2):
    if x is None:
        return '–'
    if x == 0:
        return '0'
    return f'{x:.{digits}g}' if 1e-3 <= abs(x) < 1e4 else f'{x:.{max(digits - 1, 0)}e}'


def report(parts, command, quick):
    L = []
    perm = sorted([p for p in parts if p['scene'] == 'perm'], key=lambda p: p['n'])
    L.append(
        f'Produced by `{command}`'
        + (' (quick mode: smaller sizes, fewer steps; not for decisions)' if quick else '')
        + '.'
    )
    L.append('')
    L.append(
        'Packings: '
        + '; '.join(
            f"N = {p['n']}: side {p['packing']['side']:.3g}, porosity {p['packing']['porosity']:.3f}, "
            f"largest overlap {100 * p['packing']['max_overlap_over_r']:.1f} % of the smaller radius, "
            f"{p['configs'][0]['n_cells']} cells"
            for p in perm
        )
        + '.'
    )
    L.append('')
    for p in perm:
        L.append(f"### Permeameter, N = {p['n']} (medians of {p['rounds']} rounds)")
        L.append('')
        L.append(
            '| solver | first step: CPU ms (mesh + set-up + cold solve) | iterations | G_error | flux error | '
            'pressure error | force error | steady step: CPU ms | iterations | max G_error | max pressure error |'
        )
        L.append('|---|---|---|---|---|---|---|---|---|---|---|')
        for c in p['configs']:
            ef, es = c['err_first'], c['err_steady']
            L.append(
                f"| {c['name']} | {c['first_median'] * 1e3:.1f} | {c['iters_first']} | {fmt(ef['g_error'])} | "
                f"{fmt(ef['q_error'])} | {fmt(ef['p_error'])} | {fmt(ef['f_error'])} | "
                f"{c['step_median'] * 1e3:.2f} | {c['iters_steady']:.0f} | {fmt(es['g_error'])} | "
                f"{fmt(es['p_error'])} |"
            )
        L.append('')
        pts = [(c['step_median'], max(c['err_steady']['p_error'], 1e-12)) for c in p['configs']]
        L.append(
            'Pareto front (steady-step cost, max pressure error): '
            + ' → '.join(
                f"{p['configs'][i]['name']} ({pts[i][0] * 1e3:.2f} ms, {fmt(pts[i][1]) if pts[i][1] > 1e-12 else '0'})"
                for i in pareto(pts)
            )
            + '.'
        )
        L.append('')
    for scene in ('slow', 'fast'):
        for p in sorted([q for q in parts if q['scene'] == scene], key=lambda q: q['n']):
            title = 'slow consolidation' if scene == 'slow' else 'fast deformation'
            L.append(
                f"### Oedometer, {title}, N = {p['n']}: {p['steps']} steps, settlement {100 * p['eps_f']:g} %, "
                f"tau = {p['tau']:g} steps (largest strain per step {p['max_strain_rate_per_step']:.2g})"
            )
            L.append('')
            L.append(
                '| option | remeshes | CPU ms/step (amortised) | of which remesh steps | mean iterations | '
                'e_base (RMS) | e_base (max) | e_mid | e_force | conservation |'
            )
            L.append('|---|---|---|---|---|---|---|---|---|---|')
            for c in p['configs']:
                extra = f" (same mesh: {fmt(c['e_base_same_mesh'])})" if 'e_base_same_mesh' in c else ''
                L.append(
                    f"| {c['name']} | {c['remeshes']} | {c['cost'] * 1e3:.2f} | {c['remesh_cpu'] * 1e3:.2f} | "
                    f"{c['iters_mean']:.0f} | {fmt(c['e_base'])}{extra} | {fmt(c['e_base_max'])} | "
                    f"{fmt(c['e_mid'])} | {fmt(c['e_force'])} | {fmt(c['conservation'])} |"
                )
            L.append('')
            pts = [(c['cost'], max(c['e_base'], 1e-12)) for c in p['configs']]
            front = pareto(pts)
            L.append(
                'Pareto front (cost, e_base): '
                + ' → '.join(
                    f"{p['configs'][i]['name']} ({pts[i][0] * 1e3:.2f} ms, "
                    f"{fmt(pts[i][1]) if pts[i][1] > 1e-12 else '0'})"
                    for i in front
                )
                + '.'
            )
            L.append('')
    L.append('### Pareto fronts, all scenes')
    L.append('')
    L.append(
        'Permeameter: steady-step cost against max pressure error / p_in; oedometers: amortised cost per step '
        'against e_base. Errors below 1e-12 count as 1e-12 (the reference is 0).'
    )
    L.append('')
    L.append('| scene | N | option | CPU ms/step | error |')
    L.append('|---|---|---|---|---|')
    titles = {'perm': 'permeameter', 'slow': 'slow consolidation', 'fast': 'fast deformation'}
    for scene in ('perm', 'slow', 'fast'):
        for p in sorted([q for q in parts if q['scene'] == scene], key=lambda q: q['n']):
            if scene == 'perm':
                pts = [(c['step_median'], max(c['err_steady']['p_error'], 1e-12)) for c in p['configs']]
            else:
                pts = [(c['cost'], max(c['e_base'], 1e-12)) for c in p['configs']]
            for i in pareto(pts):
                L.append(
                    f"| {titles[scene]} | {p['n']} | {p['configs'][i]['name']} | {pts[i][0] * 1e3:.2f} | "
                    f"{fmt(pts[i][1]) if pts[i][1] > 1e-12 else '0'} |"
                )
    L.append('')
    return '\n'.join(L)


def figure(parts, path):
    import matplotlib

    matplotlib.use('Agg')
    import matplotlib.pyplot as plt

    panels = [
        ('perm', 'first', 'permeameter, first solve (mesh + set-up + cold solve)', 'G_error = |Qin + Qout| / |Qin|'),
        ('perm', 'steady', 'permeameter, steady step (varying inlet pressure)', 'max pressure error / p_in'),
        ('slow', None, 'oedometer, slow consolidation', 'e_base (RMS / peak base pressure)'),
        ('fast', None, 'oedometer, fast deformation', 'e_base (RMS / peak base pressure)'),
    ]
    colours = {
        'CHOLMOD': 'k',
        'reference': 'k',
        'GS': 'tab:blue',
        'PCG': 'tab:orange',
        'interval': 'tab:green',
        'defTolerance': 'tab:red',
        'background': 'tab:purple',
        'mixed': 'tab:brown',
        'AMG-PCG': 'tab:cyan',
    }
    sizes = sorted({p['n'] for p in parts})
    markers = ['o', 's', '^', 'D']
    fig, axes = plt.subplots(2, 2, figsize=(11, 8))
    for ax, (scene, kind, title, ylabel) in zip(axes.ravel(), panels):
        data = []
        for si, n in enumerate(sizes):
            for p in (q for q in parts if q['scene'] == scene and q['n'] == n):
                for c in p['configs']:
                    if scene == 'perm':
                        fam = c.get('family', c['name'].split()[0])
                        pt = (
                            (c['first_median'] if kind == 'first' else c['step_median']) * 1e3,
                            c['err_first']['g_error'] if kind == 'first' else c['err_steady']['p_error'],
                        )
                    else:
                        fam, pt = c['family'], (c['cost'] * 1e3, c['e_base'])
                    data.append((si, n, fam, pt))
        positive = [d[3][1] for d in data if d[3][1] > 0]
        floor = 10 ** math.floor(math.log10(min(positive))) / 10 if positive else 1e-16
        for si, n in enumerate(sizes):
            pts = [(d[3][0], max(d[3][1], floor)) for d in data if d[0] == si]
            for d in (d for d in data if d[0] == si):
                col = colours.get(d[2], 'grey')
                ax.loglog(
                    d[3][0], max(d[3][1], floor), markers[si], color=col, ms=5, alpha=0.85, mfc='none' if si else col
                )
            if pts:
                front = pareto(pts)
                ax.loglog(
                    [pts[i][0] for i in front],
                    [pts[i][1] for i in front],
                    '-',
                    color='grey',
                    lw=0.8,
                    label=f'Pareto front, N = {n} ({"filled" if si == 0 else "open"} {markers[si]})',
                )
        ax.axhline(floor, color='grey', ls=':', lw=0.6)
        ax.text(
            0.01,
            0.01,
            'on the dotted line: error exactly 0 (the reference)',
            transform=ax.transAxes,
            fontsize=6,
            color='grey',
        )
        ax.set_title(title, fontsize=9)
        ax.set_xlabel('CPU ms' + ('' if kind == 'first' else ' per step'), fontsize=8)
        ax.set_ylabel(ylabel, fontsize=8)
        ax.grid(True, which='major', alpha=0.3)
        ax.legend(fontsize=7, loc='upper right')
    handles = [plt.Line2D([], [], marker='o', ls='', color=v, label=k) for k, v in colours.items() if k != 'CHOLMOD']
    handles[0] = plt.Line2D([], [], marker='o', ls='', color='k', label='CHOLMOD (direct); reference')
    handles[3] = plt.Line2D([], [], marker='o', ls='', color=colours['interval'], label='CHOLMOD, remesh interval')
    handles[4] = plt.Line2D([], [], marker='o', ls='', color=colours['defTolerance'], label='CHOLMOD, defTolerance')
    handles[5] = plt.Line2D([], [], marker='o', ls='', color=colours['background'], label='CHOLMOD, background remesh')
    handles[6] = plt.Line2D([], [], marker='o', ls='', color=colours['mixed'], label='CHOLMOD, mixed precision')
    handles[7] = plt.Line2D([], [], marker='o', ls='', color=colours['AMG-PCG'], label='CG + BoomerAMG (multigrid)')
    fig.legend(handles=handles, loc='lower center', ncol=4, fontsize=8)
    fig.tight_layout(rect=(0, 0.07, 1, 1))
    os.makedirs(os.path.dirname(path), exist_ok=True)
    fig.savefig(path, dpi=72)
    plt.close(fig)


def write_report(path, text, marks=(BEGIN_MARK, END_MARK)):
    begin, end = marks
    block = begin + '\n\n' + text + '\n' + end + '\n'
    old = open(path).read() if os.path.exists(path) else ''
    if begin in old and end in old:
        head, rest = old.split(begin, 1)
        new = head + block + rest.split(end, 1)[1].lstrip('\n')
    else:
        new = (old + '\n' if old else '# Speed and accuracy trade-offs\n\n') + block
    with open(path, 'w') as f:
        f.write(new)


# ---------------------------------------------------------------------------------------------------------- main
def measure(todo, sizes, work, rounds, quick):
    """Runs the parts in child processes, --jobs at a time; returns 1 if one failed."""
    for n in sizes:
        packing(n, work)
    jobs = option(sys.argv[1:], 'jobs', 1)
    env = dict(os.environ, OMP_NUM_THREADS='1', OPENBLAS_NUM_THREADS='1')
    running, pending = [], list(todo)  # largest first: the biggest task starts at once
    while pending or running:
        while pending and len(running) < jobs:
            s, n = pending.pop(0)
            args = [
                sys.executable,
                os.path.abspath(__file__),
                f'--part={s}:{n}',
                f'--work={work}',
                f'--rounds={rounds}',
            ] + (['--quick'] if quick else [])
            log('start', s, n)
            running.append((subprocess.Popen(args, env=env), s, n))
        time.sleep(1)
        for item in list(running):
            if item[0].poll() is not None:
                running.remove(item)
                if item[0].returncode:
                    log(f'part {item[1]}:{item[2]} failed with exit code {item[0].returncode}')
                    return 1
    return 0


def main():
    quick = option(sys.argv[1:], 'quick', False)
    work = option(sys.argv[1:], 'work', '/tmp/trade')
    os.makedirs(work, exist_ok=True)
    sizes = [int(s) for s in option(sys.argv[1:], 'sizes', '250,1000' if quick else '1000,5000').split(',')]
    rounds = option(sys.argv[1:], 'rounds', 2 if quick else 3)
    part = option(sys.argv[1:], 'part', '')
    if part:
        import pfv

        pfv.set_num_threads(1)
        scene, n = part.split(':')
        n = int(n)
        if scene.startswith('accuracy_'):
            res = run_accuracy(pfv, scene[len('accuracy_') :], n, work, quick)
        else:
            res = run_perm(pfv, n, work, rounds, quick) if scene == 'perm' else run_oedo(pfv, scene, n, work, quick)
        res['quick'] = quick
        with open(os.path.join(work, f'part_{scene}_{n}{"_quick" if quick else ""}.json'), 'w') as f:
            json.dump(res, f)
        return 0
    accuracy = option(sys.argv[1:], 'accuracy', False)
    scenes = ('accuracy_slow', 'accuracy_fast') if accuracy else ('slow', 'fast', 'perm')
    tasks = [(s, n) for n in sorted(sizes, reverse=True) for s in scenes]
    todo = [(s, int(n)) for s, n in (t.split(':') for t in option(sys.argv[1:], 'tasks', '').split(',') if t)] or tasks
    if not option(sys.argv[1:], 'report-only', False) and measure(todo, sizes, work, rounds, quick):
        return 1
    parts = []
    for s, n in tasks:
        with open(os.path.join(work, f'part_{s}_{n}{"_quick" if quick else ""}.json')) as f:
            parts.append(json.load(f))
    command = 'PYTHONPATH=build/python /usr/bin/python3.11 bench/tradeoffs.py ' + ' '.join(
        a for a in sys.argv[1:] if not a.startswith('--report-only')
    )
    out = option(sys.argv[1:], 'out', '')
    if accuracy:
        text = accuracy_report(parts, command.strip())
        print(text)
        if out:
            write_report(out, text, (ACCURACY_BEGIN_MARK, ACCURACY_END_MARK))
        return 0
    text = report(parts, command.strip(), quick)
    print(text)
    if out:
        write_report(out, text)
        fig = option(
            sys.argv[1:],
            'figure',
            os.path.join(os.path.dirname(out) or '.', 'figures', 'tradeoffs_quick.png' if quick else 'tradeoffs.png'),
        )
        figure(parts, fig)
        log('wrote', out, 'and', fig)
    return 0


if __name__ == '__main__':
    sys.exit(main())
