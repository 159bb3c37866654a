"""Candidate conductances on the walled packings of doc/validation.md section 7, against the FEM at touching spheres.

    export PYTHONPATH=$BUILD/python
    /usr/bin/python3 -m validation.stokes.walled_candidates

PFV's walled engine (pfv._core.Engine through pfv_model.run) on the touching packings of section 7 (cubic 8, the
nine centred 9, the three random 25 and two random 54), no-slip and slip lateral walls (slip with the thesis' wetted
perimeter, no YADE factor), with the thesis' conductance and with the orifice in series (ConductanceModel::entrance,
Dagan's beta = 3 pi / 8), against the FEM's limit at zero shrink stored in data/walled_touching.json (section 7.2,
"At the touching spheres"). The thesis' rows reproduce that table's PFV ratios, the check that the same problem is
solved.
"""
import json
import os
import sys

import numpy as np

from . import pfv_model, run

HERE = os.path.dirname(os.path.abspath(__file__))
REFERENCE = os.path.join(HERE, "data", "walled_touching.json")
BETAS = (("thesis", 0.0), ("entrance, beta = 3 pi / 8", 3.0 * np.pi / 8.0))
WALLS = (("slip", "symmetry"), ("noslip", "noslip"))


def main():
    with open(REFERENCE) as f:
        reference = json.load(f)["kappa_fem"]
    lines = [
        "| case | %s |" % " | ".join("%s, %s" % (label, wall) for label, _ in BETAS for wall, _ in WALLS),
        "|---|%s" % ("---|" * (len(BETAS) * len(WALLS))),
    ]
    ratios = {}
    for name, ref in reference.items():
        packing = run.case_packing(name + "@0")
        cells = []
        for label, beta in BETAS:
            for variant, lateral in WALLS:
                kappa = pfv_model.run(packing, variant, entrance=beta)["kappa"]
                ratio = kappa / ref[lateral]
                ratios.setdefault((label, variant, name.startswith("random")), []).append(ratio)
                cells.append("%.3f" % ratio)
        lines.append("| %s | %s |" % (name, " | ".join(cells)))
    print("\n".join(lines))
    print()
    print("| candidate | walls | packings | range of κ / κ_FEM |")
    print("|---|---|---|---|")
    for (label, variant, random), values in ratios.items():
        print(
            "| %s | %s | %s | %.3f – %.3f |"
            % (label, variant, "random" if random else "regular", min(values), max(values))
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
