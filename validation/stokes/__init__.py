"""Stokes flow by finite elements against PFV and YADE on the thesis' frozen packings (doc/validation.md section 7).

``run`` drives the comparison and writes JSON into ``results/`` (not tracked), ``report`` prints its tables;
``packings``, ``mesh``, ``solve``, ``pfv_model`` and ``yade_model`` hold one part each. ``periodic_mesh``,
``periodic_solve`` and ``periodic_run`` are the periodic reference on arrays of spheres (section 7.6).
"""
