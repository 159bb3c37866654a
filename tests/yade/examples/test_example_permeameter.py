"""examples/permeameter.py runs headless and what it prints obeys Darcy's law.

    yade-double -n -x tests/yade/examples/test_example_permeameter.py        (exit 0 = pass, 1 = fail)

Runs `yade-double -n -x examples/permeameter.py` (inherited environment: PYTHONPATH must reach the pfv package) and
parses its output: the number of spheres and their mean diameter d, then for dP and 2 dP the fluxes Q_in (ymin
wall), Q_out (ymax wall), the permeability K and the mean pressure of the slices y/L = 0.25, 0.5, 0.75. Checks:

* conservation, |Q_in + Q_out| / |Q_in| <= 1e-10 for both runs. The spheres are fixed, so no pore changes volume
  and the pressure system is div(q) = 0; its interior throat fluxes cancel pairwise, so Q_in + Q_out is the sum of
  the cell residuals of the solve. For this size PFV factorises in double (direct solve: residuals at round-off);
  1e-10 is the accuracy PFV also guarantees with its single-precision factor (refinement_tolerance), so the bound
  holds whichever path is taken. A missing wall term or a stray dV/dt source gives an O(1) imbalance.
* direction: Q_in < 0 < Q_out (YADE's sign, > 0 leaves the sample): the fluid flows from high to low pressure.
* K > 0 and finite, and the same for both pressure drops.
* Darcy linearity, |Q_in(2 dP) / (2 Q_in(dP)) - 1| <= 1e-10: doubling the boundary values doubles the right-hand
  side of a linear system, so the flux doubles to solver accuracy (same bound as above). It fails if the new
  bndCondValue did not reach the solve (ratio 1) or if anything in the flow depended on the pressure level.
* linear mean pressure profile, |p_slice(y) - dP (1 - y/L)| <= dP d / L at each slice: the packing is
  statistically homogeneous, so the mean gradient is uniform, up to the pressure drop over about one grain layer
  (the half pores cut by the pressure walls, and grain-scale heterogeneity averaged over a slice of (L/d)^2 pores).
  With d/L ~ 0.1 here that is 10 % of dP, while pressures imposed on the wrong walls give a flat profile (25 % off
  at y/L = 0.25 and 0.75) and a closed outlet a uniform dP (75 % off).
"""
import math
import os
import re
import shutil
import subprocess
import sys

from pfv_testing import paths


def _here():
    # under `yade-double -x` the script runs in yade's globals: __file__ is /usr/bin/yade-double, sys.argv[0] the script
    if 'yade' in sys.modules and sys.argv and sys.argv[0].endswith('.py'):
        return os.path.dirname(os.path.abspath(sys.argv[0]))
    return os.path.dirname(os.path.abspath(__file__))


HERE = _here()
EXAMPLE = paths.example('permeameter.py')
TOL_CONSERVATION = 1e-10
TOL_LINEARITY = 1e-10
BOX_SIDE_RE = re.compile(r'^(\d+) spheres, mean diameter (\S+) m, box side (\S+) m')
FLUX_RE = re.compile(r'^dP = (\S+) Pa: Q_in = (\S+) m3/s, Q_out = (\S+) m3/s, Q_in \+ Q_out = \S+ m3/s, K = (\S+) m2')
SLICE_RE = re.compile(r'^\s+mean pressure at y/L = (\S+): (\S+) Pa')


def parse(text):
    """Returns (packing dict, [run dict, ...]) from the example's output."""
    packing, runs = None, []
    for line in text.splitlines():
        m = BOX_SIDE_RE.match(line)
        if m:
            packing = dict(n=int(m.group(1)), d=float(m.group(2)), L=float(m.group(3)))
        m = FLUX_RE.match(line)
        if m:
            runs.append(
                dict(
                    dp=float(m.group(1)),
                    q_in=float(m.group(2)),
                    q_out=float(m.group(3)),
                    K=float(m.group(4)),
                    slices=[],
                )
            )
        m = SLICE_RE.match(line)
        if m and runs:
            runs[-1]['slices'].append((float(m.group(1)), float(m.group(2))))
    return packing, runs


def main():
    yade = shutil.which('yade-double') or '/usr/bin/yade-double'
    cmd = [yade, '-n', '-x', EXAMPLE]
    print('running: ' + ' '.join(cmd), flush=True)
    proc = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, timeout=300)
    packing, runs = parse(proc.stdout)
    if proc.returncode != 0 or packing is None or len(runs) != 2 or any(len(r['slices']) != 3 for r in runs):
        print(proc.stdout[-3000:])
        print('FAIL the example did not complete or printed something unexpected (exit code %d)' % proc.returncode)
        return 1
    checks = []  # (ok, message)

    def check(ok, message):
        checks.append((bool(ok), message))

    d_over_l = packing['d'] / packing['L']
    print('packing: %d spheres, d / L = %.4f' % (packing['n'], d_over_l))
    for r in runs:
        imbalance = abs(r['q_in'] + r['q_out']) / abs(r['q_in']) if r['q_in'] else math.inf
        check(
            imbalance <= TOL_CONSERVATION,
            'dP = %g: |Q_in + Q_out| / |Q_in| = %.3e (allowed %g)' % (r['dp'], imbalance, TOL_CONSERVATION),
        )
        check(r['q_in'] < 0 < r['q_out'], 'dP = %g: Q_in = %.6e < 0 < Q_out = %.6e' % (r['dp'], r['q_in'], r['q_out']))
        check(math.isfinite(r['K']) and r['K'] > 0, 'dP = %g: K = %.6e m2 positive and finite' % (r['dp'], r['K']))
        for y, p in r['slices']:
            error = abs(p - r['dp'] * (1 - y)) / r['dp']
            check(
                error <= d_over_l,
                'dP = %g: |p(y/L = %.2f) - linear| / dP = %.4f (allowed d/L = %.4f)' % (r['dp'], y, error, d_over_l),
            )
    first, second = runs
    check(
        abs(second['dp'] / first['dp'] - 2) == 0,
        'second pressure drop is twice the first (%g, %g)' % (first['dp'], second['dp']),
    )
    linearity = abs(second['q_in'] / (2 * first['q_in']) - 1) if first['q_in'] else math.inf
    check(
        linearity <= TOL_LINEARITY,
        'Darcy: |Q_in(2 dP) / (2 Q_in(dP)) - 1| = %.3e (allowed %g)' % (linearity, TOL_LINEARITY),
    )
    k_change = abs(second['K'] / first['K'] - 1) if first['K'] else math.inf
    check(k_change <= 1e-6, 'K(2 dP) / K(dP) - 1 = %.1e (K is printed to 7 digits: allowed 1e-6)' % k_change)
    for ok, message in checks:
        print('%s %s' % ('ok  ' if ok else 'FAIL', message))
    failed = sum(not ok for ok, _ in checks)
    print('%d passed, %d failed' % (len(checks) - failed, failed))
    return 1 if failed else 0


if __name__ == '__main__' and 'yade' in sys.modules:
    sys.exit(main())
elif __name__ == '__main__':
    print('run me with: yade-double -n -x %s' % sys.argv[0])
    sys.exit(2)
