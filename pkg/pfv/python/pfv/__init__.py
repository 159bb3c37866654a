"""PFV: pore-scale finite-volume fluid coupling for YADE.

``from pfv import FlowEngine`` replaces YADE's built-in FlowEngine in a scene script.
"""
from ._core import Engine  # noqa: F401
