#!/usr/bin/python3
"""Plots the elastic gate's free-end displacement (examples/fsi_elastic_gate.yaml, probe
free_end) over time against the references with numbers: the largest displacements of
SPHinXsys's run of the same case (45.8 mm horizontally, 19.6 mm upwards) and the experiment's
peak of about 40 mm horizontally (Antoci et al. 2007; published only as figures, no data file),
and prints the run's own peaks."""
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def main(csv_path: str, png_path: str) -> None:
    data = np.genfromtxt(csv_path, delimiter=",", names=True)
    t = data["time"]
    ux = -1000.0 * data["displacementxp0"]  # the gate opens towards -x
    uy = 1000.0 * data["displacementyp0"]
    fig, ax = plt.subplots(figsize=(7, 4.2))
    ax.plot(t, ux, color="tab:blue", lw=1.5, label=f"cosph, horizontal (peak {ux.max():.1f} mm)")
    ax.plot(t, uy, color="tab:red", lw=1.5, label=f"cosph, vertical (peak {uy.max():.1f} mm)")
    ax.axhline(45.8, color="tab:blue", ls="--", lw=1, label="SPHinXsys peak, horizontal (45.8 mm)")
    ax.axhline(19.6, color="tab:red", ls="--", lw=1, label="SPHinXsys peak, vertical (19.6 mm)")
    ax.axhline(40.0, color="0.4", ls=":", lw=1, label="experiment's peak, horizontal (~40 mm)")
    ax.set_xlabel("t (s)")
    ax.set_ylabel("free-end displacement (mm)")
    ax.set_title("Dam break through an elastic gate (Antoci et al. 2007)")
    ax.legend(loc="center right", fontsize=8)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(png_path, dpi=120)
    print(f"plot: {png_path}  (peak horizontal {ux.max():.1f} mm at t = {t[ux.argmax()]:.3f} s, "
          f"vertical {uy.max():.1f} mm at t = {t[uy.argmax()]:.3f} s)")


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit("usage: plot_gate.py FREE_END.csv OUT.png")
    main(sys.argv[1], sys.argv[2])
