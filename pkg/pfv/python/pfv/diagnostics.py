"""What a seabed or deposition run monitors (thesis sections 4.5, 6.2-6.4): pressure sensors, the
hydraulic gradient against the critical one, porosity, settlement, kinetic energy, and profiles of
effective stress and pore pressure along a vertical. The vertical is y (YADE's waveAction loads
ymax); pressures are the engine's excess (piezometric) pressures.

    from pfv import diagnostics
    i_c = diagnostics.critical_gradient(porosity=0.61, rho_s=2600, rho_f=1000)      # 0.624
    grid = diagnostics.SensorGrid.in_box(lo, hi, verticals=5, levels=6)
    ratios = grid.gradient_ratios(grid.pressures(flow), diagnostics.buoyant_unit_weight(0.61, 2600, 1000))

`Monitor` records all of it every `every` steps through YADE's ``plot.addData`` (so
``plot.saveDataTxt`` writes the CSV) and prints progress; `save_plots` draws the PNGs.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Any, Callable, Sequence

import numpy as np

G = 9.81


def buoyant_unit_weight(porosity: float, rho_s: float, rho_f: float, g: float = G) -> float:
    """gamma' = (rho_s - rho_f)(1 - n) g, the submerged weight of the mixture per unit volume (thesis
    4.32, 6.28): the excess pressure gradient that carries grains in suspension."""
    if not 0 <= porosity < 1:
        raise ValueError(f"porosity must be in [0, 1), not {porosity}")
    if not (rho_s > rho_f > 0):
        raise ValueError(f"rho_s ({rho_s}) must exceed rho_f ({rho_f}) > 0")
    return (rho_s - rho_f) * (1 - porosity) * g


def critical_gradient(porosity: float, rho_s: float, rho_f: float) -> float:
    """i_c = gamma' / gamma_f (thesis 4.33-4.34): 0.624 for n = 0.61, rho_s/rho_f = 2.6."""
    return buoyant_unit_weight(porosity, rho_s, rho_f, 1.0) / rho_f


@dataclass(frozen=True)
class SensorGrid:
    """Pressure sensors on `verticals` vertical lines, `levels` heights each (the thesis' 5 x 6)."""

    x: np.ndarray  # per vertical
    z: np.ndarray  # per vertical
    heights: np.ndarray  # per level, increasing

    @classmethod
    def in_box(
        cls, lo: Sequence[float], hi: Sequence[float], verticals: int = 5, levels: int = 6, z: float | None = None
    ) -> SensorGrid:
        """Verticals equally spaced in x across the box (away from the walls by half a spacing), at
        mid-depth in z unless given; levels equally spaced in y the same way."""
        lo, hi = np.asarray(lo, float), np.asarray(hi, float)
        if verticals < 1 or levels < 2:
            raise ValueError("a sensor grid needs at least one vertical and two levels")
        if not np.all(hi > lo):
            raise ValueError(f"the box {lo.tolist()} .. {hi.tolist()} is empty")

        def spaced(a, b, k):
            return a + (np.arange(k) + 0.5) * (b - a) / k

        xs = spaced(lo[0], hi[0], verticals)
        zs = np.full(verticals, 0.5 * (lo[2] + hi[2]) if z is None else z)
        return cls(xs, zs, spaced(lo[1], hi[1], levels))

    def points(self) -> np.ndarray:
        """(verticals, levels, 3) sensor positions."""
        nv, nl = len(self.x), len(self.heights)
        p = np.empty((nv, nl, 3))
        p[:, :, 0] = self.x[:, None]
        p[:, :, 1] = self.heights[None, :]
        p[:, :, 2] = self.z[:, None]
        return p

    def pressures(self, flow: Any) -> np.ndarray:
        """(verticals, levels) excess pressures of the cells holding the sensors."""
        pts = self.points()
        return np.array([[flow.getPorePressure(tuple(q)) for q in line] for line in pts])

    def gradient_ratios(self, pressures: np.ndarray, gamma_prime: float) -> np.ndarray:
        """grad H / i_c between consecutive sensors (thesis 6.28): -dp / (gamma' dy), (verticals,
        levels - 1), level k to k + 1 from the bottom. 1 where the fluid carries the grains' whole
        submerged weight (liquefaction), 0 in a still fluid or a bed resting on its contacts."""
        return -np.diff(pressures, axis=1) / (gamma_prime * np.diff(self.heights)[None, :])


def sphere_arrays(bodies: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """ids, positions, radii, velocities and masses of the dynamic spheres."""
    ids, pos, rad, vel, mass = [], [], [], [], []
    for b in bodies:
        if b is None or b.shape.__class__.__name__ != "Sphere" or not b.dynamic:
            continue
        ids.append(b.id)
        pos.append(tuple(b.state.pos))
        rad.append(b.shape.radius)
        vel.append(tuple(b.state.vel))
        mass.append(b.state.mass)
    return np.array(ids), np.array(pos).reshape(-1, 3), np.array(rad), np.array(vel).reshape(-1, 3), np.array(mass)


def top_height(pos: np.ndarray, radii: np.ndarray, quantile: float = 1.0) -> float:
    """Height of the packing's surface: the highest sphere top (quantile < 1: that quantile of the
    tops, robust to a few grains thrown up)."""
    tops = pos[:, 1] + radii
    return float(np.max(tops) if quantile >= 1 else np.quantile(tops, quantile))


def porosity_below(radii: np.ndarray, area: float, height: float, bottom: float) -> float:
    """1 - sphere volume / (area x (height - bottom)): the packing's porosity under its surface."""
    volume = area * (height - bottom)
    if not volume > 0:
        raise ValueError("the packing's surface is not above its bottom")
    return 1.0 - float(np.sum(4.0 / 3.0 * math.pi * radii**3)) / volume


def kinetic_energy(vel: np.ndarray, mass: np.ndarray) -> float:
    """Translational kinetic energy of the spheres (the thesis does not say whether it counts rotation)."""
    return 0.5 * float(np.sum(mass * np.einsum("ij,ij->i", vel, vel)))


def instability_onset(
    amplitude: Sequence[float], energy: Sequence[float], mass: float, d50: float, threshold: float, g: float = G
) -> float:
    """The load amplitude at which a bed under a growing load starts to move (thesis 6.3 reads it
    off the jump of its kinetic-energy curve): the first record where the root-mean-square grain
    velocity sqrt(2 energy / mass) exceeds threshold * sqrt(g d50) after having been at or below it. A
    bed still settling from its deposition when the load starts is not yet unstable, so records
    before it first comes to rest do not count. NaN when it never comes to rest or never moves
    again."""
    a = np.asarray(amplitude, dtype=float)
    ke = np.asarray(energy, dtype=float)
    if a.ndim != 1 or a.shape != ke.shape:
        raise ValueError(
            f"amplitude and energy must be two records of one length (got shapes " f"{a.shape} and {ke.shape})"
        )
    if not (np.all(np.isfinite(a)) and np.all(np.isfinite(ke)) and np.all(ke >= 0)):
        raise ValueError("amplitude and energy must be finite, energy non-negative")
    for name, value in (("mass", mass), ("d50", d50), ("threshold", threshold), ("g", g)):
        if not (math.isfinite(value) and value > 0):
            raise ValueError(f"{name} must be a positive number (got {value!r})")
    moving = np.sqrt(2 * ke / mass) > threshold * math.sqrt(g * d50)
    rest = np.flatnonzero(~moving)
    if not len(rest):
        return float("nan")
    onset = np.flatnonzero(moving[rest[0] :])
    return float(a[rest[0] + onset[0]]) if len(onset) else float("nan")


def effective_stress_profile(
    stresses: Sequence[Any],
    ids: np.ndarray,
    pos: np.ndarray,
    radii: np.ndarray,
    bottom: float,
    top: float,
    bins: int,
    area: float,
    x_band: tuple[float, float] | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Vertical effective stress sigma'_yy (compression positive) in horizontal slices: the sum over
    the slice's spheres of V_p sigma_p (thesis 2.18, YADE's bodyStressTensors: sigma_p = (1/V_p) sum of
    contact force x branch) over the slice volume. With x_band only the spheres whose centres lie in
    that x range count, over their share of the area (the thesis' profile along the symmetry axis).
    Returns the slice mid-heights and sigma'_yy."""
    edges = np.linspace(bottom, top, bins + 1)
    keep = np.ones(len(ids), bool)
    share = 1.0
    if x_band is not None:
        keep = (pos[:, 0] >= x_band[0]) & (pos[:, 0] < x_band[1])
        span = pos[:, 0].max() - pos[:, 0].min()
        share = (x_band[1] - x_band[0]) / span if span > 0 else 1.0
    volume = 4.0 / 3.0 * math.pi * radii**3
    syy = np.array([-stresses[i][1, 1] for i in ids])  # YADE: tension positive
    which = np.digitize(pos[:, 1], edges) - 1
    out = np.zeros(bins)
    for k in range(bins):
        sel = keep & (which == k)
        out[k] = np.sum(volume[sel] * syy[sel]) / (area * share * (edges[k + 1] - edges[k]))
    return 0.5 * (edges[1:] + edges[:-1]), out


def pressure_profile(flow: Any, x: float, z: float, heights: Sequence[float]) -> np.ndarray:
    """Excess pore pressure at the given heights along the vertical (x, ., z)."""
    return np.array([flow.getPorePressure((x, float(y), z)) for y in heights])


def horizontal_displacements(
    pos: np.ndarray, start: np.ndarray, x_axis: float, half_width: float
) -> tuple[np.ndarray, np.ndarray]:
    """Heights and x-displacements (from `start`) of the spheres whose initial centres lie within
    half_width of the vertical x = x_axis (the thesis' symmetry axis), sorted by height."""
    on_axis = np.abs(start[:, 0] - x_axis) <= half_width
    order = np.argsort(start[on_axis, 1])
    return start[on_axis, 1][order], (pos[on_axis, 0] - start[on_axis, 0])[order]


class Monitor:
    """Records a coupled run every `every` steps into YADE's plot.data (plot.saveDataTxt writes it):
    time, the load amplitude `amplitude(t)` if given, each sensor's pressure p_<vertical>_<level>, each
    gradient ratio r_<vertical>_<level> (grad H / i_c from level to level + 1), the top height, the
    porosity below it, the kinetic energy and YADE's unbalanced force; prints progress (simulated
    time, wall time, estimated time left) every `report_every` records when t_end is known."""

    def __init__(
        self,
        flow: Any,
        grid: SensorGrid,
        porosity0: float,
        rho_s: float,
        rho_f: float,
        area: float,
        bottom: float,
        amplitude: Callable[[float], float] | None = None,
        t_end: float | None = None,
        report_every: int = 10,
        g: float = G,
    ):
        self.flow, self.grid, self.area, self.bottom = flow, grid, area, bottom
        self.gamma_prime = buoyant_unit_weight(porosity0, rho_s, rho_f, g)
        self.i_c = critical_gradient(porosity0, rho_s, rho_f)
        self.amplitude, self.t_end, self.report_every = amplitude, t_end, report_every
        self.records = 0
        self.t0 = None

    def __call__(self) -> None:
        from yade import O, plot, utils

        ids, pos, rad, vel, mass = sphere_arrays(O.bodies)
        p = self.grid.pressures(self.flow)
        ratios = self.grid.gradient_ratios(p, self.gamma_prime)
        top = top_height(pos, rad, 0.99)
        data = dict(
            t=O.time,
            iter=O.iter,
            top=top,
            porosity=porosity_below(rad, self.area, top, self.bottom),
            KE=kinetic_energy(vel, mass),
            unbalanced=utils.unbalancedForce(),
        )
        if self.amplitude is not None:
            data["A"] = float(self.amplitude(O.time))
        for v in range(p.shape[0]):
            for k in range(p.shape[1]):
                data[f"p_{v + 1}_{k + 1}"] = float(p[v, k])
            for k in range(ratios.shape[1]):
                data[f"r_{v + 1}_{k + 1}"] = float(ratios[v, k])
        plot.addData(**data)
        self.records += 1
        if self.t0 is None:
            self.t0 = (time.monotonic(), O.time)
        elif self.t_end and self.records % self.report_every == 0:
            wall, done = time.monotonic() - self.t0[0], O.time - self.t0[1]
            left = wall * max(self.t_end - O.time, 0) / done if done > 0 else math.nan
            print(
                f"t = {O.time:.4g} / {self.t_end:.4g} s simulated, {wall:.0f} s wall, about {left:.0f} s left",
                flush=True,
            )


def save_plots(data: dict[str, Sequence[float]], path: str, i_c_threshold: float = 0.8) -> None:
    """PNG of a Monitor's record: gradient ratios per level (mean over the verticals) with the
    liquefaction threshold, pressures, top height and porosity, kinetic energy."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t = np.asarray(data["t"])
    fig, ax = plt.subplots(2, 2, figsize=(11, 7), sharex=True)
    levels = sorted({int(k.split("_")[2]) for k in data if k.startswith("r_")})
    verticals = sorted({int(k.split("_")[1]) for k in data if k.startswith("r_")})
    for k in levels:
        r = np.mean([data[f"r_{v}_{k}"] for v in verticals], axis=0)
        ax[0, 0].plot(t, r, label=f"sensors {k}-{k + 1}")
    ax[0, 0].axhline(i_c_threshold, color="k", ls="--", lw=0.8)
    ax[0, 0].set_ylabel("grad H / i_c (mean over verticals)")
    ax[0, 0].legend(fontsize=7)
    for k in sorted({int(k.split("_")[2]) for k in data if k.startswith("p_")}):
        ax[0, 1].plot(t, np.mean([data[f"p_{v}_{k}"] for v in verticals], axis=0), label=f"level {k}")
    ax[0, 1].set_ylabel("excess pressure [Pa]")
    ax[0, 1].legend(fontsize=7)
    ax[1, 0].plot(t, data["top"], "k")
    ax[1, 0].set_ylabel("top height [m]")
    twin = ax[1, 0].twinx()
    twin.plot(t, data["porosity"], "C3")
    twin.set_ylabel("porosity", color="C3")
    ax[1, 1].semilogy(t, np.maximum(np.asarray(data["KE"]), 1e-300))
    ax[1, 1].set_ylabel("kinetic energy [J]")
    for a in ax[1]:
        a.set_xlabel("t [s]")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
