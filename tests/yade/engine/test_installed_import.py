"""The installed package is importable from any directory by yade-double (no PYTHONPATH).

CTest runs every tests/yade/<group>/test_*.py with PYTHONPATH pointing at the build tree; this one
re-runs a tiny script from a temporary directory with a clean environment instead.
"""
import os
import subprocess
import tempfile

from pfv_testing import checks

script = "import pfv, sys\nfrom pfv import FlowEngine\nprint('PFV_AT', pfv.__file__)\nsys.exit(0)\n"
with tempfile.TemporaryDirectory() as d:
    path = os.path.join(d, "probe.py")
    with open(path, "w") as f:
        f.write(script)
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    out = subprocess.run(["yade-double", "-n", "-x", path], cwd=d, env=env, capture_output=True, text=True)
    print(out.stdout[-500:], out.stderr[-500:])
    location = [line for line in out.stdout.splitlines() if line.startswith("PFV_AT")]
    ok = out.returncode == 0 and location and "dist-packages/pfv" in location[0]
    checks.check("installed pfv importable", bool(ok))
checks.report("installed import")
