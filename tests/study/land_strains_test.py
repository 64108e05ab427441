#!/usr/bin/python3
"""Unit tests of bench/land_strains.py (seed 000 eq. 25 point-pair strains) on deformations with
known strains: a uniform stretch, a rigid rotation about the long axis, and an axial stretch; and
of bench/land_meridians.py's view (distance from the axis against z) and plot."""
import math
import sys
import tempfile
import unittest
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "bench"))
import land_meridians  # noqa: E402
import land_strains  # noqa: E402

# Points of an endocardial-like meridian, base to apex (on v = 0), and the epicardial one.
def latitudes(u0):
    return [u0 + k * (math.pi - u0) / 10 for k in range(10)] + [math.pi]


ENDO = [(7.0 * math.sin(u), 0.0, 17.0 * math.cos(u)) for u in latitudes(math.acos(5 / 17))]
ENDO[-1] = (0.0, 0.0, -17.0)
EPI = [(10.0 * math.sin(u), 0.0, 20.0 * math.cos(u)) for u in latitudes(math.acos(5 / 20))]
EPI[-1] = (0.0, 0.0, -20.0)


def write(path, points, deform):
    n = len(points)
    header = ["time"] + [f"position.{a}@p{k}" for a in "xyz" for k in range(n)]
    rows = [header]
    for t, move in ((0.0, lambda p: p), (1.0, deform)):
        moved = [move(p) for p in points]
        rows.append([str(t)] + [repr(moved[k][i]) for i in range(3) for k in range(n)])
    path.write_text("\n".join(",".join(r) for r in rows) + "\n")


def strains(deform):
    with tempfile.TemporaryDirectory() as d:
        write(Path(d) / "endo.csv", ENDO, deform)
        write(Path(d) / "epi.csv", EPI, deform)
        endo = land_strains.read_meridian(Path(d) / "endo.csv")
        epi = land_strains.read_meridian(Path(d) / "epi.csv")
    return (land_strains.longitudinal(endo), land_strains.circumferential(endo),
            land_strains.transmural(endo, epi))


class PointPairStrains(unittest.TestCase):
    def test_uniform_stretch_gives_its_strain_everywhere(self):
        lon, circ, trans = strains(lambda p: tuple(1.1 * c for c in p))
        for s in lon + trans + [c for c in circ if c is not None]:
            self.assertAlmostEqual(s, 10.0, places=9)
        self.assertIsNone(circ[-1])  # the apex has no ring
        self.assertEqual(len(lon), 10)

    def test_rotation_about_the_axis_strains_nothing(self):
        a = 0.7
        rot = lambda p: (math.cos(a) * p[0] - math.sin(a) * p[1],  # noqa: E731
                         math.sin(a) * p[0] + math.cos(a) * p[1], p[2])
        lon, circ, trans = strains(rot)
        for s in lon + trans + [c for c in circ if c is not None]:
            self.assertAlmostEqual(s, 0.0, places=9)

    def test_axial_stretch_leaves_rings_unstrained(self):
        lon, circ, _ = strains(lambda p: (p[0], p[1], 1.2 * p[2]))
        for c in circ[:-1]:
            self.assertAlmostEqual(c, 0.0, places=9)
        # A segment's stretch: sqrt(dx^2 + 1.44 dz^2) / sqrt(dx^2 + dz^2) - 1.
        (x0, _, z0), (x1, _, z1) = ENDO[0], ENDO[1]
        expect = (math.hypot(x1 - x0, 1.2 * (z1 - z0)) / math.hypot(x1 - x0, z1 - z0) - 1) * 100
        self.assertAlmostEqual(lon[0], expect, places=9)


class MeridianView(unittest.TestCase):
    def test_twist_keeps_the_profile_and_the_plot_is_written(self):
        a = 0.9  # a twist about the long axis, growing towards the apex, and a 10% shortening
        twist = lambda p: (math.cos(a * -p[2] / 20) * p[0] - math.sin(a * -p[2] / 20) * p[1],  # noqa: E731
                           math.sin(a * -p[2] / 20) * p[0] + math.cos(a * -p[2] / 20) * p[1],
                           0.9 * p[2])
        with tempfile.TemporaryDirectory() as d:
            write(Path(d) / "endocardial_meridian.csv", ENDO, twist)
            write(Path(d) / "epicardial_meridian.csv", EPI, twist)
            points = land_strains.read_meridian(Path(d) / "endocardial_meridian.csv")
            rho0, z0 = land_meridians.radial_profile(points, deformed=False)
            rho, z = land_meridians.radial_profile(points, deformed=True)
            for k in range(len(points)):
                self.assertAlmostEqual(rho[k], rho0[k], places=9)  # mm: the twist moves no radius
                self.assertAlmostEqual(z[k], 0.9 * z0[k], places=9)
            self.assertAlmostEqual(rho0[0], 1e3 * ENDO[0][0], places=9)  # metres in, mm out
            png = Path(d) / "meridians.png"
            self.assertEqual(land_meridians.main(["land_meridians.py", str(png), f"run={d}"]), 0)
            self.assertGreater(png.stat().st_size, 1000)
        self.assertEqual(land_meridians.main(["land_meridians.py", "only.png"]), 2)


if __name__ == "__main__":
    unittest.main()
