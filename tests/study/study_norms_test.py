#!/usr/bin/python3
"""Unit tests of bench/study.py's error norms and reference handling, on small hand-computed
series: every norm of NORM_TEXT (max, l2_relative, l2_time, relative_at_point, arrival_time),
the interpolation of a CSV reference at the simulation's sample times (and the samples outside
its range being left out), reading a reference CSV (comments, header, column choice, errors),
analytic and constant references, and final values derived by 'combine'.

Each expected value is written out in the test from the formula in NORM_TEXT, not taken from
study.py, and the series are chosen so that a factor 1.1, a missing sqrt or abs, an off-by-one
row or a wrong column changes the result by far more than the 1e-12 tolerance. Nothing runs
cosph: the tests write a stub scene (only its probe names are read), a study file and the probe
CSV files that cosph would write (time,<field>@<label>,... and <probe>.points.csv), then call
study.compare() on them."""
import math
import sys
import tempfile
import unittest
from pathlib import Path

import numpy as np
import yaml

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "bench"))
import study  # noqa: E402

TOLERANCE = 1e-12

# The scene is never run: load_study reads only its probe names (and whether a profile probe is
# a line or points probe).
SCENE = """\
probes:
  - name: line
    line: {from: [0.0, 0.0], to: [0.0, 0.3], count: 4, fields: [concentration, velocity]}
  - name: gauge
    points: {at: [[0.5, 0.25]], fields: [h]}
  - name: activation
    points: {at: [[3.0, 0.2], [5.0, 0.2]], fields: [activation_time, other]}
"""


class StudyFixture(unittest.TestCase):
    """A temporary directory with the stub scene; helpers write a study file and probe files."""

    def setUp(self):
        self._directory = tempfile.TemporaryDirectory()
        self.root = Path(self._directory.name)
        (self.root / "scene.yaml").write_text(SCENE)
        self.out = self.root / "out"
        self.out.mkdir()

    def tearDown(self):
        self._directory.cleanup()

    def load(self, quantity: dict, reference: dict, norm: str, **extra) -> study.Study:
        node = {"title": "test", "description": "test", "scene": "scene.yaml",
                "sweep": {"axes": [{"key": "run.threads", "values": [1]}]},
                "quantity": quantity, "reference": {"source": "by hand", **reference},
                "norm": norm, **extra}
        path = self.root / "study.yaml"
        path.write_text(yaml.safe_dump(node, sort_keys=False))
        return study.load_study(path)

    def write_probe(self, name: str, columns: list, rows: list, points: dict = None) -> None:
        lines = [",".join(["time"] + columns)]
        lines += [",".join(repr(float(v)) for v in row) for row in rows]
        (self.out / f"{name}.csv").write_text("\n".join(lines) + "\n")
        if points is not None:  # 2D sidecar, as the probe set writes it: label,x,y
            text = "label,x,y\n" + "".join(f"{label},{x!r},{y!r}\n"
                                            for label, (x, y) in points.items())
            (self.out / f"{name}.points.csv").write_text(text)

    def write_file(self, name: str, text: str) -> Path:
        path = self.root / name
        path.write_text(text)
        return path

    def compare(self, spec: study.Study) -> study.PointResult:
        result = study.PointResult(spec.points()[0])
        study.compare(spec, self.out, result)
        return result


# ---- Norms ------------------------------------------------------------------------------------


class MaxNorm(StudyFixture):
    def test_max_is_the_largest_absolute_difference(self):
        # r = t^2 at t = 0, 1, 1.5: 0, 1, 2.25; s - r = 0, 0, -1.75. The largest difference is
        # negative: max(s - r) without abs would be 0, and a factor 1.1 would give 1.925.
        self.write_probe("gauge", ["h@p0"], [[0.0, 0.0], [1.0, 1.0], [1.5, 0.5]],
                         {"p0": (0.5, 0.25)})
        spec = self.load({"probe": "gauge", "kind": "time_series", "column": "h@p0"},
                         {"expression": "t**2"}, "max")
        result = self.compare(spec)
        self.assertAlmostEqual(result.error, 1.75, delta=TOLERANCE)
        np.testing.assert_allclose(result.reference_values, [0.0, 1.0, 2.25], atol=TOLERANCE)


class RelativeL2OfProfile(StudyFixture):
    """l2_relative: sqrt(sum (s - r)^2 / sum r^2) over the probe points of one row."""

    POINTS = {"p0": (0.0, 0.0), "p1": (0.0, 0.1), "p2": (0.0, 0.2), "p3": (0.0, 0.3)}
    COLUMNS = ["concentration@p0", "concentration@p1", "concentration@p2", "concentration@p3",
               "velocity@p0", "velocity@p1", "velocity@p2", "velocity@p3"]
    # Reference (1 + 10 y) t: at t = 1 it is 1, 2, 3, 4 and at t = 2 it is 2, 4, 6, 8.
    ROWS = [[0.0, 0, 0, 0, 0, 9, 9, 9, 9],
            [1.0, 1.0, 2.2, 2.7, 4.4, 9, 9, 9, 9],
            [2.0, 2.0, 4.0, 6.6, 8.0, 9, 9, 9, 9]]

    def load_profile(self, norm="l2_relative", **quantity):
        self.write_probe("line", self.COLUMNS, self.ROWS, self.POINTS)
        return self.load({"probe": "line", "kind": "profile", "field": "concentration",
                          **quantity}, {"expression": "(1 + 10 * y) * t"}, norm)

    def test_last_row(self):
        # s - r = 0, 0, 0.6, 0 at t = 2; sum r^2 = 4 + 16 + 36 + 64 = 120.
        result = self.compare(self.load_profile())
        expected = math.sqrt(0.6 ** 2 / 120.0)
        self.assertAlmostEqual(result.error, expected, delta=TOLERANCE)
        np.testing.assert_allclose(result.sample.values, [2.0, 4.0, 6.6, 8.0])
        np.testing.assert_allclose(result.reference_values, [2.0, 4.0, 6.0, 8.0],
                                   atol=TOLERANCE)
        self.assertEqual(result.sample.field_name, "concentration")

    def test_row_nearest_the_requested_time(self):
        # time 0.9 -> the row at t = 1: s - r = 0, 0.2, -0.3, 0.4, sum of squares 0.29;
        # sum r^2 = 1 + 4 + 9 + 16 = 30. Without the sqrt the error would be 0.0097, not 0.098.
        result = self.compare(self.load_profile(time=0.9))
        expected = math.sqrt((0.2 ** 2 + 0.3 ** 2 + 0.4 ** 2) / 30.0)
        self.assertAlmostEqual(result.error, expected, delta=TOLERANCE)
        np.testing.assert_allclose(result.sample.variables["t"], [1.0] * 4)

    def test_profile_positions_from_the_points_file(self):
        # The probe runs along y (x constant): y is the plotted abscissa, and distance is the
        # distance from the first point.
        sample = self.compare(self.load_profile()).sample
        self.assertEqual(sample.abscissa_name, "y")
        np.testing.assert_allclose(sample.variables["y"], [0.0, 0.1, 0.2, 0.3])
        np.testing.assert_allclose(sample.variables["distance"], [0.0, 0.1, 0.2, 0.3])
        np.testing.assert_allclose(sample.variables["z"], [0.0] * 4)  # 2D: z = 0

    def test_max_of_a_profile(self):
        result = self.compare(self.load_profile(norm="max", time=1.0))
        self.assertAlmostEqual(result.error, 0.4, delta=TOLERANCE)  # |4.4 - 4| at t = 1

    def test_two_fields_need_a_field(self):
        self.write_probe("line", self.COLUMNS, self.ROWS, self.POINTS)
        spec = self.load({"probe": "line", "kind": "profile"}, {"expression": "y"},
                         "l2_relative")
        with self.assertRaisesRegex(study.ComparisonError, "concentration, velocity"):
            self.compare(spec)


class RelativeL2OfTimeSeries(StudyFixture):
    """l2_time: sqrt(sum (s - r)^2 / sum r^2) over the samples, the reference taken at the
    simulation's sample times."""

    def test_csv_reference_is_interpolated_linearly_at_the_sample_times(self):
        # The reference is given at t = 0, 1, 2 (rows out of order; a column 'other' in between
        # that must not be read); the simulation is sampled every 0.5 up to 2.5.
        self.write_file("reference.csv", "# a comment line\nt,other,h\n"
                        "2,-50,1\n0,-10,1\n1,-30,3\n")
        times = [0.0, 0.5, 1.0, 1.5, 2.0, 2.5]
        values = [1.0, 2.0, 3.5, 3.0, 2.0, 9.0]
        self.write_probe("gauge", ["h@p0"], [[t, v] for t, v in zip(times, values)],
                         {"p0": (0.5, 0.25)})
        spec = self.load({"probe": "gauge", "kind": "time_series", "column": "h@p0"},
                         {"csv": "reference.csv", "columns": ["t", "h"]}, "l2_time")
        result = self.compare(spec)
        # Linear interpolation: 1, 2 (midway between 1 and 3), 3, 2, 1, and nothing at
        # t = 2.5, past the reference's end (not the last value held: that would compare 9
        # with 1).
        np.testing.assert_allclose(result.reference_values[:5], [1.0, 2.0, 3.0, 2.0, 1.0],
                                   atol=TOLERANCE)
        self.assertTrue(math.isnan(result.reference_values[5]))
        # s - r over the five usable samples: 0, 0, 0.5, 1, 1; sum r^2 = 1 + 4 + 9 + 4 + 1.
        expected = math.sqrt((0.5 ** 2 + 1.0 + 1.0) / 19.0)
        self.assertAlmostEqual(result.error, expected, delta=TOLERANCE)
        self.assertEqual(result.message, "1 of 6 samples without a finite reference, left out")

    def test_analytic_reference_with_definitions(self):
        # r = a t + b with definitions a = 2, b = a + 1 (so b = 3): at t = 0, 1, 2 it is
        # 3, 5, 7. s = 3, 5.5, 6: s - r = 0, 0.5, -1; sum r^2 = 9 + 25 + 49 = 83.
        self.write_probe("gauge", ["h@p0"], [[0.0, 3.0], [1.0, 5.5], [2.0, 6.0]],
                         {"p0": (0.5, 0.25)})
        spec = self.load({"probe": "gauge", "kind": "time_series", "column": "h@p0"},
                         {"definitions": {"a": 2, "b": "a + 1"}, "expression": "a * t + b"},
                         "l2_time")
        result = self.compare(spec)
        self.assertAlmostEqual(result.error, math.sqrt((0.25 + 1.0) / 83.0), delta=TOLERANCE)

    def test_only_the_window_is_compared_and_scale_applies_first(self):
        # Scale 2 doubles the column: s = 2, 4, 6, 8 at t = 0, 1, 2, 3; the window [0.5, 2.5]
        # keeps t = 1, 2. Against r = 3: s - r = 1, 3; sum r^2 = 9 + 9.
        self.write_probe("gauge", ["h@p0"], [[0.0, 1.0], [1.0, 2.0], [2.0, 3.0], [3.0, 4.0]],
                         {"p0": (0.5, 0.25)})
        spec = self.load({"probe": "gauge", "kind": "time_series", "column": "h@p0",
                          "scale": 2.0, "window": [0.5, 2.5]}, {"value": 3.0}, "l2_time")
        result = self.compare(spec)
        self.assertAlmostEqual(result.error, math.sqrt((1.0 + 9.0) / 18.0), delta=TOLERANCE)
        np.testing.assert_allclose(result.sample.abscissa, [1.0, 2.0])

    def test_reference_without_any_finite_sample_is_an_error(self):
        self.write_file("reference.csv", "t,h\n10,1\n11,2\n")
        self.write_probe("gauge", ["h@p0"], [[0.0, 1.0], [1.0, 2.0]], {"p0": (0.5, 0.25)})
        spec = self.load({"probe": "gauge", "kind": "time_series", "column": "h@p0"},
                         {"csv": "reference.csv", "columns": ["t", "h"]}, "l2_time")
        with self.assertRaisesRegex(study.ComparisonError, "not finite at any sample"):
            self.compare(spec)


class RelativeErrorAtPoint(StudyFixture):
    """relative_at_point: |s - r| / |r| of the final value."""

    def test_last_row_against_a_negative_value(self):
        # The last row counts (not the first, 5); r = -2 is negative, so without the abs in the
        # denominator the error would be -0.05. s = -1.9: |-1.9 + 2| / 2 = 0.05.
        self.write_probe("gauge", ["h@p0"], [[0.0, 5.0], [1.0, 7.0], [2.0, -1.9]],
                         {"p0": (0.5, 0.25)})
        spec = self.load({"probe": "gauge", "kind": "final", "column": "h@p0"},
                         {"value": -2.0}, "relative_at_point")
        result = self.compare(spec)
        self.assertAlmostEqual(result.error, 0.1 / 2.0, delta=TOLERANCE)
        np.testing.assert_allclose(result.sample.values, [-1.9])

    def test_analytic_reference_at_the_probe_point_and_final_time(self):
        # p0 = (0.5, 0.25), final time 2: r = x + 4 y + t = 0.5 + 1 + 2 = 3.5. With scale 3 the
        # simulated value is 3 * 1.4 = 4.2: |4.2 - 3.5| / 3.5 = 0.2.
        self.write_probe("gauge", ["h@p0"], [[0.0, 0.0], [2.0, 1.4]], {"p0": (0.5, 0.25)})
        spec = self.load({"probe": "gauge", "kind": "final", "column": "h@p0", "scale": 3.0},
                         {"expression": "x + 4 * y + t"}, "relative_at_point")
        result = self.compare(spec)
        np.testing.assert_allclose(result.reference_values, [3.5], atol=TOLERANCE)
        self.assertAlmostEqual(result.error, 0.7 / 3.5, delta=TOLERANCE)

    def test_values_of_a_time_series(self):
        # Series 0, 3, -1, 2: mean 1, maximum 3, amplitude (3 - (-1)) / 2 = 2; each against
        # the reference 2.5.
        self.write_probe("gauge", ["h@p0"], [[0.0, 0.0], [1.0, 3.0], [2.0, -1.0], [3.0, 2.0]],
                         {"p0": (0.5, 0.25)})
        for kind, value in (("mean", 1.0), ("maximum", 3.0), ("amplitude", 2.0)):
            with self.subTest(kind=kind):
                spec = self.load({"probe": "gauge", "kind": kind, "column": "h@p0"},
                                 {"value": 2.5}, "relative_at_point")
                result = self.compare(spec)
                self.assertAlmostEqual(result.sample.values[-1], value, delta=TOLERANCE)
                self.assertAlmostEqual(result.error, abs(value - 2.5) / 2.5, delta=TOLERANCE)

    def test_missing_column_names_it(self):
        self.write_probe("gauge", ["h@p0"], [[0.0, 0.0], [2.0, 1.4]], {"p0": (0.5, 0.25)})
        spec = self.load({"probe": "gauge", "kind": "final", "column": "h@p7"},
                         {"value": 1.0}, "relative_at_point")
        with self.assertRaisesRegex(study.ComparisonError, "no column 'h@p7'.*h@p0"):
            self.compare(spec)


class ArrivalTime(StudyFixture):
    """arrival_time: the first upward crossing of the threshold, linear between rows; the error
    is |t_simulated - t_reference|."""

    def test_crossing_between_two_samples_at_a_known_fraction(self):
        # 0.2 at t = 1, 0.6 at t = 2: 0.5 is (0.5 - 0.2) / (0.6 - 0.2) = 3/4 of the way, 1.75.
        # The same fraction on the segment after (t = 2 to 3) would give 2.75.
        times = np.array([0.0, 1.0, 2.0, 3.0])
        values = np.array([0.0, 0.2, 0.6, 1.0])
        self.assertAlmostEqual(study.arrival_time(times, values, 0.5), 1.75, delta=TOLERANCE)
        # Uneven steps: 0.4 at t = 0.5, 0.9 at t = 0.75: 0.5 is 1/5 of the way, 0.55.
        times = np.array([0.0, 0.5, 0.75, 2.0])
        values = np.array([0.0, 0.4, 0.9, 1.0])
        self.assertAlmostEqual(study.arrival_time(times, values, 0.5), 0.55, delta=TOLERANCE)

    def test_only_the_first_upward_crossing_counts(self):
        # Starting above the threshold is not an arrival; the downward crossing (1 -> 2) is
        # skipped; of the upward crossings (2 -> 3 and 4 -> 5) the first counts:
        # 0.2 -> 0.8 between t = 2 and 3, 0.5 halfway: 2.5.
        times = np.arange(6.0)
        values = np.array([0.9, 0.7, 0.2, 0.8, 0.1, 1.0])
        self.assertAlmostEqual(study.arrival_time(times, values, 0.5), 2.5, delta=TOLERANCE)

    def test_reaching_the_threshold_exactly_is_an_arrival_at_that_sample(self):
        times = np.array([0.0, 1.0, 2.0])
        self.assertEqual(study.arrival_time(times, np.array([0.0, 0.5, 1.0]), 0.5), 1.0)

    def test_no_crossing_is_nan(self):
        times = np.array([0.0, 1.0, 2.0])
        self.assertTrue(math.isnan(study.arrival_time(times, np.array([0.0, 0.3, 0.4]), 0.5)))
        self.assertTrue(math.isnan(study.arrival_time(times, np.array([0.6, 0.3, 0.4]), 0.5)))

    # Simulated: 0.4 at t = 1.0 and 0.9 at t = 1.5, so 0.5 is crossed 1/5 of the way: 1.1.
    SIMULATED = [[0.0, 0.0], [0.5, 0.2], [1.0, 0.4], [1.5, 0.9], [2.0, 1.0]]

    def load_arrival(self, reference: dict, rows=None) -> study.Study:
        self.write_probe("gauge", ["p@p0"], rows or self.SIMULATED, {"p0": (0.5, 0.25)})
        return self.load({"probe": "gauge", "kind": "time_series", "column": "p@p0"},
                         reference, "arrival_time", threshold=0.5)

    def test_against_a_csv_reference(self):
        # Reference 0.1 at t = 1 and 0.6 at t = 2 (column p, not the decoy q): 0.5 is 4/5 of the
        # way, 1.8. Error |1.1 - 1.8| = 0.7.
        self.write_file("reference.csv", "t,q,p\n0,0,0\n1,0.9,0.1\n2,0.9,0.6\n3,0.9,1.0\n")
        result = self.compare(self.load_arrival({"csv": "reference.csv",
                                                 "columns": ["t", "p"]}))
        self.assertAlmostEqual(result.arrivals[0], 1.1, delta=TOLERANCE)
        self.assertAlmostEqual(result.arrivals[1], 1.8, delta=TOLERANCE)
        self.assertAlmostEqual(result.error, 0.7, delta=TOLERANCE)

    def test_against_a_value_which_is_the_reference_arrival_time(self):
        result = self.compare(self.load_arrival({"value": 1.25}))
        self.assertAlmostEqual(result.arrivals[1], 1.25, delta=TOLERANCE)
        self.assertAlmostEqual(result.error, 0.15, delta=TOLERANCE)  # |1.1 - 1.25|

    def test_against_an_analytic_reference(self):
        # r = t / 2 crosses 0.5 at t = 1 (linear, so its fine sampling is exact): error 0.1.
        result = self.compare(self.load_arrival({"expression": "t / 2"}))
        self.assertAlmostEqual(result.arrivals[1], 1.0, delta=TOLERANCE)
        self.assertAlmostEqual(result.error, 0.1, delta=TOLERANCE)

    def test_no_simulated_crossing_is_an_error(self):
        spec = self.load_arrival({"value": 1.0}, rows=[[0.0, 0.0], [1.0, 0.3], [2.0, 0.4]])
        with self.assertRaisesRegex(study.ComparisonError, "p@p0 never crosses 0.5"):
            self.compare(spec)

    def test_no_reference_crossing_is_an_error(self):
        spec = self.load_arrival({"expression": "0.1 * t"})  # at most 0.2 up to t = 2
        with self.assertRaisesRegex(study.ComparisonError, "reference never crosses 0.5"):
            self.compare(spec)

    def test_threshold_is_required(self):
        with self.assertRaisesRegex(study.StudyError, "threshold: missing"):
            self.load({"probe": "gauge", "kind": "time_series", "column": "p@p0"},
                      {"value": 1.0}, "arrival_time")


# ---- References -------------------------------------------------------------------------------


class ReferenceCsv(StudyFixture):
    """read_reference_csv: '#' comment lines, one header line, two columns sorted by the first."""

    TEXT = ("# digitised by hand\n"
            "# columns: time, a decoy, pressure\n"
            " t , other , p \n"
            "\n"
            "2.0, 7, 20.5\n"
            "0.0, 5, 0.5\n"
            "1.0, 6, 10.5\n")

    def test_columns_by_name_sorted_by_the_first(self):
        path = self.write_file("ref.csv", self.TEXT)
        abscissa, ordinate = study.read_reference_csv(path, ["t", "p"])
        np.testing.assert_array_equal(abscissa, [0.0, 1.0, 2.0])
        np.testing.assert_array_equal(ordinate, [0.5, 10.5, 20.5])

    def test_columns_by_index(self):
        path = self.write_file("ref.csv", self.TEXT)
        abscissa, ordinate = study.read_reference_csv(path, [0, 1])
        np.testing.assert_array_equal(abscissa, [0.0, 1.0, 2.0])
        np.testing.assert_array_equal(ordinate, [5.0, 6.0, 7.0])

    def test_missing_column_names_the_column_file_and_header(self):
        path = self.write_file("ref.csv", self.TEXT)
        with self.assertRaises(study.StudyError) as caught:
            study.read_reference_csv(path, ["t", "pressure"])
        message = str(caught.exception)
        self.assertIn("reference.columns", message)
        self.assertIn("'pressure'", message)
        self.assertIn(str(path), message)
        self.assertIn("header: t, other, p", message)

    def test_index_outside_the_header_is_refused(self):
        path = self.write_file("ref.csv", self.TEXT)
        with self.assertRaisesRegex(study.StudyError, "no column 3"):
            study.read_reference_csv(path, [0, 3])

    def test_missing_file_names_the_file(self):
        path = self.root / "absent.csv"
        with self.assertRaises(study.StudyError) as caught:
            study.read_reference_csv(path, ["t", "p"])
        self.assertIn("cannot read", str(caught.exception))
        self.assertIn(str(path), str(caught.exception))

    def test_too_few_rows_and_non_numeric_values(self):
        short = self.write_file("short.csv", "# only one row\nt,p\n0,1\n")
        with self.assertRaisesRegex(study.StudyError, "short.csv needs a header line and at "
                                                      "least two rows"):
            study.read_reference_csv(short, ["t", "p"])
        bad = self.write_file("bad.csv", "t,p\n0,1\n1,n/a\n")
        with self.assertRaisesRegex(study.StudyError, "bad.csv: non-numeric"):
            study.read_reference_csv(bad, ["t", "p"])

    def test_study_file_resolves_the_csv_next_to_it(self):
        self.write_file("ref.csv", self.TEXT)
        spec = self.load({"probe": "gauge", "kind": "time_series", "column": "h@p0"},
                         {"csv": "ref.csv", "columns": ["t", "p"]}, "l2_time")
        self.assertEqual(spec.reference.kind, "csv")
        self.assertEqual(spec.reference.csv_file, (self.root / "ref.csv").resolve())
        self.assertEqual(spec.reference.along, "time")
        np.testing.assert_array_equal(spec.reference.ordinate, [0.5, 10.5, 20.5])

    def test_study_file_with_a_missing_column_names_study_and_column(self):
        self.write_file("ref.csv", self.TEXT)
        with self.assertRaises(study.StudyError) as caught:
            self.load({"probe": "gauge", "kind": "time_series", "column": "h@p0"},
                      {"csv": "ref.csv", "columns": ["t", "h"]}, "l2_time")
        message = str(caught.exception)
        self.assertTrue(message.startswith(str(self.root / "study.yaml")), message)
        self.assertIn("no column 'h'", message)
        self.assertIn("ref.csv", message)

    def test_study_file_with_a_missing_csv_names_it(self):
        with self.assertRaisesRegex(study.StudyError, "cannot read .*nowhere.csv"):
            self.load({"probe": "gauge", "kind": "time_series", "column": "h@p0"},
                      {"csv": "nowhere.csv", "columns": ["t", "p"]}, "l2_time")


class EvaluateReference(unittest.TestCase):
    def test_csv_along_a_coordinate(self):
        # A profile reference along y: 10 at y = 0, 20 at y = 1; y = 0.25 -> 12.5, 0.5 -> 15,
        # 1.5 is outside: NaN. The time (5) plays no part.
        reference = study.Reference("csv", "s", abscissa=np.array([0.0, 1.0]),
                                    ordinate=np.array([10.0, 20.0]), along="y")
        variables = {"x": np.zeros(3), "y": np.array([0.25, 0.5, 1.5]), "z": np.zeros(3),
                     "t": np.full(3, 5.0), "distance": np.zeros(3)}
        values = study.evaluate_reference(reference, variables)
        np.testing.assert_allclose(values[:2], [12.5, 15.0], atol=TOLERANCE)
        self.assertTrue(math.isnan(values[2]))

    def test_csv_along_time_and_a_constant_value(self):
        reference = study.Reference("csv", "s", abscissa=np.array([0.0, 2.0]),
                                    ordinate=np.array([1.0, -3.0]))
        variables = {"t": np.array([-1.0, 0.5, 2.0]), "y": np.array([9.0, 9.0, 9.0])}
        values = study.evaluate_reference(reference, variables)
        self.assertTrue(math.isnan(values[0]))  # before the first row: NaN, not 1
        np.testing.assert_allclose(values[1:], [0.0, -3.0], atol=TOLERANCE)
        constant = study.evaluate_reference(study.Reference("value", "s", value=4.5), variables)
        np.testing.assert_array_equal(constant, [4.5, 4.5, 4.5])

    def test_expression_uses_the_functions_and_broadcasts(self):
        code = study.compile_expression("hypot(3, x) + erf(0)", "reference.expression",
                                        set(study.VARIABLES))
        reference = study.Reference("expression", "s", expression="...", code=code)
        variables = {"x": np.array([4.0, 0.0]), "t": np.zeros(2)}
        np.testing.assert_allclose(study.evaluate_reference(reference, variables), [5.0, 3.0],
                                   atol=TOLERANCE)
        # A constant expression still gives one value per sample.
        code = study.compile_expression("2 * pi", "reference.expression", set(study.VARIABLES))
        reference = study.Reference("expression", "s", expression="2 * pi", code=code)
        np.testing.assert_allclose(study.evaluate_reference(reference, variables),
                                   [2 * math.pi] * 2, atol=TOLERANCE)


class ReadProbe(StudyFixture):
    def test_times_columns_values_and_coordinates(self):
        self.write_probe("gauge", ["h@p0", "u@p0"], [[0.0, 1.0, 2.0], [0.5, 3.0, 4.0]],
                         {"p0": (0.5, 0.25)})
        times, columns, values, coordinates = study.read_probe(self.out, "gauge")
        np.testing.assert_array_equal(times, [0.0, 0.5])
        self.assertEqual(columns, ["h@p0", "u@p0"])
        np.testing.assert_array_equal(values, [[1.0, 2.0], [3.0, 4.0]])
        self.assertEqual(coordinates, {"p0": (0.5, 0.25, 0.0)})  # 2D: z = 0

    def test_missing_probe_file(self):
        with self.assertRaisesRegex(study.ComparisonError, "no probe file gauge.csv"):
            study.read_probe(self.out, "gauge")


# ---- Combined final values --------------------------------------------------------------------


class Combine(StudyFixture):
    """A final value c = f(c0, c1, ...) of the last row of the listed columns, in the listed
    order."""

    def setUp(self):
        super().setUp()
        # The CSV holds the columns in another order than 'columns' lists them, and a first row
        # that must not be used: c0 = activation_time@p0 = 3 and c1 = activation_time@p1 = 4 at
        # the last row.
        self.write_probe("activation", ["activation_time@p1", "other@p0", "activation_time@p0"],
                         [[0.0, -7.0, 50.0, 100.0], [6.0, 4.0, 60.0, 3.0]],
                         {"p0": (3.0, 0.2), "p1": (5.0, 0.2)})

    def load_combine(self, combine, value=1.0, columns=("activation_time@p0",
                                                        "activation_time@p1")):
        return self.load({"probe": "activation", "kind": "final", "columns": list(columns),
                          "combine": combine}, {"value": value}, "relative_at_point")

    def test_expressions_evaluated_by_hand(self):
        cases = (("2 / (c1 - c0)", 2.0 / (4.0 - 3.0)),
                 ("c0 - 2*c1", 3.0 - 2.0 * 4.0),
                 ("sqrt(c0**2 + c1**2)", 5.0),
                 ("hypot(c0, c1)", 5.0),
                 ("c1 / c0", 4.0 / 3.0))
        for text, expected in cases:
            with self.subTest(combine=text):
                sample = self.compare(self.load_combine(text)).sample
                self.assertAlmostEqual(sample.values[0], expected, delta=TOLERANCE)

    def test_listed_order_decides_which_column_is_c0(self):
        sample = self.compare(self.load_combine(
            "c0 - 2*c1", columns=("activation_time@p1", "activation_time@p0"))).sample
        self.assertAlmostEqual(sample.values[0], 4.0 - 2.0 * 3.0, delta=TOLERANCE)

    def test_relative_error_of_the_combined_value(self):
        # 2 / (4 - 3) = 2 against 2.5: |2 - 2.5| / 2.5 = 0.2.
        result = self.compare(self.load_combine("2 / (c1 - c0)", value=2.5))
        self.assertAlmostEqual(result.error, 0.2, delta=TOLERANCE)

    def test_combined_value_has_the_final_time_and_no_position(self):
        sample = self.compare(self.load_combine("c0 + c1")).sample
        np.testing.assert_array_equal(sample.variables["t"], [6.0])
        for name in ("x", "y", "z", "distance"):
            self.assertTrue(math.isnan(sample.variables[name][0]), name)
        self.assertEqual(sample.field_name, "c0 + c1")

    def test_not_finite_is_an_error_naming_the_values(self):
        spec = self.load_combine("1 / (c0 - c1 + 1)")  # 3 - 4 + 1 = 0: 1 / 0
        with self.assertRaisesRegex(study.ComparisonError, r"not finite \(c0 = 3, c1 = 4\)"):
            self.compare(spec)

    def test_missing_column_is_named(self):
        spec = self.load_combine("c0 + c1", columns=("activation_time@p0", "activation_time@p2"))
        with self.assertRaisesRegex(study.ComparisonError, "no column 'activation_time@p2'"):
            self.compare(spec)

    def test_caret_is_refused_and_unused_columns_too(self):
        with self.assertRaisesRegex(study.StudyError, r"quantity.combine: '\^' is not a power"):
            self.load_combine("sqrt(c0^2 + c1^2)")
        with self.assertRaisesRegex(study.StudyError, "quantity.combine: does not use c1"):
            self.load_combine("2 * c0")


if __name__ == "__main__":
    unittest.main()
