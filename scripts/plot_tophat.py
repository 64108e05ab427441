#!/usr/bin/python3
"""Plots the last row of a top-hat diffusion line probe against the analytic solution
c = 1/2 [erf((y - 0.4)/sqrt(4 d t)) - erf((y - 0.6)/sqrt(4 d t))], d = 1e-4
(seed 001 section 5.1; examples/diffusion_1d_tophat.yaml), and prints the relative L2 error."""
import math
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def main(csv_path: str, png_path: str, d: float = 1e-4) -> None:
    data = np.genfromtxt(csv_path, delimiter=",", names=True)
    last = data[-1]
    t = float(last["time"])
    values = np.array([last[name] for name in data.dtype.names[1:]])
    y = np.linspace(0.0, 1.0, len(values))  # the probe's line runs from y = 0 to y = 1
    s = math.sqrt(4.0 * d * t)
    exact = np.array([0.5 * (math.erf((v - 0.4) / s) - math.erf((v - 0.6) / s)) for v in y])
    error = np.sqrt(np.sum((values - exact) ** 2) / np.sum(exact ** 2))
    first = data[0]
    initial = np.array([first[name] for name in data.dtype.names[1:]])

    fig, ax = plt.subplots(figsize=(7, 4.2))
    ax.plot(y, initial, color="0.7", lw=1, label="initial (t = 0)")
    ax.plot(y, exact, "k-", lw=1.5, label=f"analytic, t = {t:g}")
    ax.plot(y, values, "o", ms=3, color="tab:red", label=f"cosph SPH (rel. L2 error {error:.2e})")
    ax.set_xlabel("y")
    ax.set_ylabel("concentration")
    ax.set_title("Top-hat diffusion, d = 1e-4")
    ax.legend(loc="upper right", fontsize=8)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(png_path, dpi=120)
    print(f"plot: {png_path}  (t = {t:g}, relative L2 error along the line {error:.3e})")


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit("usage: plot_tophat.py PROFILE.csv OUT.png")
    main(sys.argv[1], sys.argv[2])
