#!/usr/bin/python3
"""Independent finite-difference reference solutions of the monodomain model for the studies
bench/studies/monodomain_conduction_velocity.yaml and bench/studies/monodomain_propagation.yaml.

    dV/dt = D lap V + I(V, w),   dw/dt = g(V, w),   D = 1, no-flux boundaries,
    I = -k V (V - a)(V - 1) - w V,
    g = (eps0 + mu1 w / (mu2 + V)) (-k V (V - b - 1) - w)      (Aliev-Panfilov, seed 001 table 1)

Nothing here shares code with cosph: a cell-centred grid of spacing dx, the standard five-point
(three-point in 1D) Laplacian with mirror ghost cells (zero normal derivative on the boundary),
explicit Euler for V and w together, dt = c dx^2 with a fixed c well below the stability limit,
so that the time error, O(dt) = O(dx^2), falls with the space error and two grids give a
Richardson estimate of both.

usage: /usr/bin/python3 bench/reference/monodomain_fd.py [--only cv|propagation] [--quick]

Writes, next to this script:
  monodomain_cv_fd.csv           plane-wave conduction velocity at three grids + the extrapolation
  monodomain_propagation_fd.csv  V(t) at (0.3, 0.7) for t = 0 .. 16 every 0.02 (Ratti & Verani)
Run time about 4 to 6 minutes on one core (numpy, vectorised over the grid).
"""
import argparse
import math
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
K, A, B, EPS0, MU1, MU2 = 8.0, 0.15, 0.15, 0.002, 0.2, 0.3  # seed 001 table 1
DIFFUSIVITY = 1.0


class Grid:
    """State on a cell-centred grid with one layer of mirror ghost cells, and one explicit Euler
    step of the whole system. Works for 1D (shape (n,)) and 2D (shape (nx, ny)) grids."""

    def __init__(self, shape: tuple, dx: float, dt: float):
        self.dx, self.dt = dx, dt
        self.padded = np.zeros(tuple(n + 2 for n in shape))  # V with its ghost cells
        self.interior = tuple(slice(1, -1) for _ in shape)
        self.V = self.padded[self.interior]  # a view: writing V writes the padded array
        self.w = np.zeros(shape)
        self._lap = np.zeros(shape)
        self._tmp = np.zeros(shape)
        self._eps = np.zeros(shape)
        self._rate_w = np.zeros(shape)

    def _mirror(self) -> None:
        p = self.padded
        p[0], p[-1] = p[1], p[-2]
        if p.ndim == 2:
            p[:, 0], p[:, -1] = p[:, 1], p[:, -2]

    def _laplacian(self) -> np.ndarray:
        self._mirror()
        p, lap = self.padded, self._lap
        if p.ndim == 1:
            np.add(p[:-2], p[2:], out=lap)
            lap -= 2.0 * self.V
        else:
            np.add(p[:-2, 1:-1], p[2:, 1:-1], out=lap)
            lap += p[1:-1, :-2]
            lap += p[1:-1, 2:]
            lap -= 4.0 * self.V
        lap *= DIFFUSIVITY / self.dx**2
        return lap

    def step(self) -> None:
        """V += dt (D lap V + I(V, w)), w += dt g(V, w), both rates at the old state."""
        V, w, tmp, eps, rate_w = self.V, self.w, self._tmp, self._eps, self._rate_w
        rate_v = self._laplacian()
        # g = (eps0 + mu1 w / (mu2 + V)) (-k V (V - b - 1) - w), from the old V and w
        np.add(V, MU2, out=eps)
        np.divide(w, eps, out=eps)
        eps *= MU1
        eps += EPS0
        np.subtract(V, B + 1.0, out=rate_w)
        rate_w *= V
        rate_w *= -K
        rate_w -= w
        rate_w *= eps
        # I = -k V (V - a)(V - 1) - w V
        np.subtract(V, A, out=tmp)
        tmp *= V - 1.0
        tmp *= -K
        tmp -= w
        tmp *= V
        rate_v += tmp
        rate_v *= self.dt
        V += rate_v
        rate_w *= self.dt
        w += rate_w


def crossing(t0: float, dt: float, before: float, after: float, threshold: float = 0.5) -> float:
    return t0 + dt * (threshold - before) / (after - before)


# ---- Conduction velocity (1D plane wave) ------------------------------------------------------

CV_LENGTH, CV_STIMULUS_X, CV_STIMULUS_END = 8.0, 0.2, 0.5
CV_POINTS = (3.0, 5.0)


def conduction_velocity(dx: float, c: float) -> tuple:
    """CV = 2 / (t(5) - t(3)) on [0, 8]; V held at 1 on x < 0.2 while t < 0.5 (as cosph does:
    at t = 0 and after every step that ends before 0.5). Activation time: first upward crossing
    of V = 0.5, linear in time between steps, then linear in x between the two cells around each
    point. Returns (cv, dt, t3, t5, seconds)."""
    start = time.monotonic()
    n = int(round(CV_LENGTH / dx))
    dt = c * dx * dx
    grid = Grid((n,), dx, dt)
    centres = (np.arange(n) + 0.5) * dx
    stimulus = centres < CV_STIMULUS_X
    # The two cells either side of each measuring point.
    watch = np.concatenate([np.searchsorted(centres, x) + np.array([-1, 0]) for x in CV_POINTS])
    activation = np.full(len(watch), math.nan)
    grid.V[stimulus] = 1.0
    t, steps = 0.0, 0
    while np.isnan(activation).any():
        before = grid.V[watch].copy()
        grid.step()
        steps += 1
        t = steps * dt
        if t < CV_STIMULUS_END:
            grid.V[stimulus] = 1.0
        after = grid.V[watch]
        for j in np.nonzero(np.isnan(activation) & (before < 0.5) & (after >= 0.5))[0]:
            activation[j] = crossing(t - dt, dt, before[j], after[j])
        if t > 10.0:
            raise RuntimeError(f"dx {dx}: no activation at x = 5 by t = 10")
    times = []
    for k, x in enumerate(CV_POINTS):
        (x0, x1), (a0, a1) = centres[watch[2 * k:2 * k + 2]], activation[2 * k:2 * k + 2]
        times.append(a0 + (a1 - a0) * (x - x0) / (x1 - x0))
    return 2.0 / (times[1] - times[0]), dt, times[0], times[1], time.monotonic() - start


def write_cv(spacings: list, c: float) -> None:
    rows = []
    for dx in spacings:
        cv, dt, t3, t5, seconds = conduction_velocity(dx, c)
        print(f"cv: dx {dx:g} dt {dt:.3g}: t(3) {t3:.6f} t(5) {t5:.6f} CV {cv:.7f} "
              f"({seconds:.1f} s)", flush=True)
        rows.append((dx, dt, t3, t5, cv))
    (h1, *_, q1), (h2, *_, q2), (h3, *_, q3) = rows[-3:]
    order = math.log((q1 - q2) / (q2 - q3)) / math.log(h1 / h2)
    extrapolated = q3 + (q3 - q2) / ((h2 / h3) ** 2 - 1.0)  # assumes second order
    with_order = q3 + (q3 - q2) / ((h2 / h3) ** order - 1.0)
    uncertainty = max(abs(extrapolated - with_order), abs(q3 - q2) / 10.0)
    finest_error = abs(extrapolated - q3)
    print(f"cv: observed order {order:.2f}, extrapolated {extrapolated:.7f} "
          f"(+- {uncertainty:.1e}); finest grid error {finest_error:.1e}")
    lines = [
        "# Plane-wave conduction velocity of the monodomain model, Aliev-Panfilov (seed 001 table",
        "# 1: k 8, a 0.15, b 0.15, eps0 0.002, mu1 0.2, mu2 0.3), D = 1, on [0, 8], no-flux ends.",
        "# Stimulus: V = 1 held on x < 0.2 for t < 0.5 (V, w start at 0). Activation time: first",
        "# upward crossing of V = 0.5, linear in time between steps and in x between cells;",
        "# CV = 2 / (t(x=5) - t(x=3)).",
        "# Computed by bench/reference/monodomain_fd.py: cell-centred second-order finite",
        f"# differences with mirror (no-flux) ghost cells, explicit Euler for V and w, dt = {c:g} dx^2",
        "# (so the O(dt) time error is O(dx^2) too). Rows: dx, dt, the two activation times, CV.",
        f"# Observed order between the three grids: {order:.2f}. The last row (dx = 0) is the",
        "# Richardson extrapolation of the two finest grids assuming second order,",
        f"# CV = {extrapolated:.6f}; estimated uncertainty {uncertainty:.1e} (the difference from the",
        f"# extrapolation with the observed order, at least a tenth of the finest-grid correction);",
        f"# the finest grid itself is {finest_error:.1e} off it.",
        "dx,dt,t3,t5,cv",
    ]
    lines += [f"{dx:g},{dt:.6g},{t3:.8f},{t5:.8f},{cv:.8f}" for dx, dt, t3, t5, cv in rows]
    lines.append(f"0,0,nan,nan,{extrapolated:.8f}")
    (HERE / "monodomain_cv_fd.csv").write_text("\n".join(lines) + "\n")


# ---- Propagation in the unit square (Ratti & Verani; seed 001 section 5.3) ---------------------

PROBE = (0.3, 0.7)
END_TIME, RECORD_EVERY = 16.0, 0.02


def propagation(dx: float, c: float) -> tuple:
    """V(t) at (0.3, 0.7), bilinear between the four surrounding cell centres, every 0.02 for
    t = 0 .. 16, from V0 = exp(-((x - 1)^2 + y^2) / 0.25), w0 = 0. Returns (times, voltage,
    upstroke time (first crossing of 0.5, linear between steps), dt, seconds)."""
    start = time.monotonic()
    n = int(round(1.0 / dx))
    per_record = int(round(RECORD_EVERY / (c * dx * dx)))
    dt = RECORD_EVERY / per_record  # a whole number of steps between records
    grid = Grid((n, n), dx, dt)
    centres = (np.arange(n) + 0.5) * dx
    x, y = np.meshgrid(centres, centres, indexing="ij")
    grid.V[...] = np.exp(-((x - 1.0) ** 2 + y**2) / 0.25)
    # Bilinear weights of the probe.
    (i, fx), (j, fy) = [divmod(p / dx - 0.5, 1.0) for p in PROBE]
    i, j = int(i), int(j)
    weights = np.array([[(1 - fx) * (1 - fy), (1 - fx) * fy], [fx * (1 - fy), fx * fy]])

    def probe() -> float:
        return float(np.sum(weights * grid.V[i:i + 2, j:j + 2]))

    records = round(END_TIME / RECORD_EVERY)
    voltage = np.empty(records + 1)
    voltage[0] = previous = probe()
    upstroke = math.nan
    for r in range(1, records + 1):
        for s in range(per_record):
            grid.step()
            if math.isnan(upstroke):
                now = probe()
                if previous < 0.5 <= now:
                    upstroke = crossing(((r - 1) * per_record + s) * dt, dt, previous, now)
                previous = now
        voltage[r] = probe()
    times = np.arange(records + 1) * RECORD_EVERY
    return times, voltage, upstroke, dt, time.monotonic() - start


def relative_l2(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.sqrt(np.sum((a - b) ** 2) / np.sum(b**2)))


def write_propagation(spacings: list, c: float) -> None:
    runs = []
    for dx in spacings:
        times, voltage, upstroke, dt, seconds = propagation(dx, c)
        print(f"propagation: dx {dx:g} dt {dt:.3g}: upstroke {upstroke:.6f}, max V "
              f"{voltage.max():.5f}, V(16) {voltage[-1]:.6f} ({seconds:.1f} s)", flush=True)
        runs.append((dx, dt, times, voltage, upstroke))
    (h2, _, _, coarse, up2), (h1, dt1, times, fine, up1) = runs[-2], runs[-1]
    factor = (h2 / h1) ** 2 - 1.0  # Richardson, second order: error(fine) ~ (fine - coarse) / 3
    curve_error = relative_l2(fine, coarse) / factor
    max_error = float(np.max(np.abs(fine - coarse))) / factor
    upstroke_error = abs(up1 - up2) / factor
    extrapolated_upstroke = up1 + (up1 - up2) / factor
    orders = ""
    if len(runs) >= 3:
        h3, _, _, coarsest, up3 = runs[-3]
        order_curve = math.log(relative_l2(coarse, coarsest) / relative_l2(fine, coarse)) \
            / math.log(h3 / h2)
        order_up = math.log(abs(up3 - up2) / abs(up2 - up1)) / math.log(h3 / h2)
        orders = (f"# Observed orders between dx = {h3:g}, {h2:g}, {h1:g}: {order_curve:.2f} (curve, "
                  f"relative L2), {order_up:.2f} (upstroke time).")
        print(orders[2:])
    print(f"propagation: estimated error of the dx {h1:g} curve: relative L2 {curve_error:.1e}, "
          f"max {max_error:.1e}; upstroke {up1:.5f} +- {upstroke_error:.1e} "
          f"(extrapolated {extrapolated_upstroke:.5f})")
    upstrokes = ", ".join(f"{u:.5f} (dx {h:g})" for h, _, _, _, u in runs)
    lines = [
        "# Monodomain propagation in the unit square (Ratti & Verani 2019; seed 001 section 5.3):",
        "# Aliev-Panfilov, seed 001 table 1 (k 8, a 0.15, b 0.15, eps0 0.002, mu1 0.2, mu2 0.3),",
        "# D = 1, no-flux boundaries, V0 = exp(-((x - 1)^2 + y^2) / 0.25), w0 = 0; V at (0.3, 0.7),",
        "# bilinear between the four nearest cell centres, every 0.02 for t = 0 .. 16.",
        "# Computed by bench/reference/monodomain_fd.py: cell-centred five-point finite differences",
        "# with mirror (no-flux) ghost cells, explicit Euler for V and w;",
        f"# column voltage: dx = {h1:g} ({round(1 / h1)} x {round(1 / h1)} cells), dt = {dt1:.4g}.",
        f"# Error estimate (Richardson, second order in dx with dt ~ dx^2) from dx = {h2:g}: the",
        f"# dx = {h1:g} curve is within about {curve_error:.1e} in relative L2 over the time series",
        f"# (max {max_error:.1e} pointwise, at the upstroke). Upstroke time (first crossing of 0.5):",
        f"# {upstrokes}; extrapolated {extrapolated_upstroke:.5f},",
        f"# error of the dx = {h1:g} value about {upstroke_error:.1e}.",
    ]
    if orders:
        lines.append(orders)
    lines.append(f"# Column voltage_dx{h2:g}: the same at dx = {h2:g}.")
    lines.append(f"time,voltage,voltage_dx{h2:g}")
    lines += [f"{t:.2f},{v:.8f},{u:.8f}" for t, v, u in zip(times, fine, coarse)]
    (HERE / "monodomain_propagation_fd.csv").write_text("\n".join(lines) + "\n")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--only", choices=("cv", "propagation"))
    parser.add_argument("--quick", action="store_true",
                        help="coarse grids only, to test the script (the files are overwritten)")
    args = parser.parse_args()
    start = time.monotonic()
    if args.only in (None, "cv"):
        # 1D: stability needs dt <= dx^2 / 2; c = 0.25 is half of it.
        write_cv([0.04, 0.02, 0.01] if args.quick else [0.02, 0.01, 0.005], c=0.25)
    if args.only in (None, "propagation"):
        # 2D: stability needs dt <= dx^2 / 4; c = 0.2 is 80 % of it (the reaction is mild).
        write_propagation([0.1, 0.05] if args.quick else [0.04, 0.02, 0.01], c=0.2)
    print(f"done in {time.monotonic() - start:.1f} s")


if __name__ == "__main__":
    main()
