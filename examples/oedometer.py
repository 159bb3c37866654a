# -*- coding: utf-8 -*-
"""Oedometer (1-D consolidation) with the DEM-PFV coupling, compared with Terzaghi's theory.

    yade-double -n -x examples/oedometer.py [--quick] [--engine=pfv|yade] [--nonlinear]
                                            [--drainage=top|both] [--out=DIR] [--set=NAME=VALUE ...]
    yade-double examples/oedometer.py                  # same, with the GUI: controller, 3D view, live U and p_mid plots
    xvfb-run -a yade-double -x examples/oedometer.py --quick   # the GUI on a virtual display, leaves at the end
    yade-double -n -x examples/oedometer.py --compare=DIR_A,DIR_B [--out=DIR]   # plot two runs together

Thesis section 4.4 (Terzaghi consolidation of an oedometer sample). The script

1. prepares a dense packing (particle growth under a TriaxialStressController, then friction raised), switches to
   oedometric conditions (rigid lateral walls, fixed bottom, stress-controlled top wall) and measures the oedometric
   modulus E_oed from a dry load-unload-reload cycle of the same stress increment as the consolidation load.
   This dry part does not involve the fluid: it is saved in PFV_CACHE_DIR (or /tmp/pfv-oedometer-cache) and every
   later run with the same preparation parameters, whatever the engine, starts from the IDENTICAL saved state;
2. switches the flow engine on (PFV's by default, YADE's built-in one with --engine=yade) and measures the hydraulic
   conductivity K from one step of a permeameter (pressure dp on the bottom, 0 on the top, spheres at rest);
3. loads the top wall by `load` and records settlement and excess pore pressure against time. Drainage:
   --drainage=top (default, YADE's example): drained top wall, impermeable bottom, drainage length L = H;
   --drainage=both (the thesis): drained top and bottom, L = H/2. That makes the consolidation 4 times faster
   for the same viscosity, hence 4 times closer to the elastic waves (t_c / t_wave = 18 with --quick): raise the
   viscosity 4 times (--set=viscosity=40 with --quick; 16 times more steps) to compare with Terzaghi on equal terms.
   The fluid forces act on the wall bodies too, so the bottom wall reads the total stress (effective + pore);
4. compares with Terzaghi's series solution using the measured C_v = K E_oed / gamma_w:
   U(T_v) (settlement / dry settlement under the same increment) and isochrones p(z, T_v), and prints the error
   figures: max |U_sim - U_theory| and the RMS isochrone pressure error normalised by the load. With each
   isochrone it records the increment of the effective stress sigma'_yy in the same slices (YADE's per-particle
   stresses, thesis 2.18): pore pressure plus that increment is the load along the height (claim 18).

With --nonlinear the load is 200 kPa (thesis 4.4.2): the dry secant modulus under that load and the conductivity
measured again at the end give C_v,final, and U(T_v) is compared with both the initial and the final C_v.

--set overrides one parameter of the tables below (JSON value), e.g. --set=viscosity=20 --set=zeta=0.5.
Results with both engines, and why the time step is what it is: doc/validation.md.

Outputs in --out (default ./oedometer-<engine>[-quick][-nonlinear]): timeseries.csv, isochrones.csv, summary.json,
oedometer.png. The exit status is 0 when the run completes (the thresholds are in
tests/yade/examples/test_oedometer_quick.py).
Pressures are piezometric (no gravity anywhere in this example).
"""
import hashlib
import json
import math
import os
import sys
import tempfile
import time

# ------------------------------------------------------------------------------------------------------------
# Parameters (SI units). Thesis Table 4.1: 5000 grains in a 0.1 m cube, E = 15 MPa, k_t/k_n = 0.5, load 5 kPa,
# mu = 250 Pa.s. The full size here keeps 5000 grains and the 0.1 m cube; the viscosity is much lower than the
# thesis' so that the consolidation takes tens of thousands of steps instead of millions: the coupled time step is
# limited by dt_MV = pi rho d^2 / (1200 mu) (thesis 4.20), 50 times smaller than the DEM limit at mu = 250, and the
# number of steps to a given T_v grows like mu^2 once dt_MV rules. Consolidation stays slow compared with the elastic
# waves: t(T_v = 1) / t_wave (printed) is ~70 (quick) and ~110 (full); the thesis' numbers give ~40.
# ------------------------------------------------------------------------------------------------------------
FULL = dict(
    num_spheres=5000,  # number of spheres
    viscosity=5.0,  # fluid dynamic viscosity mu [Pa.s]
    load=5.0e3,  # consolidation load: increment of the vertical stress on the top wall [Pa]
    Tv_end=1.5,  # run the consolidation until this time factor
)
QUICK = dict(num_spheres=1000, viscosity=10.0, load=5.0e3, Tv_end=1.0)
NONLINEAR_LOAD = 200.0e3  # --nonlinear: thesis 4.4.2
NONLINEAR_TV_END = 2.0  # --nonlinear runs longer: the final state gives K_final and the coupled final strain
# --nonlinear: the sample compacts by ~5 %, its conductivity falls by ~30 % and the collective viscous limit
# with it; with zeta = 0.8 both engines blew up near T_v = 1.5.
NONLINEAR_ZETA = 0.5
COMMON = dict(
    box=0.1,  # side of the initial cube [m]
    rRelFuzz=0.2,  # "slightly polydisperse": radii r_mean (1 +- 0.2)
    seed=1,  # makeCloud seed
    young=15.0e6,  # contact modulus E: k_n = 2 E R1 R2 / (R1 + R2) (thesis 4.1)
    poisson=0.5,  # k_t / k_n (thesis 4.2, a = 0.5)
    density=2600.0,  # grain density [kg/m3]
    compaction_friction=3.0,  # friction angle during the isotropic compaction [deg] (dense sample)
    friction=30.0,  # friction angle for the oedometer [deg]
    sigma0=10.0e3,  # isotropic compaction stress, then initial vertical stress [Pa]
    gamma_w=1.0e4,  # unit weight of the fluid rho_f g [N/m3]: K = kappa gamma_w / mu
    zeta=0.8,  # coupled time step = zeta * the combined viscous and P-wave limit (see coupled_time_step)
    viscous_factor=0.5,  # the viscous limit is taken as viscous_factor * dt_MV: on the quick packing both
    # engines blow up above ~0.5 dt_MV (collective pore-pressure modes, stiffer than the
    # single-particle drag behind the thesis' beta = 400; see doc/validation.md)
    perm_dp=1.0,  # permeameter pressure drop [Pa] (tiny compared with sigma0)
    mesh_update_interval=1000,  # remesh the pores every so many steps (both engines)
    isochrones=(0.02, 0.05, 0.1, 0.2, 0.5, 1.0),  # T_v of the recorded pressure profiles
    profile_points=10,  # heights of a profile, at (i + 0.5) / n of the height
    slice_grid=6,  # a slice average is the mean pressure over grid x grid points of the horizontal slice
    dry_damping=0.2,  # NewtonIntegrator damping of the dry phases; the coupled phase has none
    wall_speed=1e3,  # top wall speed limit during consolidation, in dry settlement / t(T_v = 1)
)
CACHE_VERSION = 1

# ------------------------------------------------------------------------------------------------------------
from yade import O, utils, runtime  # noqa: E402
from yade.wrapper import (  # noqa: E402
    Bo1_Box_Aabb,
    Bo1_Sphere_Aabb,
    ForceResetter,
    FrictMat,  # noqa: E402
    GlobalStiffnessTimeStepper,
    Ig2_Box_Sphere_ScGeom,
    Ig2_Sphere_Sphere_ScGeom,
    InsertionSortCollider,
    InteractionLoop,
    Ip2_FrictMat_FrictMat_FrictPhys,
    Law2_ScGeom_FrictPhys_CundallStrack,
    NewtonIntegrator,
    TriaxialStressController,
    PyRunner,
    Sphere,
)
from yade import pack  # noqa: E402
import numpy as np  # noqa: E402
from pfv import diagnostics  # noqa: E402

XMIN, XMAX, YMIN, YMAX, ZMIN, ZMAX = range(6)  # aabbWalls order = FlowEngine.wallIds order
BOTTOM, TOP = YMIN, YMAX  # the vertical axis is y (as in YADE's example)
HEADLESS = bool(getattr(runtime.opts, 'nogui', True)) or not getattr(runtime, 'hasDisplay', False)


def log(*args):
    print('oedometer:', *args, flush=True)


def advance(steps):
    """O.run(steps) to the end. With the GUI, YADE runs this script in the Qt main thread: waiting in O.run(n, True)
    would freeze the 3D view, the controller and the live plots until the script ends. So the steps run in YADE's
    background thread (exactly the same steps) while the main thread keeps the GUI alive. Pressing Stop in the
    controller ends the script (it cannot tell a pause from a failed step)."""
    if HEADLESS:
        O.run(steps, True)
        return
    from PyQt5.QtWidgets import QApplication

    target = O.iter + steps
    O.run(steps)
    while O.running:
        QApplication.processEvents()
        time.sleep(0.01)
    if O.iter < target:
        raise RuntimeError(
            'oedometer: the run stopped at iteration %d before %d (Stop pressed, or a step failed)' % (O.iter, target)
        )


# ---------------------------------------------------------------- Terzaghi -----------------------------------
_M = (2 * np.arange(4000) + 1) * np.pi / 2


def terzaghi_U(Tv):
    """Average degree of consolidation U(T_v) = 1 - sum 2/M^2 exp(-M^2 T_v)."""
    Tv = np.atleast_1d(np.asarray(Tv, dtype=float))
    return 1 - (2 / _M[None, :] ** 2 * np.exp(-np.outer(np.maximum(Tv, 0), _M**2))).sum(axis=1)


def terzaghi_p(zeta, Tv):
    """Excess pore pressure / load at zeta = distance from the drained face / drainage length L."""
    zeta = np.atleast_1d(np.asarray(zeta, dtype=float))
    if Tv <= 0:
        return np.ones_like(zeta)
    terms = 2 / _M[None, :] * np.sin(np.outer(zeta, _M)) * np.exp(-_M[None, :] ** 2 * Tv)
    return terms.sum(axis=1)


class Terzaghi:
    """Terzaghi's solution for this sample: height H, C_v, drainage 'top' (L = H) or 'both' (L = H / 2).

    delta > 0 moves each drained face by delta into the sample: the pore cells next to a drained wall take the wall's
    pressure, and they reach down to the centres of the spheres touching it (about one mean radius). That layer
    then drains at once and the rest consolidates over L - delta (the 'dryFraction' of YADE's example)."""

    def __init__(self, drainage, H, Cv, delta=0.0):
        self.drainage, self.H, self.Cv, self.delta = drainage, H, Cv, delta
        faces = 2 if drainage == 'both' else 1
        self.dry = faces * delta / H
        self.L = (H - faces * delta) / faces

    def U(self, t):
        return self.dry + (1 - self.dry) * float(terzaghi_U(self.Cv * t / self.L**2)[0])

    def p(self, rel, t):
        """p / load at height rel * H above the bottom."""
        z = rel * self.H
        if self.drainage == 'top':
            d = self.H - self.delta - z
        else:
            d = min(z - self.delta, self.H - self.delta - z)
        if d <= 0:
            return 0.0
        return float(terzaghi_p([d / self.L], self.Cv * t / self.L**2)[0])


class VariableK:
    """Terzaghi's problem with a conductivity that falls with the compaction (the --nonlinear reference).

    K falls linearly with the local strain from K_init (before the load) to K_final (measured after the full load),
    at the constant secant modulus: with w = excess pressure / load the local strain is (1 - w) times the final one, so
    dw/dt = d/dz (c(w) dw/dz), c(w) = C_v,init (1 + (r - 1)(1 - w)), r = C_v,final / C_v,init; drained face(s) w = 0,
    w = 1 at t = 0. Small strain (fixed height H). Finite volumes (n cells over the drainage length), explicit steps
    of a fifth of the diffusive limit; profiles are kept at the requested times. With r = 1 it is Terzaghi's series
    to 2e-4 in U (n = 80)."""

    def __init__(self, drainage, H, cv_init, cv_final, times, n=80):
        self.drainage, self.H = drainage, H
        L = H if drainage == 'top' else H / 2
        dz, r = L / n, cv_final / cv_init
        w = np.ones(n)
        dt_max = 0.2 * dz * dz / max(cv_init, cv_final)
        t, self.times, self.profiles = 0.0, [], []
        for target in sorted(set(float(x) for x in times)):
            while t < target - 1e-15:
                dt = min(dt_max, target - t)
                c = cv_init * (1 + (r - 1) * (1 - w))
                flux = np.empty(n + 1)  # at the faces, towards the drained face (index 0)
                flux[0] = c[0] * w[0] / (dz / 2)
                flux[1:n] = 0.5 * (c[:-1] + c[1:]) * (w[1:] - w[:-1]) / dz
                flux[n] = 0.0  # impermeable bottom (top drainage) or the plane of symmetry (both)
                w = w + dt * (flux[1:] - flux[:-1]) / dz
                t += dt
            self.times.append(target)
            self.profiles.append(w.copy())
        self.d = (np.arange(n) + 0.5) * dz  # distance of the cell centres from the drained face

    def _w(self, t):
        return self.profiles[int(np.argmin(np.abs(np.asarray(self.times) - t)))]

    def U(self, t):
        return float(1 - self._w(t).mean())

    def p(self, rel, t):
        """p / load at height rel * H above the bottom."""
        d = (1 - rel) * self.H if self.drainage == 'top' else min(rel, 1 - rel) * self.H
        return float(np.interp(d, np.concatenate([[0.0], self.d]), np.concatenate([[0.0], self._w(t)])))


def variable_k_errors(s, rows, iso):
    """The --nonlinear run against VariableK (its own K_init, K_final, E_oed secant): U_theory_variable_K in the rows,
    error figures returned (same window as the others)."""
    ref = VariableK(
        s['drainage'],
        s['H0'],
        s['K'] * s['E_oed_secant'] / s['parameters']['gamma_w'],
        s['Cv_final'],
        [r['t'] for r in rows] + [r['Tv'] * s['t_Tv1'] for r in iso],
    )
    for r in rows:
        r['U_theory_variable_K'] = ref.U(r['t'])
    win = [r for r in rows if r['Tv'] >= s['error_window_Tv_min']]
    iso_win = [r for r in iso if r['Tv'] >= s['error_window_Tv_min']]
    e_iso = [r['p_over_load'] - ref.p(r['z_over_H'], r['Tv'] * s['t_Tv1']) for r in iso_win]
    return dict(
        U_max_abs_error_variable_K=max(abs(r['U_sim'] - r['U_theory_variable_K']) for r in win),
        isochrone_rms_error_variable_K=math.sqrt(sum(e * e for e in e_iso) / len(e_iso)),
    )


# ---------------------------------------------------------------- options -----------------------------------
def parse_args(argv):
    opts = dict(quick=False, engine='pfv', nonlinear=False, drainage='top', out=None, compare=None, set={})
    for a in argv:
        if a == '--quick':
            opts['quick'] = True
        elif a == '--nonlinear':
            opts['nonlinear'] = True
        elif a.startswith('--engine='):
            opts['engine'] = a.split('=', 1)[1]
        elif a.startswith('--drainage='):
            opts['drainage'] = a.split('=', 1)[1]
        elif a.startswith('--out='):
            opts['out'] = a.split('=', 1)[1]
        elif a.startswith('--set='):  # override a parameter: --set=viscosity=5
            k, v = a.split('=', 2)[1:]
            opts['set'][k] = json.loads(v)
        elif a.startswith('--compare='):
            opts['compare'] = a.split('=', 1)[1].split(',')
        elif a.endswith('.py') and not a.startswith('-'):
            continue  # yade may leave the script name in argv
        else:
            raise SystemExit('oedometer: unknown argument %r (see the docstring)' % a)
    if opts['engine'] not in ('pfv', 'yade'):
        raise SystemExit('oedometer: --engine must be pfv or yade')
    if opts['drainage'] not in ('top', 'both'):
        # Not 'bottom' (impermeable loaded wall): TriaxialStressController servoes the wall with the contact stiffness
        # only; against the (incompressible) fluid under an impermeable wall its gain is far too high and the wall
        # chatters (pressure +-300 x the load, tried).
        raise SystemExit('oedometer: --drainage must be top or both')
    return opts


def parameters(opts):
    P = dict(COMMON)
    P.update(QUICK if opts['quick'] else FULL)
    if opts['nonlinear']:
        P['load'] = NONLINEAR_LOAD
        P['Tv_end'] = NONLINEAR_TV_END
        P['zeta'] = NONLINEAR_ZETA
    P['small_load'] = (QUICK if opts['quick'] else FULL)['load']  # increment of the dry E_oed cycle
    P['drainage'] = opts['drainage']
    for k, v in opts['set'].items():
        if k not in P:
            raise SystemExit('oedometer: --set: unknown parameter %r' % k)
        P[k] = v
    return P


# ---------------------------------------------------------------- dry preparation ---------------------------
def cache_dir():
    return os.environ.get('PFV_CACHE_DIR') or os.path.join(tempfile.gettempdir(), 'pfv-oedometer-cache')


def prep_key(P):
    keys = (
        'num_spheres',
        'box',
        'rRelFuzz',
        'seed',
        'young',
        'poisson',
        'density',
        'compaction_friction',
        'friction',
        'sigma0',
        'small_load',
        'dry_damping',
    )
    text = json.dumps({k: P[k] for k in keys}, sort_keys=True) + ' v%d' % CACHE_VERSION
    return 'oedo_n%d_%s' % (P['num_spheres'], hashlib.sha256(text.encode()).hexdigest()[:12])


def write_json(path, data):
    """Atomic write: concurrent runs never read a half-written file."""
    fd, tmp = tempfile.mkstemp(dir=os.path.dirname(path), prefix='.tmp-', suffix='.json')
    with os.fdopen(fd, 'w') as f:
        json.dump(data, f, indent=1)
    os.replace(tmp, path)


def wall_y(i):
    return O.bodies[i].state.pos[1]


def height():
    return wall_y(TOP) - wall_y(BOTTOM)


def area():
    return (O.bodies[XMAX].state.pos[0] - O.bodies[XMIN].state.pos[0]) * (
        O.bodies[ZMAX].state.pos[2] - O.bodies[ZMIN].state.pos[2]
    )


def top_stress():
    """Compressive vertical stress the top wall receives (contacts + fluid), >0 [Pa]."""
    return O.forces.f(TOP)[1] / area()


def bottom_stress():
    """Compressive vertical stress on the bottom wall (contacts + fluid), >0 [Pa]."""
    return -O.forces.f(BOTTOM)[1] / area()


def dem_engines(triax, newton):
    return [
        ForceResetter(),
        InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Box_Aabb()]),
        InteractionLoop(
            [Ig2_Sphere_Sphere_ScGeom(), Ig2_Box_Sphere_ScGeom()],
            [Ip2_FrictMat_FrictMat_FrictPhys()],
            [Law2_ScGeom_FrictPhys_CundallStrack()],
            label='iloop',
        ),
        GlobalStiffnessTimeStepper(active=1, timeStepUpdateInterval=100, timestepSafetyCoefficient=0.8),
        triax,
        newton,
    ]


def settle(triax, goal, P, tol=0.005, unb=0.01, chunk=200, max_iter=400000):
    """Servo the top wall to vertical stress `goal` (dry, damped) until stress and unbalanced force settle."""
    triax.goal2 = -goal
    start = O.iter
    while True:
        advance(chunk)
        if abs(top_stress() - goal) < tol * P['small_load'] and utils.unbalancedForce() < unb:
            # the wall stress can pass through the goal while the packing still moves: confirm on a second chunk
            h = height()
            advance(chunk)
            if (
                abs(height() - h) < 1e-3 * P['small_load'] / P['young'] * h
                and abs(top_stress() - goal) < tol * P['small_load']
            ):
                return
        if O.iter - start > max_iter:
            raise RuntimeError('oedometer: the dry sample did not settle at %g Pa in %d iterations' % (goal, max_iter))


def prepare(P):
    """Dense packing + dry oedometric cycle; saved once, then reloaded bit for bit by every run."""
    d = cache_dir()
    base = os.path.join(d, prep_key(P))
    state, meta_path = base + '.bin.gz', base + '.json'
    if os.path.exists(state) and os.path.exists(meta_path):
        with open(meta_path) as f:
            meta = json.load(f)
        log('prepared sample read from %s (E_oed = %.4g Pa, porosity %.4f)' % (state, meta['E_oed'], meta['porosity']))
        O.load(state)
        return meta
    t0 = time.time()
    log('preparing the sample (%d spheres), cached as %s' % (P['num_spheres'], state))
    O.reset()
    L = P['box']
    O.materials.append(
        FrictMat(
            young=P['young'],
            poisson=P['poisson'],
            frictionAngle=math.radians(P['compaction_friction']),
            density=P['density'],
            label='spheres',
        )
    )
    O.materials.append(FrictMat(young=P['young'], poisson=P['poisson'], frictionAngle=0, density=0, label='walls'))
    walls = O.bodies.append(utils.aabbWalls([(0, 0, 0), (L, L, L)], thickness=0, material='walls'))
    assert walls == list(range(6))
    sp = pack.SpherePack()
    sp.makeCloud((0, 0, 0), (L, L, L), -1, P['rRelFuzz'], P['num_spheres'], False, 0.95, seed=P['seed'])
    sp.toSimulation(material='spheres')
    young = P['young']
    triax = TriaxialStressController(
        maxMultiplier=1.0 + 2e4 / young,
        finalMaxMultiplier=1.0 + 2e3 / young,
        thickness=0,
        stressMask=7,
        max_vel=0.005 * L,
        internalCompaction=True,
        label='triax',
    )
    newton = NewtonIntegrator(damping=P['dry_damping'], label='newton')
    O.engines = dem_engines(triax, newton)
    for e in O.engines:  # one thread: the prepared sample must not depend on yade -jN
        e.ompThreads = 1
    triax.goal1 = triax.goal2 = triax.goal3 = -P['sigma0']
    while True:  # isotropic compaction by particle growth
        advance(500)
        if utils.unbalancedForce() < 0.005 and abs(P['sigma0'] + triax.meanStress) / P['sigma0'] < 0.005:
            break
        if O.iter > 500000:
            raise RuntimeError('oedometer: compaction did not converge')
    log('compacted in %d iterations, porosity %.4f' % (O.iter, triax.porosity))
    utils.setContactFriction(math.radians(P['friction']))
    O.materials[0].frictionAngle = math.radians(P['friction'])
    # oedometric conditions: lateral walls fixed (zero strain rate), bottom fixed, top wall stress-controlled
    triax.internalCompaction = False
    triax.stressMask = 2
    triax.goal1 = triax.goal3 = 0
    triax.wall_bottom_activated = False
    s0, ds = P['sigma0'], P['small_load']
    settle(triax, s0, P)
    h = [height()]
    for goal in (s0 + ds, s0, s0 + ds, s0):  # load, unload, reload, unload
        settle(triax, goal, P)
        h.append(height())
    eps = [(h[0] - h[1]) / h[0], (h[2] - h[3]) / h[2], (h[4] - h[3]) / h[2]]  # first load, reload, second unload
    E_oed = ds / eps[1]
    meta = dict(
        E_oed=E_oed,
        eps_first_load=eps[0],
        eps_reload=eps[1],
        eps_unload=eps[2],
        E_oed_first_load=ds / eps[0],
        height=height(),
        area=area(),
        porosity=triax.porosity,
        iterations=O.iter,
        prepare_seconds=time.time() - t0,
        key=prep_key(P),
    )
    log(
        'dry cycle: strains first load %.4g, reload %.4g, unload %.4g -> E_oed = %.4g Pa (first load %.4g)'
        % (eps[0], eps[1], eps[2], E_oed, ds / eps[0])
    )
    os.makedirs(d, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=d, prefix='.tmp-', suffix='.bin.gz')
    os.close(fd)
    O.save(tmp)
    os.replace(tmp, state)
    write_json(meta_path, meta)
    O.load(state)  # continue from the saved state exactly as a cached run would
    return meta


def dry_nonlinear(P, meta):
    """Dry oedometric loading by the nonlinear load on a copy of the prepared sample: secant modulus."""
    key = 'dry_eps_%g' % P['load']
    if key in meta:
        return meta[key]
    triax = find_engine(TriaxialStressController)
    h0 = height()
    settle(triax, P['sigma0'] + P['load'], P, tol=0.002 * P['load'] / P['small_load'])
    eps = (h0 - height()) / h0
    meta[key] = eps
    write_json(os.path.join(cache_dir(), prep_key(P) + '.json'), meta)
    log('dry nonlinear loading: strain %.4g under %g Pa -> secant E_oed = %.4g Pa' % (eps, P['load'], P['load'] / eps))
    O.load(os.path.join(cache_dir(), prep_key(P) + '.bin.gz'))
    return eps


def find_engine(cls):
    return [e for e in O.engines if isinstance(e, cls)][0]


# ---------------------------------------------------------------- coupled phase -----------------------------
def make_flow(engine):
    if engine == 'pfv':
        from pfv import FlowEngine
    else:
        from yade.wrapper import FlowEngine
    return FlowEngine(label='flow')


def viscous_time_step(mu):
    """dt_MV = pi rho d^2 / (1200 mu) = m / (200 mu d) at the smallest value over the dynamic spheres."""
    return min(b.state.mass / (2 * b.shape.radius) for b in O.bodies if isinstance(b.shape, Sphere) and b.dynamic) / (
        200 * mu
    )


def coupled_time_step(dt_mv, dt_dem):
    """Largest dt with dt / dt_MV + (dt / dt_DEM)^2 <= 1.

    For one degree of freedom m x'' + c x' + k x = 0 integrated like NewtonIntegrator (explicit damping force,
    leap-frog), the amplification polynomial l^2 - (2 - a - b) l + (1 - a) with a = c dt / m, b = k dt^2 / m is stable
    iff a / 2 + b / 4 < 1, i.e. dt / dt_v + (dt / dt_k)^2 < 1 with dt_v = 2 m / c and dt_k = 2 sqrt(m / k). The thesis'
    min(dt_MV, dt_MK) (4.21) is the limit of either term alone; when both are of the same order (here: a viscosity
    chosen to keep the run short) it is not enough, and zeta * min(...) with zeta = 0.8 blows up (seen here with both
    engines). dt_MV and the P-wave step stand for dt_v and dt_k."""
    r = dt_dem / dt_mv
    return dt_dem * (-r + math.sqrt(r * r + 4)) / 2


def slice_pressure(flow, y, n):
    """Mean pore pressure over an n x n grid of the horizontal slice at height y (same for both engines)."""
    x0, x1 = O.bodies[XMIN].state.pos[0], O.bodies[XMAX].state.pos[0]
    z0, z1 = O.bodies[ZMIN].state.pos[2], O.bodies[ZMAX].state.pos[2]
    s = 0.0
    for i in range(n):
        for j in range(n):
            s += flow.getPorePressure((x0 + (i + 0.5) / n * (x1 - x0), y, z0 + (j + 0.5) / n * (z1 - z0)))
    return s / (n * n)


def effective_stress(n):
    """sigma'_yy in n equal horizontal slices between the walls (YADE's per-particle stresses, thesis 2.18;
    compression positive), from the bottom up; the same for both engines."""
    ids, pos, rad, _, _ = diagnostics.sphere_arrays(O.bodies)
    bottom = wall_y(BOTTOM)
    return diagnostics.effective_stress_profile(
        utils.bodyStressTensors(), ids, pos, rad, bottom, bottom + height(), n, area()
    )[1]


def permeameter(flow, P, triax):
    """Steady permeameter: dp on the bottom, 0 on the top, everything held still: K = Q gamma_w H / (A dp).

    Spheres are blocked with zero velocity and the wall servo is paused, so that no deformation flux adds to the
    permeameter flux (at the end of the nonlinear run the sample is still consolidating, and YADE's getBoundaryFlux
    also counts the volume swept by a moving drained wall). Two steps: YADE applies new boundary conditions one step
    after the remesh that takes them."""
    spheres = [b for b in O.bodies if isinstance(b.shape, Sphere)]
    saved = [(b.state.blockedDOFs, b.state.vel, b.state.angVel) for b in spheres]
    for b in spheres:
        b.state.blockedDOFs = 'xyzXYZ'
        b.state.vel = b.state.angVel = (0, 0, 0)
    servo, wall_vel = triax.dead, O.bodies[TOP].state.vel
    triax.dead = True
    O.bodies[TOP].state.vel = (0, 0, 0)
    flow.bndCondIsPressure = [False, False, True, True, False, False]
    flow.bndCondValue = [0, 0, P['perm_dp'], 0, 0, 0]
    flow.updateTriangulation = True
    advance(2)
    q_in, q_out = flow.getBoundaryFlux(BOTTOM), flow.getBoundaryFlux(TOP)
    for b, (dofs, vel, ang) in zip(spheres, saved):
        b.state.blockedDOFs, b.state.vel, b.state.angVel = dofs, vel, ang
    triax.dead = servo
    O.bodies[TOP].state.vel = wall_vel
    K = 0.5 * (abs(q_in) + abs(q_out)) * P['gamma_w'] * height() / (area() * P['perm_dp'])
    log('permeameter: Qin %.6g Qout %.6g -> K = %.6g m/s (mu = %g Pa.s)' % (q_in, q_out, K, P['viscosity']))
    if abs(q_in + q_out) > 1e-3 * abs(q_in):
        raise RuntimeError('oedometer: the permeameter fluxes do not balance (Qin %g, Qout %g)' % (q_in, q_out))
    return K, q_in, q_out


class LivePlot:
    """With the GUI, U and the mid-height pressure against T_v on fixed logarithmic axes, shown and refreshed live by
    yade.plot's updater; headless, nothing.

    plot.plot() would start its updater thread at once, and matplotlib is not thread-safe: a redraw racing with
    set_xscale('log') meets the linear default limits (0, 1) and raises. So the figures are made without it, the axes
    fixed, and the updater started here, on a thread that stop() joins before YADE leaves (a thread killed inside a
    redraw at exit aborts the process)."""

    def __init__(self, Tv_range):
        self.plot = None
        if HEADLESS:
            return
        import threading
        from yade import plot

        plot.plots = {'Tv': ('U_sim', 'U_theory'), 'Tv ': ('p_mid', 'p_mid_theory')}  # p_mid: / load
        figures = plot.plot(subPlots=True, noShow=True)
        self.figures = figures if isinstance(figures, list) else [figures]
        self.axes = {ref.line.axes for ref in plot.currLineRefs}
        for a in self.axes:
            a.set_xscale('log')
            a.set_xlim(*Tv_range)
            a.set_autoscalex_on(False)
        self.updater = threading.Thread(target=plot.liveUpdate, args=(time.time(),), daemon=True)
        self.updater.start()
        for f in self.figures:
            f.show()
        self.plot = plot

    def add(self, **columns):
        if self.plot:
            self.plot.addData(**columns)

    def stop(self):
        """Stops the updater and draws the points it has not drawn yet."""
        if not self.plot:
            return
        self.plot.live = False
        self.updater.join()
        self.plot.live = True
        for ref in self.plot.currLineRefs:
            ref.update()
        for a in self.axes:
            a.relim()
            a.autoscale_view()
        for f in self.figures:
            f.canvas.draw_idle()


def isochrone(flow, P, T_iso, row, sigma_eff_start, theories):
    """The pressure profile recorded at the isochrone T_iso (reached at `row`), against both Terzaghi solutions."""
    plain, layer = theories
    t, H = row['t'], row['height']
    d_sigma = (effective_stress(P['profile_points']) - sigma_eff_start) / P['load']
    profile = []
    for i in range(P['profile_points']):
        rel = (i + 0.5) / P['profile_points']  # height above the bottom / H
        p = slice_pressure(flow, wall_y(BOTTOM) + rel * H, P['slice_grid'])
        profile.append(
            dict(
                Tv_target=T_iso,
                Tv=row['Tv'],
                z_over_H=rel,
                p_over_load=p / P['load'],
                p_theory_over_load=plain.p(rel, t),
                p_theory_layer_over_load=layer.p(rel, t),
                d_sigma_eff_over_load=d_sigma[i],
                p_plus_d_sigma_eff_over_load=p / P['load'] + d_sigma[i],
            )
        )
    return profile


def switch_fluid_on(opts, P):
    """The flow engine inserted before the stress controller and NewtonIntegrator, undamped, at the coupled time
    step; returns the engine, the controller, dt_MV and the P-wave step."""
    triax, newton = find_engine(TriaxialStressController), find_engine(NewtonIntegrator)
    flow = make_flow(opts['engine'])
    O.engines = [
        e
        for e in O.engines
        if not isinstance(e, (GlobalStiffnessTimeStepper, TriaxialStressController, NewtonIntegrator))
    ] + [flow, triax, newton]
    flow.viscosity = P['viscosity']
    flow.boundaryUseMaxMin = [False] * 6  # the pore space is bounded by the wall bodies
    flow.meshUpdateInterval = P['mesh_update_interval']
    flow.useSolver = 3
    newton.damping = 0.0  # the fluid damps (thesis)
    dt_mv = viscous_time_step(P['viscosity'])
    dt_dem = utils.PWaveTimeStep()
    dt_star = coupled_time_step(P['viscous_factor'] * dt_mv, dt_dem)
    O.dt = P['zeta'] * dt_star
    log(
        'time step: dt_MV %.4g s, P-wave %.4g s, combined limit %.4g s -> O.dt = %.4g s = %.3f dt_MV'
        % (dt_mv, dt_dem, dt_star, O.dt, O.dt / dt_mv)
    )
    if opts['engine'] == 'pfv':
        assert abs(flow.viscous_time_step / dt_mv - 1) < 1e-9, (flow.viscous_time_step, dt_mv)
    return flow, triax, dt_mv, dt_dem


def rms(values):
    """The root mean square of the values, NaN for none."""
    values = list(values)
    return math.sqrt(sum(v * v for v in values) / len(values)) if values else float('nan')


def output_folder(opts, P):
    """The folder of the results (made if missing): --out, else oedometer-<engine>[-quick][-nonlinear][-drainage]."""
    tag = (
        opts['engine']
        + ('-quick' if opts['quick'] else '')
        + ('-nonlinear' if opts['nonlinear'] else '')
        + ('-' + P['drainage'] if P['drainage'] != 'top' else '')
    )
    out = opts['out'] or os.path.abspath('oedometer-' + tag)
    os.makedirs(out, exist_ok=True)
    return out


def run(opts):
    P = parameters(opts)
    out = output_folder(opts, P)
    wall0 = time.time()
    meta = prepare(P)
    if not HEADLESS:  # the 3D view (the controller is opened by YADE)
        from yade import qt

        qt.View()
    dry_eps = P['small_load'] / meta['E_oed'] if not opts['nonlinear'] else dry_nonlinear(P, meta)

    # --- switch the fluid on -------------------------------------------------------------------------------
    flow, triax, dt_mv, dt_dem = switch_fluid_on(opts, P)
    K0, q_in, q_out = permeameter(flow, P, triax)
    H0, A = height(), area()
    E_oed = meta['E_oed']
    Cv = K0 * E_oed / P['gamma_w']
    L_drain = H0 / 2 if P['drainage'] == 'both' else H0
    t_c = L_drain**2 / Cv
    c_wave = math.sqrt(E_oed / (P['density'] * (1 - meta['porosity'])))
    log(
        'C_v = %.5g m2/s, drainage length %.5g m, t(T_v=1) = %.5g s = %d steps; t_c / t_wave = %.1f'
        % (Cv, L_drain, t_c, round(t_c / O.dt), t_c / (H0 / c_wave))
    )

    # --- consolidation -------------------------------------------------------------------------------------
    flow.bndCondIsPressure = [False, False, P['drainage'] == 'both', True, False, False]
    flow.bndCondValue = [0.0] * 6
    flow.updateTriangulation = True  # YADE applies new boundary types at a remesh
    sigma_start = top_stress()
    sigma_eff_start = effective_stress(P['profile_points'])  # the load adds to this, slice by slice
    triax.goal2 = -(P['sigma0'] + P['load'])
    triax.max_vel = P['wall_speed'] * dry_eps * H0 / t_c  # do not let the wall speed limit the settlement
    it0, t0 = O.iter, O.time
    s_dry = dry_eps * H0
    r_mean = float(np.mean([b.shape.radius for b in O.bodies if isinstance(b.shape, Sphere)]))
    plain = Terzaghi(P['drainage'], H0, Cv, 0.0)
    layer = Terzaghi(P['drainage'], H0, Cv, r_mean)
    n = P['slice_grid']
    rows, iso = [], []
    targets = sorted(set(list(np.geomspace(1e-3, P['Tv_end'], 60)) + list(P['isochrones'])))
    targets = [T for T in targets if T <= P['Tv_end'] * (1 + 1e-9)]
    iso_left = [T for T in P['isochrones'] if T <= P['Tv_end'] * (1 + 1e-9)]
    live = LivePlot((0.8 * targets[0], 1.25 * targets[-1]))
    # drained volume: outflow through the drained walls, accumulated every step (fluid volume balance check)
    drained = [0.0]
    faces = [TOP] + ([BOTTOM] if P['drainage'] == 'both' else [])

    def accumulate():
        drained[0] += sum(flow.getBoundaryFlux(w) for w in faces) * O.dt

    meter = PyRunner(iterPeriod=1, command='_oedometer_meter()', label='meter')
    import builtins

    builtins._oedometer_meter = accumulate
    O.engines = O.engines + [meter]
    wall_flow = 0.0
    for T in targets:
        steps = max(1, int(math.ceil((t0 + T * t_c - O.time) / O.dt)))
        t_run = time.time()
        advance(steps)
        wall_flow += time.time() - t_run
        t = O.time - t0
        H = height()
        s = H0 - H
        p_mid = slice_pressure(flow, wall_y(BOTTOM) + 0.5 * H, n)
        row = dict(
            iter=O.iter - it0,
            t=t,
            Tv=t / t_c,
            height=H,
            settlement=s,
            U_sim=s / s_dry,
            U_theory=plain.U(t),
            U_theory_layer=layer.U(t),
            p_mid=p_mid,
            p_mid_theory=P['load'] * plain.p(0.5, t),
            p_mid_theory_layer=P['load'] * layer.p(0.5, t),
            sigma_top=top_stress(),
            sigma_bottom_total=bottom_stress(),
            bottom_fluid_stress=-flow.fluidForce(BOTTOM)[1] / A,
            kinetic_energy=utils.kineticEnergy(),
            drained_volume=drained[0],
            settlement_volume=s * A,
        )
        rows.append(row)
        live.add(
            Tv=row['Tv'],
            U_sim=row['U_sim'],
            U_theory=row['U_theory'],
            p_mid=p_mid / P['load'],
            p_mid_theory=row['p_mid_theory'] / P['load'],
        )
        if iso_left and row['Tv'] >= iso_left[0] * (1 - 1e-9):
            iso += isochrone(flow, P, iso_left.pop(0), row, sigma_eff_start, (plain, layer))
        if len(rows) % 10 == 0 or T == targets[-1]:
            log(
                'T_v %.4f  U_sim %.4f  U_th %.4f  p_mid/load %.4f (th %.4f)  bottom total stress %.5g Pa'
                % (
                    row['Tv'],
                    row['U_sim'],
                    row['U_theory'],
                    p_mid / P['load'],
                    row['p_mid_theory'] / P['load'],
                    row['sigma_bottom_total'],
                )
            )
    live.stop()
    log(
        'engine %s: %d coupled steps in %.1f s (%.2f ms/step)'
        % (opts['engine'], O.iter - it0, wall_flow, 1e3 * wall_flow / max(1, O.iter - it0))
    )

    # --- errors --------------------------------------------------------------------------------------------
    load_total = P['sigma0'] + P['load']
    # Terzaghi's theory is quasi-static: the error figures start once the load has crossed the sample twice at the
    # oedometric wave speed (earlier samples show the inertial transient of the loading; they are plotted anyway).
    Tv_min = 2 * (H0 / c_wave) / t_c
    win = [r for r in rows if r['Tv'] >= Tv_min]
    iso_win = [r for r in iso if r['Tv'] >= Tv_min]
    summary = dict(
        engine=opts['engine'],
        quick=opts['quick'],
        nonlinear=opts['nonlinear'],
        drainage=P['drainage'],
        parameters=P,
        prepared=meta,
        dt=O.dt,
        dt_MV=dt_mv,
        dt_DEM=dt_dem,
        dt_over_dt_MV=O.dt / dt_mv,
        K=K0,
        Qin=q_in,
        Qout=q_out,
        E_oed=E_oed,
        Cv=Cv,
        H0=H0,
        area=A,
        drainage_length=L_drain,
        t_Tv1=t_c,
        sigma_top_start=sigma_start,
        dry_settlement=s_dry,
        mean_radius=r_mean,
        steps=O.iter - it0,
        final_Tv=rows[-1]['Tv'],
        final_U=rows[-1]['U_sim'],
        error_window_Tv_min=Tv_min,
        U_max_abs_error=max(abs(r['U_sim'] - r['U_theory']) for r in win),
        isochrone_rms_error=rms(r['p_over_load'] - r['p_theory_over_load'] for r in iso_win),
        mid_pressure_rms_error=rms((r['p_mid'] - r['p_mid_theory']) / P['load'] for r in win),
        U_max_abs_error_layer=max(abs(r['U_sim'] - r['U_theory_layer']) for r in win),
        isochrone_rms_error_layer=rms(r['p_over_load'] - r['p_theory_layer_over_load'] for r in iso_win),
        U_max_abs_error_all=max(abs(r['U_sim'] - r['U_theory']) for r in rows),
        isochrone_rms_error_all=rms(r['p_over_load'] - r['p_theory_over_load'] for r in iso),
        # the whole record (the servo's loading transient included) and the quasi-static window
        max_p_mid_over_load=max(r['p_mid'] for r in rows) / P['load'],
        max_p_mid_over_load_window=max(r['p_mid'] for r in win) / P['load'],
        # claim 18: pore pressure + effective stress increment = the load increment along the height
        p_plus_sigma_eff_max_error_Tv01=max(
            (abs(r['p_plus_d_sigma_eff_over_load'] - 1) for r in iso if r['Tv_target'] == 0.1), default=float('nan')
        ),
        bottom_total_stress_max_error=max(abs(r['sigma_bottom_total'] - load_total) for r in win) / P['load'],
        drained_over_settlement_volume_end=rows[-1]['drained_volume'] / rows[-1]['settlement_volume'],
        coupled_wall_seconds=wall_flow,
        ms_per_step=1e3 * wall_flow / max(1, O.iter - it0),
    )
    if opts['engine'] == 'pfv':
        summary['remesh_count'] = flow.core.remesh_count
        # the engine's collective viscous limit, recomputed at every remesh (doc/validation.md section 4)
        # the limits themselves (not their bounds), and not the permeameter's
        hist = [h for h in flow.collective_viscous_history if h['method'] != 'bound' and math.isfinite(h['limit'])]
        summary['collective_limit_over_dt'] = [h['limit'] / O.dt for h in hist]
        summary['collective_limit_seconds'] = [h['seconds'] for h in hist]
        if hist:
            log(
                'collective viscous limit / O.dt: first %.3f, last %.3f, lowest %.3f (%d meshes; the engine '
                'warns below %.3f)'
                % (
                    hist[0]['limit'] / O.dt,
                    hist[-1]['limit'] / O.dt,
                    min(h['limit'] for h in hist) / O.dt,
                    len(hist),
                    1 / flow.time_step_safety,
                )
            )
    if opts['nonlinear']:
        K1, _, _ = permeameter(flow, P, triax)
        E_sec = P['load'] / dry_eps
        Cv1 = K1 * E_sec / P['gamma_w']
        final = Terzaghi(P['drainage'], height(), Cv1, 0.0)
        for r in rows:
            r['U_theory_final_Cv'] = final.U(r['t'])
        summary.update(
            K_final=K1,
            E_oed_secant=E_sec,
            Cv_final=Cv1,
            dry_strain=dry_eps,
            U_max_abs_error_final_Cv=max(abs(r['U_sim'] - r['U_theory_final_Cv']) for r in win),
            final_strain=(H0 - rows[-1]['height']) / H0,
        )
        summary.update(variable_k_errors(summary, rows, iso))
        log(
            'nonlinear: K_init %.5g K_final %.5g m/s, E_oed init %.5g secant %.5g Pa, C_v init %.5g final %.5g m2/s'
            % (K0, K1, E_oed, E_sec, Cv, Cv1)
        )
        log(
            'nonlinear: max |U_sim - U_theory| with C_v,init %.4f, with C_v,final %.4f, with K falling with the '
            'strain %.4f (isochrones %.4f)'
            % (
                summary['U_max_abs_error'],
                summary['U_max_abs_error_final_Cv'],
                summary['U_max_abs_error_variable_K'],
                summary['isochrone_rms_error_variable_K'],
            )
        )
    summary['total_wall_seconds'] = time.time() - wall0

    write_csv(os.path.join(out, 'timeseries.csv'), rows)
    write_csv(os.path.join(out, 'isochrones.csv'), iso)
    with open(os.path.join(out, 'summary.json'), 'w') as f:
        json.dump(summary, f, indent=1, default=str)
    plot_runs([(opts['engine'], rows, iso, summary)], os.path.join(out, 'oedometer.png'))
    log(
        'RESULT engine=%s K=%.6g E_oed=%.6g Cv=%.6g steps=%d max|U_sim-U_th|=%.4f isochrone_rms/load=%.4f '
        'mid_rms/load=%.4f final_U=%.4f bottom_total_err/load=%.4f | drained-layer theory: max|dU|=%.4f '
        'isochrone_rms/load=%.4f'
        % (
            opts['engine'],
            K0,
            E_oed,
            Cv,
            summary['steps'],
            summary['U_max_abs_error'],
            summary['isochrone_rms_error'],
            summary['mid_pressure_rms_error'],
            summary['final_U'],
            summary['bottom_total_stress_max_error'],
            summary['U_max_abs_error_layer'],
            summary['isochrone_rms_error_layer'],
        )
    )
    log('outputs in %s' % out)
    return summary


def write_csv(path, rows):
    if not rows:
        open(path, 'w').close()
        return
    keys = list(rows[0].keys())
    with open(path, 'w') as f:
        f.write(','.join(keys) + '\n')
        for r in rows:
            f.write(','.join(repr(float(r[k])) for k in keys) + '\n')


def read_csv(path):
    with open(path) as f:
        keys = f.readline().strip().split(',')
        return [dict(zip(keys, map(float, line.split(',')))) for line in f if line.strip()]


# ---------------------------------------------------------------- plots -------------------------------------
def plot_runs(runs, path):
    """runs: [(label, timeseries rows, isochrone rows, summary)]; one PNG with U(T_v), p_mid(T_v), isochrones."""
    import matplotlib

    if HEADLESS:
        matplotlib.use('Agg')
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(1, 3, figsize=(13, 4.3))
    styles = ['o', 's', '^', 'v']
    Tv = np.geomspace(1e-3, max(r[3]['parameters']['Tv_end'] for r in runs), 200)
    ax[0].semilogx(Tv, terzaghi_U(Tv), 'k-', lw=1.2, label='Terzaghi')
    ax[1].semilogx(Tv, [terzaghi_p([0.5], T)[0] for T in Tv], 'k-', lw=1.2, label='Terzaghi')
    first = runs[0]
    ax[0].semilogx(
        [r['Tv'] for r in first[1]],
        [r['U_theory_layer'] for r in first[1]],
        'k:',
        lw=1,
        label='Terzaghi, drained layer of one radius',
    )
    ax[1].semilogx(
        [r['Tv'] for r in first[1]],
        [r['p_mid_theory_layer'] / first[3]['parameters']['load'] for r in first[1]],
        'k:',
        lw=1,
        label='Terzaghi, drained layer',
    )
    for a in ax[:2]:
        a.axvline(
            first[3]['error_window_Tv_min'], ls='--', color='grey', lw=0.8, label='errors from here (2 wave transits)'
        )
    for k, (label, rows, iso, summ) in enumerate(runs):
        m = styles[k % len(styles)]
        ax[0].semilogx(
            [r['Tv'] for r in rows],
            [r['U_sim'] for r in rows],
            m,
            ms=3.5,
            mfc='none',
            label='%s (max err %.3f)' % (label, summ['U_max_abs_error']),
        )
        if 'U_theory_final_Cv' in rows[0]:
            ax[0].semilogx(
                [r['Tv'] for r in rows],
                [r['U_theory_final_Cv'] for r in rows],
                '--',
                label='Terzaghi with C_v,final (%s)' % label,
            )
        if 'U_theory_variable_K' in rows[0]:
            ax[0].semilogx(
                [r['Tv'] for r in rows],
                [r['U_theory_variable_K'] for r in rows],
                '-.',
                label='K falling with the strain (%s, max err %.3f)' % (label, summ['U_max_abs_error_variable_K']),
            )
        ax[1].semilogx(
            [r['Tv'] for r in rows],
            [r['p_mid'] / summ['parameters']['load'] for r in rows],
            m,
            ms=3.5,
            mfc='none',
            label='%s (RMS %.3f)' % (label, summ['mid_pressure_rms_error']),
        )
        for j, T in enumerate(sorted(set(r['Tv_target'] for r in iso))):
            pts = [r for r in iso if r['Tv_target'] == T]
            ax[2].plot(
                [r['p_over_load'] for r in pts],
                [r['z_over_H'] for r in pts],
                m,
                ms=3.5,
                mfc='none',
                color='C%d' % j,
                label=('%s (RMS %.3f)' % (label, summ['isochrone_rms_error'])) if j == 0 else None,
            )
            if k == 0:
                th = Terzaghi(summ['drainage'], 1.0, 1.0)
                zz = np.linspace(0, 1, 101)
                ax[2].plot([th.p(z, pts[0]['Tv']) for z in zz], zz, '-', color='C%d' % j, lw=1, label='T_v = %g' % T)
    ax[0].set(xlabel='T_v', ylabel='U = settlement / dry settlement', title='Degree of consolidation')
    ax[1].set(xlabel='T_v', ylabel='p / load at mid-height', title='Excess pore pressure, mid-height')
    ax[2].set(xlabel='p / load', ylabel='height / H', title='Isochrones (lines: Terzaghi)')
    for a in ax:
        a.grid(alpha=0.3)
        a.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=72)
    plt.close(fig)
    log('plot written to %s' % path)


def compare(dirs, out):
    runs = []
    for d in dirs:
        with open(os.path.join(d, 'summary.json')) as f:
            s = json.load(f)
        runs.append(
            (s['engine'], read_csv(os.path.join(d, 'timeseries.csv')), read_csv(os.path.join(d, 'isochrones.csv')), s)
        )
        if 'Cv_final' in s:  # recomputed: runs of older versions lack it
            s.update(variable_k_errors(s, runs[-1][1], runs[-1][2]))
    os.makedirs(out, exist_ok=True)
    plot_runs(runs, os.path.join(out, 'oedometer-comparison.png'))
    print(
        '| engine | K [m/s] | E_oed [Pa] | C_v [m2/s] | steps | max abs(U_sim - U_th) | RMS isochrones / load | '
        'RMS p_mid / load | final U | max abs dU, drained layer | RMS isochrones, drained layer | '
        'whole curve: max abs dU / RMS isochrones | drained / settled volume | ms/step |'
    )
    print('|---|---|---|---|---|---|---|---|---|---|---|---|---|---|')
    for label, rows, iso, s in runs:
        line_format = (
            '| %s | %.4g | %.4g | %.4g | %d | %.4f | %.4f | %.4f | %.4f | %.4f | %.4f | %.4f / %.4f | ' '%.4f | %.2f |'
        )
        print(
            line_format
            % (
                label,
                s['K'],
                s['E_oed'],
                s['Cv'],
                s['steps'],
                s['U_max_abs_error'],
                s['isochrone_rms_error'],
                s['mid_pressure_rms_error'],
                s['final_U'],
                s['U_max_abs_error_layer'],
                s['isochrone_rms_error_layer'],
                s['U_max_abs_error_all'],
                s['isochrone_rms_error_all'],
                s['drained_over_settlement_volume_end'],
                s['ms_per_step'],
            )
        )
    if all('Cv_final' in r[3] for r in runs):
        print()
        print(
            '| engine | K_init [m/s] | K_final [m/s] | E_oed init [Pa] | E_oed secant [Pa] | C_v init [m2/s] | '
            'C_v final [m2/s] | max abs dU, C_v init | max abs dU, C_v final | RMS isochrones, C_v init | '
            'max abs dU, K(strain) | RMS isochrones, K(strain) | final strain | dry strain | drained / settled |'
        )
        print('|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|')
        for label, rows, iso, s in runs:
            print(
                '| %s | %.4g | %.4g | %.4g | %.4g | %.4g | %.4g | %.4f | %.4f | %.4f | %.4f | %.4f | %.4f | %.4f | '
                '%.4f |'
                % (
                    label,
                    s['K'],
                    s['K_final'],
                    s['E_oed'],
                    s['E_oed_secant'],
                    s['Cv'],
                    s['Cv_final'],
                    s['U_max_abs_error'],
                    s['U_max_abs_error_final_Cv'],
                    s['isochrone_rms_error'],
                    s['U_max_abs_error_variable_K'],
                    s['isochrone_rms_error_variable_K'],
                    s['final_strain'],
                    s['dry_strain'],
                    s['drained_over_settlement_volume_end'],
                )
            )


def main():
    opts = parse_args(sys.argv[1:])
    if opts['compare']:
        compare(opts['compare'], opts['out'] or '.')
    else:
        run(opts)
    return 0


# yade runs this file with exec (its __name__ is not '__main__'): run unconditionally. Headless, leave yade at the end
# (an exception gives exit status 1); with the GUI, keep the session open for the plots.
_status = main()
if HEADLESS:
    sys.exit(_status)
