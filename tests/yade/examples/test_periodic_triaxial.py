"""examples/periodic_triaxial.py: the undrained cell keeps its fluid, the drained one drains, and the example runs.

    yade-double -n -x tests/yade/examples/test_periodic_triaxial.py        (exit 0 = pass, 1 = fail)

1. Undrained isotropic compression, in this process with the example's functions: its --quick packing (300
   spheres, dense, at 100 kPa), pfv.PeriodicFlowEngine with fluidBulkModulus K_f, the cell shortened along its
   three axes at a tenth of the example's axial rate (O.cell.velGrad; the spheres go with it and interact). No
   fluid leaves a periodic cell, so the fluid volume-weighted mean pressure (average_fluid_pressure()) must rise by
   exactly what the engine's storage gives: each pore stores V_f,i / (K_f dt) per unit pressure, V_f,i measured at
   the remesh, so summing the pores' balances (the throat fluxes cancel) gives sum_i V_f,i dp_i = -K_f dV per step,
   dV the change of all the pores' volume, which is the change of the cell's volume (the pores tile the cell).
   Between two remeshes the mean therefore rises by K_f (V_start - V_end) / V_f, V_f = V_mesh - the spheres'
   volume (the pores' fluid volumes add up to that: each sphere's solid angles in its pores add up to 4 pi, overlaps
   or not, as long as no pore is emptied: doc/periodic.md), all computed here from O.cell.hSize and the radii.
   Checked to 1e-6 over 40 steps in one mesh, and over 40 steps with a remesh every 10 against the sum of
   K_f dV_k / V_f,k over the meshes (the discrete scheme; the continuum K_f ln(V_f0 / V_f) differs by 2e-5). The
   second also needs each remesh to carry the pressures over without changing their V_f-weighted mean, which holds
   as far as the pressure is uniform (nearly so here: a uniform compression, water's viscosity).
2. Runs `yade-double -n -x examples/periodic_triaxial.py --quick --out=DIR` (the inherited environment: PYTHONPATH
   must reach the pfv package) and checks its outputs:
   * undrained.csv, drained.csv, summary.json and periodic_triaxial.png are written, with a record every
     record_every steps;
   * undrained: the mean pressure against the cell's volume in the records, K_f dV / V_f, to 1e-6 of u before the
     first remesh, and over the whole test (a remesh every 100 steps) to 1e-6 of sigma3: the remeshes carry the
     V_f-weighted mean pressure over (measured 2e-8 of sigma3 over 71 remeshes; 2e-6 when it was carried by position
     alone). Without the dV/dt term, without the carry-over or with the storage wrong the error
     is of the order of u itself (up to sigma3 here);
   * the total lateral stress (sigma'_r + u) in the undrained test and the effective one in the drained test within
     1 % of sigma3: the servo holds what each test must hold (holding sigma'_r in the undrained test would miss by
     u, up to sigma3);
   * dilatancy of a dense packing: in the drained test the cell contracts first (eps_v > 0), then dilates
     (eps_v < 0 at 4 %); the undrained pressure rises first, then falls below zero, so that the undrained p' ends
     above the drained one; the drained q peaks, then softens;
   * drained: max |u| / p' below the fraction the example states, 1e-3 (measured 1e-4). The drained pressure is
     what drives the expelled fluid to the drains; with the engine's reference pore as the only drain it is about
     1 % of p', and the undrained one is 30 % of p' and more.
"""
import csv
import importlib.util
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile

from pfv_testing import checks, paths

EXAMPLE = paths.example('periodic_triaxial.py')
DRAINED_FRACTION = 1e-3  # the example's docstring: the drained max |u| / p' stays below this


def load_example():
    """The example as a module (its run is under `if __name__ == '__main__'`); registered in sys.modules, where
    its PyRunners find it."""
    spec = importlib.util.spec_from_file_location('periodic_triaxial', EXAMPLE)
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


# ---------------------------------------------------------------- 1. undrained isotropic compression ---------
def compress(ex, P, steps, interval):
    """From the prepared packing: `steps` steps of isotropic compression after the meshing step. Returns the mean
    pressure and the cell's volume after each step (the first: the meshing step)."""
    from yade import O
    from pfv import PeriodicFlowEngine

    O.loadTmp('consolidated')
    flow = PeriodicFlowEngine(
        viscosity=P['viscosity'],
        fluidBulkModulus=P['bulk_modulus'],
        meshUpdateInterval=interval,
        defTolerance=0,  # remeshes every `interval` steps only
        label='flow',
    )
    rate = ex.strain_rate(P) / 10
    O.engines = ex.engines(ex.CellServo(P['sigma3'], (), 1.0, rate, flow, P['bulk_modulus']), P, flow)
    u, volume = [], []
    for _ in range(steps + 1):
        O.step()
        u.append(flow.average_fluid_pressure())
        volume.append(O.cell.hSize.determinant())
    return u, volume


def sphere_radii():
    from yade import O

    return [b.shape.radius for b in O.bodies]


def isotropic(ex):
    P = ex.parameters(ex.parse_args(['--quick']))
    prep = ex.prepare(P)
    solid = sum(4.0 / 3.0 * math.pi * r**3 for r in sphere_radii())
    K, steps = P['bulk_modulus'], 40
    u, volume = compress(ex, P, steps, 10**6)
    expected = K * (volume[0] - volume[-1]) / (volume[0] - solid)
    rise = u[-1] - u[0]
    checks.check(
        'undrained isotropic compression, one mesh: mean pressure rise = K_f dV / V_f',
        abs(rise / expected - 1) <= 1e-6,
        '(%.10g Pa vs %.10g Pa, relative %.2e; dV / V = %.3g, porosity %.4f)'
        % (rise, expected, rise / expected - 1, (volume[0] - volume[-1]) / volume[0], prep['porosity']),
    )
    interval = 10
    u, volume = compress(ex, P, steps, interval)
    expected = 0.0
    for k in range(steps):
        # step k + 1 moves the volume from volume[k] to volume[k + 1]; the remeshes are at steps 0, 10, 20, ...
        mesh = volume[((k + 1) // interval) * interval]
        expected += K * (volume[k] - volume[k + 1]) / (mesh - solid)
    rise = u[-1] - u[0]
    continuum = K * math.log((volume[0] - solid) / (volume[-1] - solid))
    checks.check(
        'undrained isotropic compression, a remesh every %d steps: rise = sum of K_f dV_k / V_f,k' % interval,
        abs(rise / expected - 1) <= 1e-6,
        '(%.10g Pa vs %.10g Pa, relative %.2e; the continuum K_f ln(V_f0 / V_f) would be %.2e off)'
        % (rise, expected, rise / expected - 1, continuum / expected - 1),
    )


# ---------------------------------------------------------------- 2. the example --------------------------------
def read_csv(path):
    with open(path) as f:
        return [{k: float(v) for k, v in row.items()} for row in csv.DictReader(f)]


def run_example(out):
    yade = shutil.which('yade-double') or '/usr/bin/yade-double'
    cmd = [yade, '-n', '-x', EXAMPLE, '--quick', '--out=' + out]
    print('running: ' + ' '.join(cmd), flush=True)
    proc = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    print('\n'.join(line for line in proc.stdout.splitlines() if line.startswith('periodic_triaxial:')))
    names = ('undrained.csv', 'drained.csv', 'summary.json', 'periodic_triaxial.png')
    missing = [
        n for n in names if not os.path.isfile(os.path.join(out, n)) or not os.path.getsize(os.path.join(out, n))
    ]
    if not checks.check(
        'the example completes and writes its outputs',
        proc.returncode == 0 and not missing,
        '(exit code %d, missing %s)' % (proc.returncode, missing),
    ):
        print(proc.stdout[-3000:])
        return None
    with open(os.path.join(out, 'periodic_triaxial.png'), 'rb') as f:
        checks.check('periodic_triaxial.png is a PNG', f.read(8) == b'\x89PNG\r\n\x1a\n')
    with open(os.path.join(out, 'summary.json')) as f:
        s = json.load(f)
    return s, read_csv(os.path.join(out, 'undrained.csv')), read_csv(os.path.join(out, 'drained.csv'))


def undrained_mass(s, und):
    """u against K_f dV / V_f from the records (every remesh is a record: the interval is a multiple of theirs)."""
    P = s['parameters']
    K, solid, sigma3 = P['bulk_modulus'], s['prepared']['solid_volume'], P['sigma3']
    interval, start = P['mesh_update_interval'], und[0]['iter']
    checks.check('every remesh is a record', interval % P['record_every'] == 0)
    first = [r for r in und if start < r['iter'] < start + interval]
    worst = max(abs(r['u'] / (K * (und[0]['volume'] - r['volume']) / (und[0]['volume'] - solid)) - 1) for r in first)
    checks.check(
        'undrained test, first mesh: u = K_f dV / V_f',
        worst <= 1e-6,
        '(largest relative difference %.2e over %d records)' % (worst, len(first)),
    )
    expected, mesh, worst = 0.0, und[0]['volume'], 0.0
    for before, r in zip(und, und[1:]):
        expected += K * (before['volume'] - r['volume']) / (mesh - solid)
        worst = max(worst, abs(r['u'] - expected) / sigma3)
        if (r['iter'] - start) % interval == 0:
            mesh = r['volume']
    checks.check(
        'undrained test, %d remeshes: u = sum of K_f dV_k / V_f,k' % ((und[-1]['iter'] - start) // interval),
        worst <= 1e-6,
        '(largest difference %.2e of sigma3; u from %.4g to %.4g Pa)'
        % (worst, min(r['u'] for r in und), max(r['u'] for r in und)),
    )


def example_checks(s, und, dr):
    P = s['parameters']
    sigma3 = P['sigma3']
    every = P['record_every']
    rows = [(s['prepared'][t + '_steps'] - 1) // every + 1 for t in ('undrained', 'drained')]  # the first step, ...
    checks.check(
        'a record every record_every steps',
        [len(und), len(dr)] == rows,
        '(%d and %d records, %s expected)' % (len(und), len(dr), rows),
    )
    undrained_mass(s, und)
    lateral = max(abs(r['sigma_r_total'] / sigma3 - 1) for r in und[1:])
    checks.check(
        'undrained: total lateral stress sigma\'_r + u = sigma3 within 1 %',
        lateral <= 0.01,
        '(largest difference %.2e of sigma3)' % lateral,
    )
    lateral = max(abs(r['sigma_r_eff'] / sigma3 - 1) for r in dr[1:])
    checks.check(
        'drained: effective lateral stress = sigma3 within 1 %',
        lateral <= 0.01,
        '(largest difference %.2e of sigma3)' % lateral,
    )
    checks.check(
        'drained: the cell contracts first, then dilates',
        dr[1]['eps_v'] > 0 > dr[-1]['eps_v'],
        '(eps_v at the first record %.3g, max %.3g, end %.3g)'
        % (dr[1]['eps_v'], max(r['eps_v'] for r in dr), dr[-1]['eps_v']),
    )
    checks.check(
        'undrained: the pressure rises first, then falls below zero',
        und[1]['u'] > 0 > und[-1]['u'],
        '(u at the first record %.4g Pa, max %.4g Pa, end %.4g Pa)'
        % (und[1]['u'], max(r['u'] for r in und), und[-1]['u']),
    )
    checks.check(
        'undrained p\' ends above drained p\' (the dilatant cell draws its pressure down)',
        und[-1]['p_eff'] > dr[-1]['p_eff'],
        '(%.4g vs %.4g Pa)' % (und[-1]['p_eff'], dr[-1]['p_eff']),
    )
    q_peak = max(r['q'] for r in dr)
    checks.check(
        'drained: q peaks, then softens', dr[-1]['q'] < q_peak, '(peak %.4g Pa, end %.4g Pa)' % (q_peak, dr[-1]['q'])
    )
    fraction = max(abs(r['u']) / r['p_eff'] for r in dr)
    checks.check(
        'drained: max |u| / p\' below the stated fraction',
        fraction < DRAINED_FRACTION,
        '(%.2e, stated %g; undrained %.3f)' % (fraction, DRAINED_FRACTION, max(abs(r['u']) / r['p_eff'] for r in und)),
    )


def main():
    isotropic(load_example())
    out = tempfile.mkdtemp(prefix='pfv-periodic-triaxial-test-')
    result = run_example(out)
    if result is not None:
        example_checks(*result)
    print('outputs in %s' % out)
    if not checks.failures:
        shutil.rmtree(out, ignore_errors=True)
    checks.report('periodic_triaxial')


main()
