"""YADE's file outputs of a pfv.FlowEngine, a part of the engine: pressureProfile, printVertices,
exportTriplets, exportMatrix, cholmodStats (a print) and saveVtk (VTK files for ParaView, written
outside the engine's lock: a step or a query need not wait for the disk).
"""
from __future__ import annotations

import os
import sys
import threading
from typing import Any

import numpy as np

import yade

from . import _attributes as attributes
from ._coupled_bodies import CoupledBodies


class FileOutputs:
    """The outputs of the engine whose pfv.Engine is `core`, whose coupled bodies are `bodies` and whose
    lock is `lock`."""

    def __init__(self, core: Any, bodies: CoupledBodies, lock: threading.RLock) -> None:
        self._core = core
        self._bodies = bodies
        self._lock = lock

    def pressureProfile(self, wallUpY: float, wallDownY: float) -> None:
        """Append to the file Pressure_profile the mean pore pressure of 6 levels y = wallDownY + k (wallUpY -
        wallDownY) / 6, k = 0 .. 5, each sampled at 6 points across z at mid x, one line per level. YADE writes
        the running mean over the levels so far (its sums are not reset per level); PFV the level's mean."""
        self._bodies.require_mesh()
        up = attributes.as_number("wallUpY", wallUpY)
        down = attributes.as_number("wallDownY", wallDownY)
        walls = self._core.walls()
        inset = 1e-9 * max(walls[1] - walls[0], walls[3] - walls[2], walls[5] - walls[4])
        x = 0.5 * (walls[0] + walls[1])
        lines = []
        for k in range(6):
            y = min(max(down + k * (up - down) / 6, walls[2] + inset), walls[3] - inset)
            pressures = []
            for j in range(6):
                z = min(max(walls[4] + j * (walls[5] - walls[4]) / 5, walls[4] + inset), walls[5] - inset)
                cell = self._core.locate((x, y, z))
                if cell >= 0:
                    pressures.append(self._core.cell_pressure(cell))
            lines.append(f"{np.mean(pressures):g}" if pressures else "nan")
        with open("Pressure_profile", "a") as f:
            f.write("\n".join(lines) + "\n")

    def printVertices(self) -> None:
        """Write vertices.txt as YADE does ("id x y z r alpha fictious"): the walls first, each as the point of
        its plane at the middle of its face with radius inf (PFV's walls are planes, YADE's large spheres),
        then the spheres at the last step's positions."""
        self._bodies.require_mesh()
        walls = self._core.walls()
        centre = [0.5 * (walls[2 * a] + walls[2 * a + 1]) for a in range(3)]
        lines = ["id x y z r alpha fictious"]
        for w, body in enumerate(self._bodies.stepped.wall_ids):
            point = list(centre)
            point[w // 2] = walls[w]
            lines.append(f"{body} {point[0]:g} {point[1]:g} {point[2]:g}  inf 0 1")
        for body, x, r in zip(self._bodies.stepped.ids, self._core.last_positions(), self._bodies.stepped.radii):
            lines.append(f"{body} {x[0]:g} {x[1]:g} {x[2]:g}  {r:g} 0 0")
        with open("vertices.txt", "w") as f:
            f.write("\n".join(lines) + "\n")

    def _lower_triangle(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
        """G's lower triangle by column (rows ascending within a column), as YADE's matrix A: (col, row, value, n)."""
        m = self._core.system_matrix()
        start, row, value = m["col_start"], m["row"], m["value"]
        n = len(start) - 1
        col = np.repeat(np.arange(n), np.diff(start))
        # The upper entry (row r, column c) is the lower entry (row c, column r).
        order = np.lexsort((col, row))
        return row[order], col[order], value[order], n

    def exportTriplets(self, filename: str = "triplets") -> None:
        """Write G's lower triangle, one "row col value" line per entry by column, as YADE does (rows and
        columns are the unknown cells in cell order; YADE numbers them in the order it meets them)."""
        self._bodies.require_mesh()
        lower_col, lower_row, value, _ = self._lower_triangle()
        with open(str(filename), "w") as f:
            f.writelines(f"{r} {c} {v:g}\n" for r, c, v in zip(lower_row, lower_col, value))

    def exportMatrix(self, filename: str = "matrix") -> None:
        """Write G's lower triangle as YADE does (Eigen's print of a sparse matrix): its entries by column as
        (value,row), the column pointers, then every row in full, zeros included."""
        self._bodies.require_mesh()
        lower_col, lower_row, value, n = self._lower_triangle()
        pointers = np.searchsorted(lower_col, np.arange(n))
        text = [f"{v:g}" for v in value]
        with open(str(filename), "w") as f:
            f.write("Nonzero entries:\n")
            f.write("".join(f"({t},{r}) " for t, r in zip(text, lower_row)) + "\n\n")
            f.write("Outer pointers:\n" + "".join(f"{p} " for p in pointers) + " $\n\n")
            by_row = np.lexsort((lower_col, lower_row))
            row_start = np.searchsorted(lower_row[by_row], np.arange(n + 1))
            for r in range(n):
                line = ["0"] * n
                for k in by_row[row_start[r] : row_start[r + 1]]:
                    line[lower_col[k]] = text[k]
                f.write(" ".join(line) + " \n")

    def cholmodStats(self) -> None:
        """Print CHOLMOD's report on the current factor, then its ordering method and whether METIS ran."""
        self._bodies.require_mesh()
        if not self._core.print_cholmod_statistics("PFV Cholmod factorization"):
            print("cholmodStats: the current solver is not CHOLMOD (useSolver=3)", file=sys.stderr)

    def saveVtk(
        self, folder: str | os.PathLike = "./VTK", withBoundaries: bool = False, compress: bool = False
    ) -> None:
        """Write the pore network (pressure, mean fluid velocity, imposed-pressure flag, volumes) and the spheres
        (radii, ids, fluid forces) of the last step into `folder` as VTK XML files for ParaView: out_<N>.vtu,
        spheres_<N>.vtu and the collection out.pvd of every snapshot this process wrote there, at O.time.
        withBoundaries=False leaves out the cells with a wall vertex (YADE's default); compress=True compresses
        the data with zlib. See doc/yade.md, "VTK output"."""
        if not isinstance(folder, (str, os.PathLike)):
            raise TypeError(f"saveVtk folder must be a path, got {folder!r}")
        with_boundaries = attributes.as_flag("saveVtk withBoundaries", withBoundaries)
        compress = attributes.as_flag("saveVtk compress", compress)
        try:
            from . import _vtk_output
        except ImportError as error:
            raise ImportError(
                f"pfv.FlowEngine.saveVtk needs VTK's Python package (Debian: apt-get install " f"python3-vtk9): {error}"
            ) from None
        with self._lock:
            self._bodies.require_mesh()
            scan = self._bodies.stepped
            state = _vtk_output.read_state(self._core, scan.ids, scan.radii, scan.wall_ids, yade.O.time)
        _vtk_output.save(state, os.fspath(folder), with_boundaries, compress)
