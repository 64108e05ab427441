#!/usr/bin/python3
"""The strains of Land et al. (2015) problems 2 and 3 as seed 000 defines them (its eq. 25):
the stretch of point pairs, s = (|x1 - x2| / |X1 - X2| - 1) x 100%, not the Green strain, from a
ventricle run's meridian probes (examples/solid_land_ventricle_static.yaml and
solid_land_ventricle_active_static.yaml: endocardial_meridian.csv, epicardial_meridian.csv, the
benchmark's 11 points per wall on v = 0 from the base to the apex, with position.x, .y, .z).

- longitudinal: consecutive points of one meridian (10 segments per wall);
- circumferential: the ring through each point, whose chord between v = +-dv tends to the ring's
  radius ratio rho / rho_0 (the benchmark's loads and fibres are symmetric about the long axis,
  so rings stay circles and centred; exact in that limit). Not defined at the apex (rho_0 = 0);
- transmural: the endocardial point i to the epicardial point i.

The reference positions are the first row of each CSV (t = 0), the deformed ones its last row.

usage: /usr/bin/python3 bench/land_strains.py OUTPUT_DIR   (prints a Markdown table)
"""
import csv
import math
import sys
from pathlib import Path


def read_meridian(path):
    """[(X, x)] per point: reference and deformed (x, y, z) from the first and last rows."""
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    header, first, last = rows[0], rows[1], rows[-1]
    index = {name: k for k, name in enumerate(header)}
    points = []
    p = 0
    while f"position.x@p{p}" in index:
        def at(row, axis):
            key = f"position.{axis}@p{p}"
            return float(row[index[key]]) if key in index else 0.0
        points.append((tuple(at(first, a) for a in "xyz"), tuple(at(last, a) for a in "xyz")))
        p += 1
    if len(points) < 2:
        raise ValueError(f"{path}: needs at least two position.x@pN columns")
    return points


def stretch_percent(X1, X2, x1, x2):
    return (math.dist(x1, x2) / math.dist(X1, X2) - 1.0) * 100.0


def longitudinal(points):
    return [stretch_percent(points[k][0], points[k + 1][0], points[k][1], points[k + 1][1])
            for k in range(len(points) - 1)]


def circumferential(points):
    """Per point, or None where the reference radius is zero (the apex)."""
    strains = []
    for X, x in points:
        rho0, rho = math.hypot(X[0], X[1]), math.hypot(x[0], x[1])
        strains.append(None if rho0 < 1e-12 * max(1.0, abs(X[2])) else (rho / rho0 - 1.0) * 100.0)
    return strains


def transmural(endo, epi):
    if len(endo) != len(epi):
        raise ValueError("the endocardial and epicardial meridians have different point counts")
    return [stretch_percent(a[0], b[0], a[1], b[1]) for a, b in zip(endo, epi)]


def table(endo, epi):
    lines = ["| point | long. endo % | long. epi % | circ. endo % | circ. epi % | transmural % |",
             "|---:|---:|---:|---:|---:|---:|"]
    le, lp = longitudinal(endo), longitudinal(epi)
    ce, cp = circumferential(endo), circumferential(epi)
    tr = transmural(endo, epi)
    fmt = lambda v: "" if v is None else f"{v:.2f}"  # noqa: E731
    for k in range(len(endo)):
        segment = k < len(le)
        lines.append(f"| {k} | {fmt(le[k]) if segment else ''} | {fmt(lp[k]) if segment else ''} "
                     f"| {fmt(ce[k])} | {fmt(cp[k])} | {fmt(tr[k])} |")
    return "\n".join(lines)


def main(argv):
    if len(argv) != 2:
        print(__doc__, file=sys.stderr)
        return 2
    out = Path(argv[1])
    endo = read_meridian(out / "endocardial_meridian.csv")
    epi = read_meridian(out / "epicardial_meridian.csv")
    print("Longitudinal strains are of the segment from point k to k + 1 (point 0 at the base).")
    print(table(endo, epi))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
