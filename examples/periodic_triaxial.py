# -*- coding: utf-8 -*-
"""Undrained and drained triaxial compression of a dense packing in a periodic cell, with pfv.PeriodicFlowEngine.

    yade-double -n -x examples/periodic_triaxial.py [--quick] [--out=DIR] [--set=NAME=VALUE ...]

The script

1. prepares a dense random packing in a periodic cell, dry: YADE's makeCloud, an isotropic compaction to sigma3
   with a friction of 1 degree, then the friction raised to 30 degrees and the packing settled again; it measures
   the packing's permeability kappa (one flow step under a pressure gradient, nothing moving);
2. undrained test: water, compressible (fluidBulkModulus = K_f = 2.2 GPa), fills the pores; the cell is shortened
   along z at a constant strain rate (inertial number 1e-3: quasi-static for the grains) while the total lateral
   stress is held at sigma3. No fluid leaves a periodic cell: each pore stores V_f / (K_f dt) per unit pressure,
   and the fluid volume-weighted mean pressure follows the cell's volume, rising by K_f dV / V_f (doc/periodic.md).
   Dense packings dilate under shear: the pressure first rises, then falls below zero, and the effective stress
   path climbs along the failure line. The fluid is linear: its pressure goes on falling where real water would
   cavitate (below about -100 kPa without a back pressure);
3. drained test: the same loading of the same packing with an incompressible fluid (fluidBulkModulus = 0) and
   drains: p = 0 imposed (imposePressure) in the pores at the nodes of a grid about drain_spacing (two grain
   diameters) apart, 27 in the --quick cell, which take in or give back what the cell's volume change expels or
   draws. The excess pressure u is what drives that fluid to the drains: for point sinks of the size a of a grain,
   u ~ mu Q / (4 pi kappa a N), Q = V d(eps_v)/dt, N drains, which is 11 Pa for d(eps_v)/dt = the axial rate with
   --quick, where the median |u| is 8 Pa. With a single drain (no imposed pressure: the engine's reference pore,
   p~ = 0, takes the whole flow, doc/periodic.md) u is about 50 times larger and swings by a factor of 10 with
   the size of the reference pore, chosen anew at each remesh. The loading (inertial number 1e-3) is slow for the
   drainage: max |u| stays below 1e-3 of p' (measured 1e-4 with --quick).

Stresses, compression positive. sigma' is the contact stress, YADE's utils.getStress() (Love-Weber, sign changed):
the fluid forces act on the particles, and a uniform pore pressure exerts no net force on a sphere, so the contacts
carry Terzaghi's effective stress and the total stress is sigma' + u I, u the pores' pressure averaged over the
fluid (average_fluid_pressure()). The pressure in the undrained cell is uniform to 5e-4 of sigma3 (water flows
between neighbouring pores within a step), so what the spheres feel is that mean. p' = tr(sigma') / 3,
q = sigma'_zz - (sigma'_xx + sigma'_yy) / 2, eps_a = -ln(F_zz), eps_v = -ln(det F), F = O.cell.trsf from the start
of the test.

The cell is driven through O.cell.velGrad: z at the imposed strain rate, x and y by the servo CellServo on the total
lateral stress sigma'_ii + u (undrained) or on sigma'_ii (drained, where u is 1e-4 of it: the drains' pressure
answers the rate of the cell's volume, which the servo sets, and fed back it made the loop ring). CellServo adds the
undrained fluid's stiffness K_f V / V_f (here over 100 times the contacts' stiffness) to the contacts' tangent
(utils.getStressAndTangent) and integrates the strain increment. YADE's PeriTriaxController servoes the contact
stress alone, and tried here in the dry isotropic compaction it stayed 15 to 20 % off its goal for 200 000 steps:
its stress servo takes (goal - stress) x face area / mean contact stiffness as the strain increment, a length, so
that its gain depends on the units and on the cell's size.

Outputs in --out (default ./periodic_triaxial[-quick]): undrained.csv and drained.csv (each test's yade.plot.addData
records: eps_a, eps_v, q, p_eff, u, p_total, sigma_r_total, ...), summary.json, periodic_triaxial.png (q and u
against eps_a, the stress paths (p', q), eps_v against eps_a). --set overrides one parameter of the tables below
(JSON value), e.g. --set=axial_strain=0.02. The checks are in tests/yade/examples/test_periodic_triaxial.py.
"""
import json
import math
import os
import sys
import time

# ------------------------------------------------------------------------------------------------------------
# Parameters (SI units). Contact modulus and confining stress give overlaps ~1e-3 of the radius; water's bulk
# modulus and viscosity.
# ------------------------------------------------------------------------------------------------------------
FULL = dict(num_spheres=1000, axial_strain=0.10)
QUICK = dict(num_spheres=300, axial_strain=0.04)
COMMON = dict(
    radius=0.5e-3,  # mean sphere radius [m]
    rRelFuzz=0.3,  # radii r (1 +- 0.3), uniform
    seed=1,  # makeCloud seed
    young=1.0e8,  # contact modulus [Pa]
    poisson=0.5,  # k_t / k_n
    density=2650.0,  # [kg/m3]
    compaction_friction=1.0,  # friction angle during the isotropic compaction [deg]: a dense packing
    friction=30.0,  # friction angle of the tests [deg]
    sigma3=1.0e5,  # confining (total lateral) stress [Pa]
    inertial_number=1e-3,  # axial strain rate = I / (d sqrt(rho / sigma3)), d the mean diameter
    viscosity=1.0e-3,  # [Pa s]
    bulk_modulus=2.2e9,  # K_f of the undrained test [Pa]
    drain_spacing=2.0e-3,  # the drained test's drains: pores held at p = 0 on a grid about this far apart [m]
    damping=0.2,  # NewtonIntegrator's
    mesh_update_interval=100,  # remesh the pores every so many steps
    record_every=25,  # steps between two records
)
DRAINED_FRACTION = 1e-3  # the drained test's max |u| / p' stays below this (docstring, test)

# ------------------------------------------------------------------------------------------------------------
from yade import O, pack, plot, runtime, utils  # noqa: E402
from yade.minieigenHP import Matrix3, Vector3  # noqa: E402
from yade.wrapper import (  # noqa: E402
    Bo1_Sphere_Aabb,
    ForceResetter,
    FrictMat,
    Ig2_Sphere_Sphere_ScGeom,
    InsertionSortCollider,
    InteractionLoop,
    Ip2_FrictMat_FrictMat_FrictPhys,
    Law2_ScGeom_FrictPhys_CundallStrack,
    NewtonIntegrator,
    PyRunner,
)
from pfv import PeriodicFlowEngine  # noqa: E402

AXIAL, LATERAL = 2, (0, 1)
HEADLESS = bool(getattr(runtime.opts, 'nogui', True)) or not getattr(runtime, 'hasDisplay', False)
# A PyRunner evaluates its command in YADE's __main__, which is not this module when a test imports it: the
# commands find their callables here.
_RUNNER_COMMAND = "__import__('sys').modules[%r]._CALLBACKS[%r]()"
_CALLBACKS = {}


def log(*args):
    print('periodic_triaxial:', *args, flush=True)


def parse_args(argv):
    opts = dict(quick=False, out=None, set={})
    for a in argv:
        if a == '--quick':
            opts['quick'] = True
        elif a.startswith('--out='):
            opts['out'] = a.split('=', 1)[1]
        elif a.startswith('--set='):  # override a parameter: --set=axial_strain=0.02
            k, v = a.split('=', 2)[1:]
            opts['set'][k] = json.loads(v)
        elif a.endswith('.py') and not a.startswith('-'):
            continue  # yade may leave the script name in argv
        else:
            raise SystemExit('periodic_triaxial: unknown argument %r (see the docstring)' % a)
    return opts


def parameters(opts):
    P = dict(COMMON)
    P.update(QUICK if opts['quick'] else FULL)
    for k, v in opts['set'].items():
        if k not in P:
            raise SystemExit('periodic_triaxial: --set: unknown parameter %r' % k)
        P[k] = v
    return P


def strain_rate(P):
    return P['inertial_number'] / (2 * P['radius'] * math.sqrt(P['density'] / P['sigma3']))


def solid_volume():
    return sum(4.0 / 3.0 * math.pi * b.shape.radius**3 for b in O.bodies)


def runner(name, function, period):
    _CALLBACKS[name] = function
    return PyRunner(command=_RUNNER_COMMAND % (__name__, name), iterPeriod=period, label=name)


# ---------------------------------------------------------------- the cell's servo ---------------------------
class CellServo:
    """Each step, O.cell.velGrad: the axes not in `axes` shorten at `axial_rate`; on each axis of `axes` the total
    stress sigma'_ii + u (compression positive) is servoed to sigma3, u the flow engine's mean pressure if
    `bulk_modulus` > 0 (undrained); drained, sigma'_ii (the drains' pressure answers the rate of the cell's volume,
    which the servo sets: fed back, it made the loop ring).

    Strain increment per step, velocity form of a PI controller: d_n = d_(n-1) - (e_n / 2 + (e_n - e_(n-1))) / M, e
    the stress error (YADE's sign: sigma_ii + sigma3 with sigma_ii < 0 in compression), M the stiffness of the
    axis: the contacts' tangent (affine, an upper bound of the packing's: the gain errs on the stable side) plus
    the undrained fluid's K_f V / V_f per unit volumetric strain, counted once for each servoed axis since they all
    move the same pore volume. If the stress answers an increment with the stiffness c M (the affine response of
    the contacts, c <= 1 once the grains relax), the error obeys e_(n+1) = (2 - 3c/2) e_n - (1 - c) e_(n-1), which
    decays for 0 < c < 1.6; the integral part follows a constant loading rate without a lag."""

    def __init__(self, sigma3, axes, max_rate, axial_rate=0.0, flow=None, bulk_modulus=0.0):
        self.sigma3, self.axes, self.max_rate, self.axial_rate = sigma3, axes, max_rate, axial_rate
        self.flow, self.bulk_modulus = flow, bulk_modulus
        self.increment = [0.0, 0.0, 0.0]
        self.error = [0.0, 0.0, 0.0]
        self.solid = solid_volume()
        self.stress, self.u = None, 0.0  # this step's contact stress (YADE's sign) and mean pore pressure

    def __call__(self):
        stress, tangent = utils.getStressAndTangent(symmetry=True)
        self.stress = stress
        self.u = self.flow.average_fluid_pressure() if self.flow is not None else 0.0
        volume = O.cell.volume
        fluid = self.bulk_modulus * volume / (volume - self.solid) * len(self.axes)
        limit = self.max_rate * O.dt
        held = self.u if self.bulk_modulus > 0 else 0.0
        rates = [-self.axial_rate] * 3
        for a in self.axes:
            error = stress[a, a] - held + self.sigma3
            stiffness = tangent[a, a] + fluid
            if stiffness > 0:
                step = self.increment[a] - (0.5 * error + (error - self.error[a])) / stiffness
            else:  # no contact yet (the loose cloud): as fast as allowed
                step = -limit if error > 0 else limit
            self.increment[a] = max(-limit, min(limit, step))
            self.error[a] = error
            rates[a] = self.increment[a] / O.dt
        O.cell.velGrad = Matrix3(rates[0], 0, 0, 0, rates[1], 0, 0, 0, rates[2])


def engines(servo, P, flow=None):
    """YADE's periodic DEM loop; the flow engine after the contacts (its forces join theirs), the servo after it
    (it reads this step's pressure), NewtonIntegrator last (it applies the new velGrad in this step)."""
    return [
        ForceResetter(),
        InsertionSortCollider([Bo1_Sphere_Aabb()], allowBiggerThanPeriod=True),
        InteractionLoop(
            [Ig2_Sphere_Sphere_ScGeom()], [Ip2_FrictMat_FrictMat_FrictPhys()], [Law2_ScGeom_FrictPhys_CundallStrack()]
        ),
        *([flow] if flow is not None else []),
        runner('servo', servo, 1),
        NewtonIntegrator(damping=P['damping']),
    ]


# ---------------------------------------------------------------- preparation --------------------------------
def settle(P, tol=1e-3, unbalanced=0.01, chunk=500, max_iter=300000):
    """Run until every normal stress is sigma3 within tol and the unbalanced force is below `unbalanced`."""
    start = O.iter
    while True:
        O.run(chunk, True)
        s = utils.getStress()
        err = max(abs(s[a, a] + P['sigma3']) for a in range(3)) / P['sigma3']
        if err < tol and utils.unbalancedForce() < unbalanced:
            return
        if O.iter - start > max_iter:
            raise RuntimeError(
                'periodic_triaxial: no equilibrium at sigma3 in %d iterations (stress error %.3g, '
                'unbalanced force %.3g)' % (max_iter, err, utils.unbalancedForce())
            )


def prepare(P):
    """The dense packing under the isotropic stress sigma3, dry, with the tests' friction; kept by
    O.saveTmp('consolidated') (the flow engine is added after loading it). Returns its description."""
    O.reset()
    O.periodic = True
    n, r, fuzz = P['num_spheres'], P['radius'], P['rRelFuzz']
    side = (n * 4.0 / 3.0 * math.pi * r**3 * (1 + fuzz * fuzz) / 0.3) ** (1.0 / 3.0)  # a cloud of solid fraction 0.3
    O.cell.setBox(side, side, side)
    O.materials.append(
        FrictMat(
            young=P['young'],
            poisson=P['poisson'],
            frictionAngle=math.radians(P['compaction_friction']),
            density=P['density'],
            label='grains',
        )
    )
    cloud = pack.SpherePack()
    placed = cloud.makeCloud(Vector3(0, 0, 0), Vector3(side, side, side), r, fuzz, n, True, seed=P['seed'])
    if placed != n:
        raise RuntimeError('periodic_triaxial: makeCloud placed %d spheres of %d' % (placed, n))
    cloud.toSimulation(material='grains')
    O.dt = 0.5 * utils.PWaveTimeStep()
    O.engines = engines(CellServo(P['sigma3'], (0, 1, 2), 10 * strain_rate(P)), P)
    settle(P)
    compacted = O.iter
    utils.setContactFriction(math.radians(P['friction']))
    settle(P)
    O.cell.trsf = Matrix3.Identity
    O.saveTmp('consolidated')
    solid = solid_volume()
    prep = dict(
        spheres=n,
        compaction_iterations=compacted,
        iterations=O.iter,
        cell_volume=O.cell.volume,
        solid_volume=solid,
        porosity=1 - solid / O.cell.volume,
        dt=O.dt,
    )
    log(
        '%d spheres compacted to %g Pa in %d iterations, settled with friction %g deg: porosity %.4f'
        % (n, P['sigma3'], compacted, P['friction'], prep['porosity'])
    )
    return prep


# ---------------------------------------------------------------- the tests --------------------------------
def measure(servo, t0):
    """One record (compression positive)."""
    s, u = servo.stress, servo.u
    F = O.cell.trsf
    sa = -s[AXIAL, AXIAL]
    sr = -0.5 * (s[0, 0] + s[1, 1])
    p_eff = (sa + 2 * sr) / 3
    return dict(
        iter=O.iter,
        t=O.time - t0,
        eps_a=-math.log(F[AXIAL, AXIAL]),
        eps_v=-math.log(F.determinant()),
        q=sa - sr,
        p_eff=p_eff,
        u=u,
        p_total=p_eff + u,
        sigma_r_eff=sr,
        sigma_r_total=sr + u,
        volume=O.cell.hSize.determinant(),  # as the flow engine computes it
        unbalanced=utils.unbalancedForce(),
    )


def permeability(P):
    """kappa of the consolidated packing along z: one step of the flow engine alone (nothing moves) under a unit
    pressure gradient, kappa = -mu v_z / gradP_z (Darcy)."""
    O.loadTmp('consolidated')
    flow = PeriodicFlowEngine(viscosity=P['viscosity'], gradP=Vector3(0, 0, 1))
    O.engines = [flow]
    O.step()
    return -flow.averageVelocity()[2] * P['viscosity']


def drains_per_side(P, volume):
    return max(1, int(round(volume ** (1.0 / 3.0) / P['drain_spacing'])))


def impose_drains(flow, P):
    """p = 0 imposed in the pores holding the points of an n x n x n grid over the cell."""
    h = O.cell.hSize
    n = drains_per_side(P, h.determinant())
    for i in range(n):
        for j in range(n):
            for k in range(n):
                flow.imposePressure(h * Vector3((i + 0.5) / n, (j + 0.5) / n, (k + 0.5) / n), 0.0)


def shear(P, drained):
    """One test from the consolidated packing; returns its records (yade.plot.data, as lists) and its steps."""
    O.loadTmp('consolidated')
    K = 0.0 if drained else P['bulk_modulus']
    # defTolerance = 0: a remesh every meshUpdateInterval steps and at no other time, which the test's fluid balance
    # reads off the records
    flow = PeriodicFlowEngine(
        viscosity=P['viscosity'],
        fluidBulkModulus=K,
        meshUpdateInterval=P['mesh_update_interval'],
        defTolerance=0,
        label='flow',
    )
    if drained:
        impose_drains(flow, P)
    rate = strain_rate(P)
    servo = CellServo(P['sigma3'], LATERAL, 10 * rate, rate, flow, K)
    plot.reset()
    t0 = O.time

    def record():
        plot.addData(**measure(servo, t0))

    O.engines = engines(servo, P, flow) + [runner('record', record, P['record_every'])]
    steps = int(round(P['axial_strain'] / (rate * O.dt)))
    wall = time.time()
    O.run(steps, True)  # the recorder runs at the first step (u = 0: no volume change counted yet), then every so often
    name = 'drained' if drained else 'undrained'
    log('%s: %d steps, %d records, %.1f s' % (name, steps, len(plot.data['iter']), time.time() - wall))
    return {k: [float(x) for x in v] for k, v in plot.data.items()}, steps


def summarize(P, prep, und, dr):
    """The figures of summary.json."""
    fluid0 = prep['cell_volume'] - prep['solid_volume']
    drains = drains_per_side(P, prep['cell_volume']) ** 3
    first = 1  # the first record after the start
    lateral = [abs(x - P['sigma3']) / P['sigma3'] for x in und['sigma_r_total']]
    lateral += [abs(x - P['sigma3']) / P['sigma3'] for x in dr['sigma_r_eff']]
    return dict(
        parameters=P,
        prepared=prep,
        strain_rate=strain_rate(P),
        fluid_volume=fluid0,
        drains=drains,
        # the pressure that drives a volume rate V eps_a' to one of the drains (point sinks of the grains' radius)
        drain_pressure_scale=P['viscosity']
        * prep['cell_volume']
        * strain_rate(P)
        / (4 * math.pi * prep['permeability'] * P['radius'] * drains),
        undrained=dict(
            # Skempton's B for an elastic isotropic skeleton (A = 1/3)
            du_over_dp_first_record=und['u'][first] / (und['p_total'][first] - P['sigma3']),
            u_max=max(und['u']),
            u_end=und['u'][-1],
            q_peak=max(und['q']),
            q_end=und['q'][-1],
            p_eff_end=und['p_eff'][-1],
            eps_v_end=und['eps_v'][-1],
        ),
        drained=dict(
            q_peak=max(dr['q']),
            p_eff_at_q_peak=dr['p_eff'][dr['q'].index(max(dr['q']))],
            eps_v_min=min(dr['eps_v']),
            eps_v_end=dr['eps_v'][-1],
            u_max_abs=max(abs(x) for x in dr['u']),
            u_over_p_eff_max=max(abs(u) / p for u, p in zip(dr['u'], dr['p_eff'])),
            stated_fraction=DRAINED_FRACTION,
        ),
        lateral_stress_error_max=max(lateral),
    )


# ---------------------------------------------------------------- outputs ----------------------------------
def write_csv(path, data):
    keys = list(data.keys())
    with open(path, 'w') as f:
        f.write(','.join(keys) + '\n')
        for i in range(len(data[keys[0]])):
            f.write(','.join(repr(data[k][i]) for k in keys) + '\n')


def plot_tests(und, dr, P, path):
    import matplotlib

    if HEADLESS:
        matplotlib.use('Agg')
    import matplotlib.pyplot as plt

    kPa, pct = 1e-3, 100.0
    fig, ax = plt.subplots(2, 2, figsize=(10, 8))
    tests = (('undrained', und, 'C0'), ('drained', dr, 'C1'))
    for name, d, c in tests:
        ea = [pct * x for x in d['eps_a']]
        ax[0, 0].plot(ea, [kPa * x for x in d['q']], color=c, label=name)
        ax[0, 1].plot([kPa * x for x in d['p_eff']], [kPa * x for x in d['q']], color=c, label=name + " (p', q)")
        ax[1, 0].plot(ea, [kPa * x for x in d['u']], color=c, label=name)
        ax[1, 1].plot(ea, [pct * x for x in d['eps_v']], color=c, label=name)
    q_max = max(max(und['q']), max(dr['q']))
    ax[0, 1].plot(
        [kPa * P['sigma3'], kPa * (P['sigma3'] + q_max / 3)], [0, kPa * q_max], 'k--', lw=0.8, label='total stress path'
    )
    ax[0, 0].set(xlabel='axial strain [%]', ylabel='q [kPa]', title='Deviator stress')
    ax[0, 1].set(xlabel="p' [kPa]", ylabel='q [kPa]', title='Stress paths')
    ax[1, 0].set(xlabel='axial strain [%]', ylabel='u [kPa]', title='Excess pore pressure')
    ax[1, 1].set(xlabel='axial strain [%]', ylabel='volumetric strain [%] (contraction > 0)', title='Volume')
    for a in ax.flat:
        a.grid(alpha=0.3)
        a.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=80)
    plt.close(fig)


def main(argv):
    wall = time.time()
    opts = parse_args(argv)
    P = parameters(opts)
    out = opts['out'] or ('periodic_triaxial' + ('-quick' if opts['quick'] else ''))
    os.makedirs(out, exist_ok=True)
    prep = prepare(P)
    prep['permeability'] = permeability(P)
    log(
        'permeability %.4g m2; axial strain rate %.4g 1/s, dt %.4g s, K_f %g Pa, %d drains in the drained test'
        % (
            prep['permeability'],
            strain_rate(P),
            prep['dt'],
            P['bulk_modulus'],
            drains_per_side(P, prep['cell_volume']) ** 3,
        )
    )
    und, prep['undrained_steps'] = shear(P, drained=False)
    dr, prep['drained_steps'] = shear(P, drained=True)
    summary = summarize(P, prep, und, dr)
    summary['seconds'] = time.time() - wall
    write_csv(os.path.join(out, 'undrained.csv'), und)
    write_csv(os.path.join(out, 'drained.csv'), dr)
    with open(os.path.join(out, 'summary.json'), 'w') as f:
        json.dump(summary, f, indent=1)
    plot_tests(und, dr, P, os.path.join(out, 'periodic_triaxial.png'))
    u, d = summary['undrained'], summary['drained']
    log(
        'undrained: u / (p - sigma3) at the first record %.4f, u max %.4g Pa, u end %.4g Pa, q peak %.4g Pa, '
        'p\' end %.4g Pa' % (u['du_over_dp_first_record'], u['u_max'], u['u_end'], u['q_peak'], u['p_eff_end'])
    )
    log(
        'drained: q peak %.4g Pa at p\' %.4g Pa, eps_v end %.4g, max |u| %.4g Pa (the drain\'s scale %.3g Pa), '
        'max |u| / p\' %.4g (stated bound %g)'
        % (
            d['q_peak'],
            d['p_eff_at_q_peak'],
            d['eps_v_end'],
            d['u_max_abs'],
            summary['drain_pressure_scale'],
            d['u_over_p_eff_max'],
            DRAINED_FRACTION,
        )
    )
    log(
        'max lateral stress error / sigma3 %.3g; outputs in %s (%.1f s)'
        % (summary['lateral_stress_error_max'], out, summary['seconds'])
    )
    return 0


if __name__ == '__main__':
    # Headless, leave yade at the end (an exception gives exit status 1); with the GUI, keep the session open.
    _status = main(sys.argv[1:])
    if HEADLESS:
        sys.exit(_status)
