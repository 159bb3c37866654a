"""PFV's permeability and forces on a frozen packing (pfv._core.Engine, no YADE).

Same problem as solve.py: walls at the faces of the unit cube, pressure dp on y = 0 and 0 on
y = 1, the lateral walls no-slip or slip (symmetry), the slip walls with the thesis' formula
(wall surfaces left out of R_h) or with YADE's extra factor on R_h (``yade_wall_throat_factor``).
kappa = mu Q l0 / (dp S) with Q the flux through the outlet wall (S = l0^2 = 1).
"""
import numpy as np
import pfv

WALLS = [0.0, 1.0, 0.0, 1.0, 0.0, 1.0]
FACES = ("xmin", "xmax", "ymin", "ymax", "zmin", "zmax")
VARIANTS = ("noslip", "slip", "slip_yade")


def run(packing, variant, dp=1.0, mu=1.0, entrance=0.0):
    centres = np.ascontiguousarray(packing["centres"], dtype=float)
    radii = np.ascontiguousarray(packing["radii"], dtype=float)
    e = pfv.Engine()
    e.viscosity = mu
    e.conductance_entrance = entrance
    e.slip_boundary = variant != "noslip"
    e.yade_wall_throat_factor = variant == "slip_yade"
    e.bnd_is_pressure = [False, False, True, True, False, False]
    e.bnd_value = [0.0, 0.0, dp, 0.0, 0.0, 0.0]
    e.step(centres, radii, WALLS, 1.0)
    q_out = e.boundary_flux(3)
    q_in = e.boundary_flux(2)
    pressure, viscous = e.force_parts(centres, radii, WALLS)
    forces = {}
    for k in range(len(radii)):
        forces["sphere%d" % k] = {"pressure": pressure[k].tolist(), "viscous": viscous[k].tolist()}
    for w, name in enumerate(FACES):
        forces[name] = {"pressure": pressure[len(radii) + w].tolist(), "viscous": viscous[len(radii) + w].tolist()}
    total = np.asarray(e.forces())
    return {
        "variant": variant,
        "flux_in": -q_in,
        "flux_out": q_out,
        "kappa": mu * q_out / dp,
        "cells": e.n_cells(),
        "forces": forces,
        "split_error": float(np.abs(pressure + viscous - total).max()),
    }
