"""pfv refuses to import inside a YADE other than the one its bridge is pinned to.

The bridge (pkg/pfv/yade_bridge) reads YADE's objects by their memory layout in one YADE version
(yade_version.hpp, pfv._core.PINNED_YADE_VERSION). Checked here: the running YADE is that version;
the check refuses another version string with an ImportError naming both; and `import pfv` in a
YADE whose yade.config.version reads otherwise raises that error (in a fresh yade-double).
"""
import os
import subprocess
import tempfile

import yade.config

from pfv import _core
from pfv._yade_version import YadeVersionError, check
from pfv_testing import checks


pinned = _core.PINNED_YADE_VERSION
checks.check(f"the running YADE {yade.config.version} is the pinned {pinned}", yade.config.version == pinned)

try:
    check(pinned, pinned)
    checks.check("the pinned version passes", True)
except ImportError as error:
    checks.check(f"the pinned version passes ({error})", False)

for other in ("2024.06a", "2023.02", "3.14"):
    try:
        check(other, pinned)
        checks.check(f"{other} is refused", False)
    except YadeVersionError as error:
        message = str(error)
        checks.check(
            f"{other} is refused with an ImportError naming both versions",
            isinstance(error, ImportError) and other in message and pinned in message,
        )

# The check at import: a fresh YADE whose version reads as another one.
script = (
    "import sys, yade.config\nyade.config.version = '2099.01z'\n"
    "try:\n    import pfv\nexcept ImportError as error:\n    print('REFUSED', error)\n    sys.exit(0)\n"
    "print('IMPORTED')\nsys.exit(1)\n"
)
with tempfile.TemporaryDirectory() as folder:
    path = os.path.join(folder, "other_yade.py")
    with open(path, "w") as f:
        f.write(script)
    out = subprocess.run(["yade-double", "-n", "-x", path], cwd=folder, capture_output=True, text=True)
refused = [line for line in out.stdout.splitlines() if line.startswith("REFUSED")]
print(out.stdout[-600:], out.stderr[-600:])
checks.check(
    "import pfv under YADE 2099.01z raises ImportError naming both versions",
    out.returncode == 0 and bool(refused) and "2099.01z" in refused[0] and pinned in refused[0],
)

checks.report("YADE version pin")
