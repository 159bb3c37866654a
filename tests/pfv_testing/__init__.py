"""Scenes, timing and helpers shared by the benchmarks (bench/) and the YADE tests (tests/yade/).

The build links this folder into build/python (the PYTHONPATH of every test), so a script imports it as
`from pfv_testing import scenes`, with no change to the import path:

    PYTHONPATH=build/python yade-double -n -x bench/...

It is not installed: it belongs to the repository's tests and benchmarks, not to the pfv package.
"""
