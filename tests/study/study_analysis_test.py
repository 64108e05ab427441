#!/usr/bin/python3
"""Unit tests of bench/study.py's time-series analysis: the dominant oscillation of a noisy
signal, the smoothing and window of a quantity, the run key of the run cache, and a study's
comparison tables and reference band."""
import sys
import tempfile
import unittest
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "bench"))
import study  # noqa: E402


def quantity(**options):
    return study.Quantity(probe="p", kind=options.pop("kind", "time_series"), field=None,
                          column="c", time="last", **options)


class DominantOscillation(unittest.TestCase):
    def test_finds_period_and_amplitude_under_noise_and_offset(self):
        t = np.linspace(0.0, 3.0, 601)
        signal = 1.3 * np.sin(2 * np.pi * t / 0.3337 + 0.4) + 0.1
        noise = 0.3 * np.sin(2 * np.pi * 60.0 * t)
        period, amplitude = study.dominant_oscillation(t, signal + noise)
        self.assertAlmostEqual(period, 0.3337, delta=0.002)
        self.assertAlmostEqual(amplitude, 1.3, delta=0.02)

    def test_constant_series_is_refused(self):
        with self.assertRaises(study.ComparisonError):
            study.dominant_oscillation(np.linspace(0, 1, 50), np.ones(50))


class CycleStatistics(unittest.TestCase):
    def test_mean_and_amplitude_are_the_benchmarks_not_the_sinusoids(self):
        # c + A (sin + 0.1 sin 3x): extremes +-0.9 A (at x = pi/2 for 0.1 < 1/9), so the benchmark's
        # amplitude is 0.9 A where the strongest sinusoid's is A. c + A sin + B sin^2 (A > 2B):
        # extremes c + B +- A, so its mean is c + B where the time mean is c + B / 2.
        t = np.arange(0.0, 6.0 + 1e-9, 0.002)
        x = 2 * np.pi * t / 0.53
        mean, amplitude = study.cycle_statistics(t, 0.3 + 2.0 * (np.sin(x) + 0.1 * np.sin(3 * x)))
        self.assertAlmostEqual(amplitude, 1.8, delta=1e-3)
        self.assertAlmostEqual(mean, 0.3, delta=1e-3)
        self.assertAlmostEqual(study.dominant_oscillation(t, 2.0 * np.sin(x))[1], 2.0, delta=0.02)
        mean, amplitude = study.cycle_statistics(t, 0.3 + 2.0 * np.sin(x) + 0.5 * np.sin(x) ** 2)
        self.assertAlmostEqual(mean, 0.8, delta=1e-3)
        self.assertAlmostEqual(amplitude, 2.0, delta=1e-3)

    def test_constant_series_is_refused(self):
        with self.assertRaises(study.ComparisonError):
            study.cycle_statistics(np.linspace(0, 1, 50), np.ones(50))


class SeriesPreparation(unittest.TestCase):
    def test_window_cuts_and_smoothing_is_centred(self):
        t = np.arange(0.0, 1.0001, 0.01)
        # A centred average leaves a straight line unchanged; an off-centre one would shift it.
        times, values = study._prepare_series(quantity(smooth=0.02, window=(0.2, 0.8)), t, 2 * t)
        self.assertAlmostEqual(times[0], 0.2)
        self.assertAlmostEqual(times[-1], 0.8)
        self.assertTrue(np.allclose(values, 2 * times, atol=1e-12))
        noisy = np.where(np.arange(t.size) % 2 == 0, 1.0, -1.0)
        _, smoothed = study._prepare_series(quantity(smooth=0.1, window=(0.2, 0.8)), t, noisy)
        self.assertLess(np.max(np.abs(smoothed)), 0.1)

    def test_noise_is_the_spread_around_the_moving_mean(self):
        # A slow ramp (left unchanged by a centred mean) plus an alternating +-0.3: the noise is
        # 0.3 whatever the ramp; a noise kind without a moving-mean width is refused.
        t = np.arange(0.0, 1.0001, 0.01)
        signal = 5.0 * t + np.where(np.arange(t.size) % 2 == 0, 0.3, -0.3)
        q = quantity(kind="noise", smooth=0.2, window=(0.3, 0.7))
        times, residual = study._prepare_series(q, t, signal)
        self.assertAlmostEqual(study.SERIES_VALUES["noise"](q, times, residual), 0.3, delta=0.02)
        with self.assertRaises(study.StudyError):
            study._parse_series_options({"window": [0, 1]}, "noise")

    def test_empty_window_is_an_error(self):
        with self.assertRaises(study.ComparisonError):
            study._prepare_series(quantity(window=(5.0, 6.0)), np.linspace(0, 1, 11),
                                  np.zeros(11))


class RunKey(unittest.TestCase):
    def test_depends_on_executable_scene_and_overrides(self):
        with tempfile.TemporaryDirectory() as directory:
            exe, scene = Path(directory) / "cosph", Path(directory) / "scene.yaml"
            exe.write_bytes(b"binary 1")
            scene.write_text("end_time: 1\n")
            key = study.run_key(exe, scene, {"a": 1}, 1)
            self.assertEqual(key, study.run_key(exe, scene, {"a": 1}, 1))
            self.assertNotEqual(key, study.run_key(exe, scene, {"a": 2}, 1))
            scene.write_text("end_time: 2\n")
            self.assertNotEqual(key, study.run_key(exe, scene, {"a": 1}, 1))
            scene.write_text("end_time: 1\n")
            exe.write_bytes(b"binary 2")
            self.assertNotEqual(key, study.run_key(exe, scene, {"a": 1}, 1))

    def test_depends_on_the_files_the_scene_names(self):
        with tempfile.TemporaryDirectory() as directory:
            exe, scene = Path(directory) / "cosph", Path(directory) / "scene.yaml"
            table = Path(directory) / "fibres.csv"
            exe.write_bytes(b"binary")
            scene.write_text("fibres: {csv: fibres.csv}\n")
            table.write_text("x,y,f\n0,0,1\n")
            key = study.run_key(exe, scene, {}, 1)
            table.write_text("x,y,f\n0,0,2\n")
            self.assertNotEqual(key, study.run_key(exe, scene, {}, 1))


class ComparisonsAndBand(unittest.TestCase):
    """A final-value study may draw another method's table beside its points and the spread of
    the reference solvers; anything malformed is refused with its key."""

    SCENE = ("dimension: 2\nend_time: 1\nprobes:\n  - name: tip\n"
             "    points: {at: [{coordinates: [0, 0]}], fields: [z]}\n")
    STUDY = """title: t
description: d
scene: scene.yaml
sweep: {{axes: [{{key: a, values: [1, 2]}}]}}
quantity: {{probe: tip, kind: {kind}, column: z}}
reference: {{value: 4.17, source: s{band}}}
comparisons: [{{label: seed, source: table 1, csv: table.csv, columns: [particles, z]}}]
norm: {norm}
{extra}"""

    def load(self, kind="final", norm="relative_at_point", band="", extra=""):
        with tempfile.TemporaryDirectory() as directory:
            root = Path(directory)
            (root / "scene.yaml").write_text(self.SCENE)
            (root / "table.csv").write_text("# a comment\nparticles,z\n4544,4.217\n1025,4.707\n")
            path = root / "study.yaml"
            path.write_text(self.STUDY.format(kind=kind, norm=norm, band=band, extra=extra))
            return study.load_study(path)

    def test_table_is_read_sorted_by_particle_count_and_band_kept(self):
        loaded = self.load(band=", band: {low: 4.0, high: 4.2, label: FEM}")
        (comparison,) = loaded.comparisons
        self.assertEqual(comparison.label, "seed")
        self.assertEqual(list(comparison.particles), [1025.0, 4544.0])
        self.assertEqual(list(comparison.values), [4.707, 4.217])
        self.assertEqual(loaded.reference.band, (4.0, 4.2, "FEM"))

    def test_refuses_a_table_beside_a_time_series_and_an_empty_band(self):
        with self.assertRaisesRegex(study.StudyError, "comparisons: only for a final value"):
            self.load(kind="time_series", norm="l2_time")
        with self.assertRaisesRegex(study.StudyError, "reference.band: low"):
            self.load(band=", band: {low: 4.2, high: 4.0, label: FEM}")
        with self.assertRaisesRegex(study.StudyError, "reference.band.*colour"):
            self.load(band=", band: {low: 4.0, high: 4.2, label: FEM, colour: red}")

    def test_a_study_may_give_its_runs_more_time(self):
        self.assertIsNone(self.load().timeout)
        self.assertEqual(self.load(extra="timeout: 2400").timeout, 2400.0)
        with self.assertRaisesRegex(study.StudyError, "timeout: expected seconds > 0"):
            self.load(extra="timeout: 0")
        with self.assertRaisesRegex(study.StudyError, "timeout: expected a number"):
            self.load(extra="timeout: long")


class Ensemble(unittest.TestCase):
    """A point of an ensemble study is the mean of one run per ensemble value, compared with the
    reference as one run would be; its members' values are kept for the range."""

    def load(self, extra):
        return ComparisonsAndBand().load(extra=extra)

    def member(self, point, value, reference=4.0, wall=2.0):
        result = study.PointResult(point, wall_seconds=wall, cpu_seconds=wall, particles=100.0,
                                   steps=10.0, particle_steps_per_second=500.0, threads=2.0)
        t = np.array([1.0])
        result.sample = study.Sample(np.array([value]), {"t": t}, t, "time", "z")
        result.reference_values = np.array([reference])
        return result

    def test_members_differ_in_the_ensemble_key_only(self):
        loaded = self.load("ensemble: {key: output.interval, values: [0.5, 0.7], label: out}")
        point = loaded.points()[1]
        members = study.ensemble_members(loaded, point)
        self.assertEqual([m.overrides for m in members],
                         [{"a": 2, "output.interval": 0.5}, {"a": 2, "output.interval": 0.7}])
        self.assertEqual([m.index for m in members], [1, 1])
        self.assertEqual(members[1].label, "a=2, out=0.7")

    def test_point_is_the_members_mean_and_keeps_their_range(self):
        loaded = self.load("ensemble: {key: output.interval, values: [0.5, 0.7, 0.9]}")
        point = loaded.points()[0]
        members = [self.member(point, v, wall=w) for v, w in ((4.2, 1.0), (4.6, 2.0), (4.4, 3.0))]
        combined = study.combine_members(loaded, point, members)
        self.assertEqual(combined.status, "ok")
        self.assertAlmostEqual(combined.sample.values[-1], 4.4)
        self.assertAlmostEqual(combined.error, 0.4 / 4.0)  # relative_at_point, of the mean
        self.assertEqual(combined.members, (4.2, 4.6, 4.4))
        self.assertAlmostEqual(combined.wall_seconds, 2.0)
        self.assertIn("values 4.2 to 4.6", combined.message)
        with tempfile.TemporaryDirectory() as directory:
            path = Path(directory) / "results.csv"
            study.write_results_csv(path, loaded, [combined])
            row = path.read_text().splitlines()[1]
            self.assertTrue(row.endswith("4.2; 4.6; 4.4"), row)

    def test_members_that_agree_plot_without_negative_bars(self):
        # The mean of three 0.1s is 0.10000000000000002, above every member.
        loaded = self.load("ensemble: {key: output.interval, values: [0.5, 0.7, 0.9]}")
        point = loaded.points()[0]
        combined = study.combine_members(loaded, point, [self.member(point, 0.1)] * 3)
        with tempfile.TemporaryDirectory() as directory:
            study.write_plot(Path(directory) / "plot.png", loaded, [combined])

    def test_members_with_other_references_fail_the_point(self):
        loaded = self.load("ensemble: {key: output.interval, values: [0.5, 0.7]}")
        point = loaded.points()[0]
        combined = study.combine_members(
            loaded, point, [self.member(point, 4.2), self.member(point, 4.2, reference=4.1)])
        self.assertEqual(combined.status, "failed")
        self.assertIn("references differ", combined.message)

    def test_a_failed_member_fails_the_point(self):
        loaded = self.load("ensemble: {key: output.interval, values: [0.5, 0.7]}")
        point = loaded.points()[0]
        members = [self.member(point, 4.2), study.PointResult(point, "diverged", "NaN at t = 3")]
        combined = study.combine_members(loaded, point, members)
        self.assertEqual(combined.status, "diverged")
        self.assertEqual(combined.message, "member 1: NaN at t = 3")
        self.assertTrue(np.isnan(combined.error))

    def test_refuses_one_value_and_a_time_series(self):
        refused = [
            ("ensemble.values: expected a list of two", "ensemble: {key: o, values: [0.5]}"),
            ("ensemble.key: 'a' is also set by", "ensemble: {key: a, values: [0.5, 0.7]}"),
            ("ensemble.key: 'b' is also set by",
             "overrides: {b: 1}\nensemble: {key: b, values: [0.5, 0.7]}"),
            ("ensemble.values: a value is listed twice",
             "ensemble: {key: o, values: [0.5, 0.7, 0.5]}"),
            ("overrides", "overrides: 5\nensemble: {key: b, values: [0.5, 0.7]}"),
            ("ensemble.*vlaues.*unknown key", "ensemble: {key: o, vlaues: [0.5, 0.7]}"),
        ]
        for message, extra in refused:
            with self.subTest(extra=extra), self.assertRaisesRegex(study.StudyError, message):
                self.load(extra)
        with tempfile.TemporaryDirectory() as directory:
            root = Path(directory)
            (root / "scene.yaml").write_text(ComparisonsAndBand.SCENE)
            text = ComparisonsAndBand.STUDY.format(
                kind="time_series", norm="l2_time", band="",
                extra="ensemble: {key: output.interval, values: [0.5, 0.7]}")
            (root / "study.yaml").write_text(text.replace("comparisons:", "# comparisons:"))
            with self.assertRaisesRegex(study.StudyError,
                                        "ensemble: needs a single-valued quantity"):
                study.load_study(root / "study.yaml")


class RunsOf(unittest.TestCase):
    """A study that reads another study's runs takes what makes them (scene, overrides, sweep,
    ensemble, repeat, timeout) from that study's file, and sets none of it itself."""

    BASE = """title: base
description: d
scene: ../scenes/scene.yaml
overrides: {end_time: 3}
sweep: {axes: [{key: a, values: [1, 2]}]}
ensemble: {key: output.interval, values: [0.5, 0.7]}
repeat: 2
timeout: 600
quantity: {probe: tip, kind: final, column: z}
reference: {value: 4.17, source: s}
norm: relative_at_point
"""
    READER = """title: reader
description: d
runs_of: {source}
quantity: {{probe: tip, kind: final, column: z}}
reference: {{value: 1.0, source: s}}
norm: relative_at_point
{extra}"""

    def load(self, source="../../base/base.yaml", extra="", base=BASE):
        with tempfile.TemporaryDirectory() as directory:
            root = Path(directory)
            for folder in ("scenes", "base", "readers/deeper"):
                (root / folder).mkdir(parents=True)
            (root / "scenes" / "scene.yaml").write_text(ComparisonsAndBand.SCENE)
            (root / "base" / "base.yaml").write_text(base)
            (root / "base" / "chained.yaml").write_text("runs_of: base.yaml\n" + base)
            path = root / "readers" / "deeper" / "reader.yaml"
            path.write_text(self.READER.format(source=source, extra=extra))
            loaded = study.load_study(path)
            return loaded, study.load_study(root / "base" / "base.yaml")

    def test_takes_the_runs_from_the_named_study(self):
        reader, base = self.load()
        self.assertEqual(reader.scene, base.scene)  # relative to the base's file, not the reader's
        self.assertEqual(reader.overrides, {"end_time": 3})
        self.assertEqual([m.overrides for m in study.ensemble_members(reader, reader.points()[1])],
                         [m.overrides for m in study.ensemble_members(base, base.points()[1])])
        self.assertEqual((reader.repeat, reader.timeout), (2, 600.0))
        self.assertEqual((reader.title, reader.reference.value), ("reader", 1.0))

    def test_refuses_run_keys_of_its_own_a_chain_and_a_missing_file(self):
        refused = [
            ("sweep: comes from runs_of's study", {"extra": "sweep: {axes: []}"}),
            ("overrides: comes from runs_of's study", {"extra": "overrides: {b: 1}"}),
            ("runs_of: no such file", {"source": "../../base/none.yaml"}),
            ("reads another study's runs itself", {"source": "../../base/chained.yaml"}),
            ("runs_of: expected the path of a study file", {"source": "[1, 2]"}),
            ("is not a study with a scene", {"base": "title: t\n"}),
        ]
        for message, options in refused:
            with self.subTest(message=message), self.assertRaisesRegex(study.StudyError, message):
                self.load(**options)


if __name__ == "__main__":
    unittest.main()
