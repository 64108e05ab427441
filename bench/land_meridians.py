#!/usr/bin/python3
"""The deformed meridians of Land et al. (2015) problems 2 and 3 (the benchmark's 11 points per
wall on v = 0, from the base to the apex) from ventricle runs' meridian probes
(endocardial_meridian.csv, epicardial_meridian.csv: first row the reference, last row the
deformed positions), drawn as distance from the long axis, hypot(x, y), against z: the twist of
problem 3 turns the points out of the plane v = 0, and this view keeps them.

usage: /usr/bin/python3 bench/land_meridians.py PNG LABEL=OUTPUT_DIR [LABEL=OUTPUT_DIR ...]
"""
import math
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from land_strains import read_meridian  # noqa: E402


def radial_profile(points, deformed):
    """(hypot(x, y), z) in mm of each point, reference or deformed."""
    chosen = [p[1] if deformed else p[0] for p in points]
    return ([math.hypot(x, y) * 1e3 for x, y, _ in chosen], [z * 1e3 for _, _, z in chosen])


def main(argv):
    if len(argv) < 3 or any("=" not in a for a in argv[2:]):
        print(__doc__, file=sys.stderr)
        return 2
    runs = [a.split("=", 1) for a in argv[2:]]
    figure, axis = plt.subplots(figsize=(5.5, 8.5))
    reference_drawn = False
    for colour, (label, directory) in zip(plt.rcParams["axes.prop_cycle"].by_key()["color"], runs):
        for wall, style in (("endocardial", "-"), ("epicardial", "--")):
            points = read_meridian(Path(directory) / f"{wall}_meridian.csv")
            if not reference_drawn:
                axis.plot(*radial_profile(points, False), style, color="0.6", marker=".",
                          label=f"reference, {wall}")
            axis.plot(*radial_profile(points, True), style, color=colour, marker="o",
                      markersize=3, label=f"{label}, {wall}")
        reference_drawn = True
    axis.set_xlabel("distance from the long axis (mm)")
    axis.set_ylabel("z (mm)")
    axis.set_aspect("equal")
    axis.grid(alpha=0.3)
    axis.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.08))
    axis.set_title("Land et al. (2015) ventricle: meridians v = 0", fontsize=9)
    figure.tight_layout()
    figure.savefig(argv[1], dpi=110)
    print(f"wrote {argv[1]}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
