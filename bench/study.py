#!/usr/bin/python3
"""Accuracy-versus-cost studies: runs one cosph scene over a sweep of overrides, compares a probe
quantity of every run with a reference, and writes results.csv, table.md and plot.png.

usage: bench/study.py STUDY.yaml [--cosph PATH] [--out DIR] [--repeat N] [--expect-max-error X]

A study file (YAML; see bench/studies/*.yaml and the README section "Accuracy-versus-cost
studies") names the scene, the sweep, the quantity, the reference with its source, and the norm.
Exit codes: 0 done (points may have failed: they are recorded, not dropped), 1 the outputs could
not be written or the best error exceeds --expect-max-error, 2 an invalid study file or usage.
"""
import argparse
import ast
import csv
import hashlib
import itertools
import json
import math
import os
import platform
import re
import shutil
import subprocess
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Optional

import matplotlib
import numpy as np
import yaml

matplotlib.use("Agg")  # files only: the tool runs headless in CI
import matplotlib.pyplot as plt  # noqa: E402

REPO_ROOT = Path(__file__).resolve().parent.parent
DEFAULT_COSPH = REPO_ROOT / "build" / "release" / "app" / "cosph"

# period: the mean period of a time series' downward zero crossings (oscillating structures);
# mean, maximum, amplitude: one value of a time series (amplitude = (max - min) / 2);
# dominant_period, dominant_amplitude: the period and amplitude of the strongest sinusoid of a
# noisy oscillation (the peak of a Hann-windowed, zero-padded spectrum), e.g. the lift of a
# cylinder shedding vortices under acoustic noise;
# cycle_mean, cycle_amplitude: (max + min) / 2 and (max - min) / 2 of each whole period (the
# dominant one) in the window, averaged over the periods: Turek & Hron's "mean +- amplitude",
# which for a signal with harmonics differs from the time mean and the strongest sinusoid;
# noise: the standard deviation of a series around its own moving mean (of width `smooth`, which it
# requires) over the window, e.g. the acoustic noise on a wall pressure's plateau.
SCALAR_KINDS = ("period", "mean", "maximum", "amplitude", "dominant_period",
                "dominant_amplitude", "cycle_mean", "cycle_amplitude", "noise")
KINDS = ("profile", "time_series", "final") + SCALAR_KINDS
# Which quantity kinds each norm makes sense for: a spatial L2 needs a profile, an arrival time
# needs a time series, a relative error at a point needs a single value.
NORM_KINDS = {
    "max": ("profile", "time_series", "final") + SCALAR_KINDS,
    "l2_relative": ("profile",),
    "l2_time": ("time_series",),
    "relative_at_point": ("final",) + SCALAR_KINDS,
    "arrival_time": ("time_series",),
}
NORM_TEXT = {
    "max": "maximum absolute error",
    "l2_relative": "relative L2 error over the probe points, sqrt(sum (s - r)^2 / sum r^2)",
    "l2_time": "relative L2 error over the time series, sqrt(sum (s - r)^2 / sum r^2)",
    "relative_at_point": "relative error of the final value, |s - r| / |r|",
    "arrival_time": "absolute error of the arrival time (first upward crossing of the threshold)",
}
VARIABLES = ("x", "y", "z", "t", "distance")
CSV_ALONG = ("time", "x", "y", "z", "distance")


class StudyError(Exception):
    """An invalid study file: the message names the file and the key."""


class ComparisonError(Exception):
    """A run that finished but whose output cannot be compared with the reference."""


# ---- Study file -------------------------------------------------------------------------------


@dataclass(frozen=True)
class Axis:
    key: str
    values: list
    label: str


@dataclass(frozen=True)
class Point:
    index: int
    label: str
    overrides: dict  # scene key path -> value, in --set order
    axis_values: dict  # axis label -> value (empty for explicit points)


@dataclass(frozen=True)
class Quantity:
    probe: str
    kind: str
    field: Optional[str]
    column: Optional[str]
    time: Any  # "last" or a simulated time (profile only)
    # A final value derived from several final columns: combine, an expression of c0, c1, ...
    # (the columns in order), e.g. a conduction velocity 2 / (c1 - c0) from two activation times.
    columns: tuple = ()
    combine: Optional[str] = None
    combine_code: Any = None
    label: Optional[str] = None  # what the quantity is, for the tables and plots
    # Time series only: the samples inside [t0, t1], a centred moving average over `smooth`
    # time units (acoustic noise on forces), and a factor (e.g. force to coefficient).
    window: Optional[tuple] = None
    smooth: Optional[float] = None
    scale: float = 1.0


@dataclass(frozen=True)
class Reference:
    kind: str  # expression, csv or value
    source: str
    expression: Optional[str] = None
    definitions: tuple = ()  # ((name, text, code), ...) evaluated in order before the expression
    code: Any = None
    csv_file: Optional[Path] = None
    abscissa: Optional[np.ndarray] = None
    ordinate: Optional[np.ndarray] = None
    along: str = "time"
    value: Optional[float] = None
    band: Optional[tuple] = None  # (low, high, label): where a set of reference solvers spread


@dataclass(frozen=True)
class Comparison:
    """Another method's final values against its particle count (a paper's convergence table),
    drawn beside cosph's points; it is not what errors are measured against."""
    label: str
    source: str
    particles: np.ndarray
    values: np.ndarray


@dataclass(frozen=True)
class Study:
    path: Path
    name: str
    title: str
    description: str
    scene: Path
    overrides: dict
    axes: list
    explicit_points: list
    quantity: Quantity
    reference: Reference
    norm: str
    threshold: Optional[float]
    repeat: int
    order: Optional[int]
    comparisons: tuple = ()
    timeout: Optional[float] = None  # seconds a run may take (the runner's default if None)
    # Runs that differ only in a setting that should not matter (e.g. output.interval: a step ends
    # on each output time, so a chaotic flow takes another path): each point is the mean of one
    # run per value, with the members' spread (single-valued quantities only).
    ensemble: Optional[Axis] = None

    def points(self) -> list:
        """The cartesian product of the axes, then the explicit points."""
        points = []
        # product() of no axes would yield one empty point: a study of explicit points only
        # must not get an extra point without overrides.
        combos = itertools.product(*(axis.values for axis in self.axes)) if self.axes else []
        for combo in combos:
            overrides = dict(self.overrides)
            axis_values = {}
            for axis, value in zip(self.axes, combo):
                overrides[axis.key] = value
                axis_values[axis.label] = value
            label = ", ".join(f"{a}={format_value(v)}" for a, v in axis_values.items())
            points.append(Point(len(points), label, overrides, axis_values))
        for label, extra in self.explicit_points:
            points.append(Point(len(points), label, {**self.overrides, **extra}, {}))
        return points


class _UniqueKeyLoader(yaml.SafeLoader):
    """A safe loader that rejects duplicate keys (PyYAML would silently keep the last one)."""


def _construct_unique_mapping(loader, node, deep=False):
    seen = set()
    for key_node, _ in node.value:
        key = loader.construct_object(key_node, deep=deep)
        if key in seen:
            mark = key_node.start_mark
            raise yaml.constructor.ConstructorError(
                None, None, f"duplicate key '{key}' (line {mark.line + 1})", mark)
        seen.add(key)
    return loader.construct_mapping(node, deep)


_UniqueKeyLoader.add_constructor(yaml.resolver.BaseResolver.DEFAULT_MAPPING_TAG,
                                 _construct_unique_mapping)


def _check_keys(node: Any, where: str, required: tuple, optional: tuple = ()) -> dict:
    if not isinstance(node, dict):
        raise StudyError(f"{where}: expected a mapping, got {type(node).__name__}")
    allowed = required + optional
    for key in node:
        if key not in allowed:
            raise StudyError(f"{where}.{key}: unknown key '{key}'; expected one of: "
                             + ", ".join(allowed))
    for key in required:
        if node.get(key) is None:
            raise StudyError(f"{where}.{key}: missing (required)")
    return node


def _string(node: Any, where: str) -> str:
    if not isinstance(node, str) or not node.strip():
        raise StudyError(f"{where}: expected a non-empty string")
    return node.strip()


def _number(node: Any, where: str) -> float:
    if isinstance(node, bool) or not isinstance(node, (int, float)):
        raise StudyError(f"{where}: expected a number, got {node!r}")
    return float(node)


def _overrides(node: Any, where: str) -> dict:
    if node is None:
        return {}
    if not isinstance(node, dict):
        raise StudyError(f"{where}: expected a mapping of scene key paths to values")
    for key, value in node.items():
        if not isinstance(key, str) or value is None:
            raise StudyError(f"{where}.{key}: expected 'scene.key.path: value'")
    return dict(node)


def load_study(path: Path) -> Study:
    """Reads and validates a study file; raises StudyError naming the offending key."""
    path = Path(path)
    root = _read_yaml(path)
    try:
        return _parse_study(path, _with_runs_of(path, root))
    except StudyError as error:
        raise StudyError(f"{path}: {error}") from None


def _read_yaml(path: Path) -> Any:
    try:
        text = path.read_text()
    except OSError as error:
        raise StudyError(f"{path}: cannot read: {error.strerror}") from None
    try:
        return yaml.load(text, Loader=_UniqueKeyLoader)
    except yaml.YAMLError as error:
        raise StudyError(f"{path}: not valid YAML: {error}") from None


# What makes a study's runs. A study that compares another quantity of another study's runs names
# that study in `runs_of` and takes these from it, so the two cannot drift apart (and the run
# cache runs them once).
RUN_KEYS = ("scene", "overrides", "sweep", "ensemble", "repeat", "timeout")


def _with_runs_of(path: Path, root: Any) -> Any:
    """The study's keys with those of RUN_KEYS taken from the study its `runs_of` names."""
    if not isinstance(root, dict) or "runs_of" not in root:
        return root
    source = root["runs_of"]
    if not isinstance(source, str):
        raise StudyError(f"runs_of: expected the path of a study file, got {source!r}")
    for key in RUN_KEYS:
        if key in root:
            raise StudyError(f"{key}: comes from runs_of's study ({source}); a study that reads "
                             "another's runs does not set it")
    base_path = (path.parent / source).resolve()
    if not base_path.is_file():
        raise StudyError(f"runs_of: no such file: {base_path}")
    base = _read_yaml(base_path)
    if not isinstance(base, dict) or "scene" not in base:
        raise StudyError(f"runs_of: {base_path} is not a study with a scene")
    if "runs_of" in base:
        raise StudyError(f"runs_of: {base_path} reads another study's runs itself; name that one")
    merged = {key: value for key, value in root.items() if key != "runs_of"}
    merged.update({key: base[key] for key in RUN_KEYS if key in base})
    if isinstance(merged["scene"], str):  # relative to the file that names it
        merged["scene"] = str((base_path.parent / merged["scene"]).resolve())
    return merged


def _parse_study(path: Path, root: Any) -> Study:
    _check_keys(root, "study", ("title", "description", "scene", "sweep", "quantity",
                                "reference", "norm"),
                ("name", "overrides", "threshold", "repeat", "order", "comparisons", "timeout",
                 "ensemble"))
    scene = (path.parent / _string(root["scene"], "scene")).resolve()
    if not scene.is_file():
        raise StudyError(f"scene: no such file: {scene}")
    axes, explicit = _parse_sweep(root["sweep"])
    quantity = _parse_quantity(root["quantity"], scene)
    norm = root["norm"]
    if norm not in NORM_KINDS:
        raise StudyError(f"norm: unknown norm {norm!r}; expected one of: " + ", ".join(NORM_KINDS))
    if quantity.kind not in NORM_KINDS[norm]:
        raise StudyError(f"norm: '{norm}' does not apply to a quantity of kind '{quantity.kind}' "
                         f"(it applies to: {', '.join(NORM_KINDS[norm])})")
    threshold = root.get("threshold")
    if norm == "arrival_time":
        if threshold is None:
            raise StudyError("threshold: missing (required by norm arrival_time)")
        threshold = _number(threshold, "threshold")
    elif threshold is not None:
        raise StudyError("threshold: only used with norm arrival_time")
    reference = _parse_reference(root["reference"], path.parent, quantity, norm)
    repeat = root.get("repeat", 1)
    if not isinstance(repeat, int) or isinstance(repeat, bool) or repeat < 1:
        raise StudyError(f"repeat: expected an integer >= 1, got {repeat!r}")
    order = root.get("order")
    if order is not None and (not isinstance(order, int) or isinstance(order, bool)):
        raise StudyError(f"order: expected an integer, got {order!r}")
    comparisons = _parse_comparisons(root.get("comparisons"), path.parent, quantity)
    timeout = root.get("timeout")
    if timeout is not None:
        timeout = _number(timeout, "timeout")
        if not timeout > 0:
            raise StudyError(f"timeout: expected seconds > 0, got {timeout!r}")
    overrides = _overrides(root.get("overrides"), "overrides")
    ensemble = _parse_ensemble(root.get("ensemble"), quantity, norm)
    fixed = [a.key for a in axes] + [k for _, extra in explicit for k in extra] + list(overrides)
    if ensemble is not None and ensemble.key in fixed:
        raise StudyError(f"ensemble.key: '{ensemble.key}' is also set by the sweep or the "
                         "overrides; an ensemble varies a setting nothing else fixes")
    return Study(path=path.resolve(), name=_string(root.get("name", path.stem), "name"),
                 title=_string(root["title"], "title"),
                 description=_string(root["description"], "description"), scene=scene,
                 overrides=overrides, axes=axes,
                 explicit_points=explicit, quantity=quantity, reference=reference, norm=norm,
                 threshold=threshold, repeat=repeat, order=order, comparisons=comparisons,
                 timeout=timeout, ensemble=ensemble)


def _parse_ensemble(node: Any, quantity: Quantity, norm: str) -> Optional[Axis]:
    if node is None:
        return None
    _check_keys(node, "ensemble", ("key", "values"), ("label",))
    key = _string(node["key"], "ensemble.key")
    values = node["values"]
    if not isinstance(values, list) or len(values) < 2:
        raise StudyError("ensemble.values: expected a list of two or more values")
    if len({format_value(v) for v in values}) != len(values):
        raise StudyError("ensemble.values: a value is listed twice (it would count twice)")
    if quantity.kind not in ("final",) + SCALAR_KINDS or norm not in ("max", "relative_at_point"):
        raise StudyError(f"ensemble: needs a single-valued quantity (kind final or one of "
                         f"{', '.join(SCALAR_KINDS)}) and norm max or relative_at_point")
    return Axis(key, values, _string(node.get("label", key.rsplit(".", 1)[-1]), "ensemble.label"))


def _parse_comparisons(node: Any, base: Path, quantity: Quantity) -> tuple:
    """comparisons: [{label, source, csv, columns: [particles column, value column]}, ...]"""
    if node is None:
        return ()
    if quantity.kind != "final":
        raise StudyError("comparisons: only for a final value (drawn against particle count)")
    if not isinstance(node, list):
        raise StudyError("comparisons: expected a list")
    comparisons = []
    for i, item in enumerate(node):
        where = f"comparisons[{i}]"
        _check_keys(item, where, ("label", "source", "csv", "columns"))
        columns = item["columns"]
        if not isinstance(columns, list) or len(columns) != 2:
            raise StudyError(f"{where}.columns: expected [particles column, value column]")
        particles, values = read_reference_csv(
            (base / _string(item["csv"], f"{where}.csv")).resolve(), columns)
        comparisons.append(Comparison(_string(item["label"], f"{where}.label"),
                                      _string(item["source"], f"{where}.source"),
                                      particles, values))
    return tuple(comparisons)


def _parse_sweep(node: Any) -> tuple:
    _check_keys(node, "sweep", (), ("axes", "points"))
    axes, explicit = [], []
    for i, axis in enumerate(node.get("axes") or []):
        where = f"sweep.axes[{i}]"
        _check_keys(axis, where, ("key", "values"), ("label",))
        key = _string(axis["key"], f"{where}.key")
        values = axis["values"]
        if not isinstance(values, list) or not values:
            raise StudyError(f"{where}.values: expected a non-empty list")
        label = _string(axis.get("label", key.rsplit(".", 1)[-1]), f"{where}.label")
        axes.append(Axis(key, values, label))
    for i, point in enumerate(node.get("points") or []):
        where = f"sweep.points[{i}]"
        _check_keys(point, where, ("label", "overrides"))
        explicit.append((_string(point["label"], f"{where}.label"),
                         _overrides(point["overrides"], f"{where}.overrides")))
    if not axes and not explicit:
        raise StudyError("sweep: needs 'axes' or 'points' (or both)")
    labels = [axis.label for axis in axes]
    if len(set(labels)) != len(labels):
        raise StudyError("sweep.axes: two axes share a label; give them distinct 'label's")
    return axes, explicit


def _scene_probes(scene: Path) -> dict:
    """The scene's probes by name, so that a misspelt probe is caught before anything runs."""
    try:
        root = yaml.safe_load(scene.read_text()) or {}
    except (OSError, yaml.YAMLError) as error:
        raise StudyError(f"scene: cannot read {scene}: {error}") from None
    probes = (root.get("probes") or []) if isinstance(root, dict) else []
    return {p.get("name"): p for p in probes if isinstance(p, dict)}


def _parse_quantity(node: Any, scene: Path) -> Quantity:
    _check_keys(node, "quantity", ("probe", "kind"),
                ("field", "column", "columns", "combine", "label", "time", "window", "smooth",
                 "scale"))
    probe = _string(node["probe"], "quantity.probe")
    kind = node["kind"]
    if kind not in KINDS:
        raise StudyError(f"quantity.kind: unknown kind {kind!r}; expected one of: "
                         + ", ".join(KINDS))
    probes = _scene_probes(scene)
    if probe not in probes:
        raise StudyError(f"quantity.probe: the scene has no probe '{probe}' (it has: "
                         + ", ".join(str(name) for name in probes) + ")")
    spec = probes[probe]
    if kind == "profile":
        if "line" not in spec and "points" not in spec:
            raise StudyError(f"quantity.kind: a profile needs a line or points probe; "
                             f"'{probe}' is neither")
        if node.get("column") is not None:
            raise StudyError("quantity.column: not used by a profile (it takes every column "
                             "of 'field')")
    columns, combine, combine_code = _parse_combination(node, kind)
    if kind != "profile":
        if node.get("column") is None and not columns:
            raise StudyError(f"quantity.column: missing (required by kind {kind}), e.g. "
                             "concentration@p0"
                             + (" (or 'columns' with 'combine')" if kind == "final" else ""))
        if node.get("time") is not None:
            raise StudyError("quantity.time: only used by a profile")
    when = node.get("time", "last")
    if when != "last":
        when = _number(when, "quantity.time")
    field_name = node.get("field")
    if field_name is not None:
        field_name = _string(field_name, "quantity.field")
    column = node.get("column")
    if column is not None:
        column = _string(column, "quantity.column")
    label = node.get("label")
    if label is not None:
        label = _string(label, "quantity.label")
    window, smooth, scale = _parse_series_options(node, kind)
    return Quantity(probe, kind, field_name, column, when, columns, combine, combine_code, label,
                    window, smooth, scale)


def _parse_series_options(node: dict, kind: str) -> tuple:
    """(window, smooth, scale) of a time-series quantity."""
    series_kinds = ("time_series",) + SCALAR_KINDS
    for key in ("window", "smooth"):
        if node.get(key) is not None and kind not in series_kinds:
            raise StudyError(f"quantity.{key}: only used by a time series ("
                             + ", ".join(series_kinds) + ")")
    window = node.get("window")
    if window is not None:
        if not isinstance(window, list) or len(window) != 2:
            raise StudyError("quantity.window: expected [t0, t1]")
        window = (_number(window[0], "quantity.window[0]"), _number(window[1], "quantity.window[1]"))
        if not window[0] < window[1]:
            raise StudyError("quantity.window: expected t0 < t1")
    smooth = node.get("smooth")
    if kind == "noise" and smooth is None:
        raise StudyError("quantity.smooth: missing (required by kind noise: the width of the "
                         "moving mean the noise is measured around)")
    if smooth is not None:
        smooth = _number(smooth, "quantity.smooth")
        if not smooth > 0:
            raise StudyError("quantity.smooth: expected a positive time")
    scale = node.get("scale", 1.0)
    if node.get("scale") is not None and (kind not in series_kinds and kind != "final"
                                          or node.get("combine") is not None):
        raise StudyError("quantity.scale: only used by a time series or a single final column")
    scale = _number(scale, "quantity.scale")
    if scale == 0:
        raise StudyError("quantity.scale: expected a nonzero factor")
    return window, smooth, scale


def _parse_combination(node: dict, kind: str) -> tuple:
    """(columns, combine text, compiled combine) of a derived final value, or ((), None, None)."""
    columns, combine = node.get("columns"), node.get("combine")
    if columns is None and combine is None:
        return (), None, None
    if kind != "final":
        given = "columns" if columns is not None else "combine"
        raise StudyError(f"quantity.{given}: only used by kind final (a value derived from "
                         "several final columns)")
    if node.get("column") is not None:
        raise StudyError("quantity.column: give either 'column' or 'columns' with 'combine', "
                         "not both")
    if columns is None:
        raise StudyError("quantity.columns: missing (required by 'combine'), e.g. "
                         '["activation_time@p0", "activation_time@p1"]')
    if combine is None:
        raise StudyError("quantity.combine: missing (required by 'columns'), an expression of "
                         "c0, c1, ... e.g. 2 / (c1 - c0)")
    if not isinstance(columns, list) or not columns:
        raise StudyError("quantity.columns: expected a non-empty list of probe columns")
    names = tuple(_string(c, f"quantity.columns[{i}]") for i, c in enumerate(columns))
    if len(set(names)) != len(names):
        raise StudyError("quantity.columns: a column is listed twice")
    text = (str(combine) if isinstance(combine, (int, float)) and not isinstance(combine, bool)
            else _string(combine, "quantity.combine"))
    known = {f"c{i}" for i in range(len(names))}
    code = compile_expression(text, "quantity.combine", known)
    used = {n.id for n in ast.walk(ast.parse(text.strip(), mode="eval"))
            if isinstance(n, ast.Name)}
    unused = sorted(known - used, key=lambda n: int(n[1:]))
    if unused:
        raise StudyError(f"quantity.combine: does not use {', '.join(unused)} (a listed column "
                         "that the expression ignores is probably a mistake)")
    return names, text, code


def _parse_reference(node: Any, base: Path, quantity: Quantity, norm: str) -> Reference:
    if not isinstance(node, dict):
        raise StudyError("reference: expected a mapping")
    if node.get("source") is None:
        raise StudyError("reference.source: missing (required: where the reference comes from)")
    source = _string(node["source"], "reference.source")
    given = [kind for kind in ("expression", "csv", "value") if node.get(kind) is not None]
    if len(given) != 1:
        raise StudyError("reference: give exactly one of 'expression', 'csv', 'value'")
    kind = given[0]
    if kind == "expression":
        _check_keys(node, "reference", ("source", "expression"), ("definitions",))
        definitions = _compile_definitions(node.get("definitions"))
        known = set(VARIABLES) | {name for name, _, _ in definitions}
        text = _string(node["expression"], "reference.expression")
        code = compile_expression(text, "reference.expression", known)
        return Reference(kind, source, expression=text, definitions=definitions, code=code)
    if kind == "value":
        _check_keys(node, "reference", ("source", "value"), ("band",))
        return Reference(kind, source, value=_number(node["value"], "reference.value"),
                         band=_parse_band(node.get("band")))
    _check_keys(node, "reference", ("source", "csv", "columns"), ("along",))
    along = node.get("along", "time")
    if along not in CSV_ALONG:
        raise StudyError(f"reference.along: expected one of: {', '.join(CSV_ALONG)}")
    if norm == "arrival_time" and along != "time":
        raise StudyError("reference.along: an arrival time needs a reference along time")
    columns = node["columns"]
    if not isinstance(columns, list) or len(columns) != 2:
        raise StudyError("reference.columns: expected [abscissa column, value column]")
    csv_file = (base / _string(node["csv"], "reference.csv")).resolve()
    abscissa, ordinate = read_reference_csv(csv_file, columns)
    return Reference(kind, source, csv_file=csv_file, abscissa=abscissa, ordinate=ordinate,
                     along=along)


def _parse_band(node: Any) -> Optional[tuple]:
    """reference.band: {low, high, label}, the spread of the solvers the value comes from."""
    if node is None:
        return None
    _check_keys(node, "reference.band", ("low", "high", "label"))
    low, high = _number(node["low"], "reference.band.low"), _number(node["high"], "reference.band.high")
    if not low < high:
        raise StudyError(f"reference.band: low ({low}) must be below high ({high})")
    return (low, high, _string(node["label"], "reference.band.label"))


def _compile_definitions(node: Any) -> tuple:
    if node is None:
        return ()
    if not isinstance(node, dict):
        raise StudyError("reference.definitions: expected a mapping 'name: expression'")
    known = set(VARIABLES)
    compiled = []
    for name, text in node.items():
        where = f"reference.definitions.{name}"
        if not isinstance(name, str) or not name.isidentifier():
            raise StudyError(f"{where}: not a valid name")
        if name in VARIABLES or name in expression_functions():
            raise StudyError(f"{where}: '{name}' is a variable or function name already")
        text = str(text) if isinstance(text, (int, float)) else _string(text, where)
        compiled.append((name, text, compile_expression(text, where, known)))
        known.add(name)
    return tuple(compiled)


def read_reference_csv(path: Path, columns: list) -> tuple:
    """Two columns of a CSV file ('#' comment lines, one header line), sorted by the first."""
    try:
        lines = [line for line in path.read_text().splitlines()
                 if line.strip() and not line.lstrip().startswith("#")]
    except OSError as error:
        raise StudyError(f"reference.csv: cannot read {path}: {error.strerror}") from None
    rows = list(csv.reader(lines))
    if len(rows) < 3:
        raise StudyError(f"reference.csv: {path} needs a header line and at least two rows")
    header = [name.strip() for name in rows[0]]
    indices = []
    for column in columns:
        if isinstance(column, int) and not isinstance(column, bool) and 0 <= column < len(header):
            indices.append(column)
        elif column in header:
            indices.append(header.index(column))
        else:
            raise StudyError(f"reference.columns: no column {column!r} in {path} "
                             f"(header: {', '.join(header)})")
    try:
        data = np.array([[float(row[i]) for i in indices] for row in rows[1:]])
    except (ValueError, IndexError):
        raise StudyError(f"reference.csv: {path}: non-numeric or missing values in columns "
                         f"{columns}") from None
    data = data[np.argsort(data[:, 0], kind="stable")]
    return data[:, 0], data[:, 1]


# ---- Reference expressions --------------------------------------------------------------------

def _heaviside(value, at_zero=1.0):
    return np.heaviside(value, at_zero)


def expression_functions() -> dict:
    """The whole namespace an expression may use, besides x, y, z, t, distance and definitions."""
    erf = np.vectorize(math.erf, otypes=[float])
    erfc = np.vectorize(math.erfc, otypes=[float])
    return {
        "pi": math.pi, "e": math.e, "inf": math.inf,
        "erf": erf, "erfc": erfc, "exp": np.exp, "log": np.log, "log10": np.log10,
        "sqrt": np.sqrt, "sin": np.sin, "cos": np.cos, "tan": np.tan, "asin": np.arcsin,
        "acos": np.arccos, "atan": np.arctan, "atan2": np.arctan2, "sinh": np.sinh,
        "cosh": np.cosh, "tanh": np.tanh, "abs": np.abs, "sign": np.sign, "floor": np.floor,
        "ceil": np.ceil, "minimum": np.minimum, "maximum": np.maximum, "where": np.where,
        "hypot": np.hypot, "heaviside": _heaviside,
    }


# Only arithmetic, comparisons, numbers, names and calls of the namespace's functions: no
# attributes, subscripts or literals of other types, so eval() cannot reach anything else.
_ALLOWED_NODES = (ast.Expression, ast.BinOp, ast.UnaryOp, ast.Call, ast.Name, ast.Load,
                  ast.Constant, ast.Compare, ast.Add, ast.Sub, ast.Mult, ast.Div, ast.Pow,
                  ast.Mod, ast.USub, ast.UAdd, ast.Lt, ast.LtE, ast.Gt, ast.GtE, ast.Eq,
                  ast.NotEq)


def compile_expression(text: str, where: str, known: set) -> Any:
    """Compiles a reference expression after checking it uses only the restricted namespace."""
    try:
        tree = ast.parse(text.strip(), mode="eval")
    except SyntaxError as error:
        raise StudyError(f"{where}: syntax error in {text.strip()!r}: {error.msg}") from None
    functions = expression_functions()
    for node in ast.walk(tree):
        if isinstance(node, ast.BitXor):
            raise StudyError(f"{where}: '^' is not a power here; write a**b")
        if not isinstance(node, _ALLOWED_NODES):
            raise StudyError(f"{where}: '{type(node).__name__}' is not allowed in an expression")
        if isinstance(node, ast.Constant) and not isinstance(node.value, (int, float)):
            raise StudyError(f"{where}: only numbers may appear as constants")
        if isinstance(node, ast.Call) and (not isinstance(node.func, ast.Name)
                                           or node.func.id not in functions or node.keywords):
            name = node.func.id if isinstance(node.func, ast.Name) else "this call"
            raise StudyError(f"{where}: unknown function '{name}'; known functions: "
                             + ", ".join(sorted(k for k, v in functions.items() if callable(v)))
                             + " (positional arguments only)")
        if isinstance(node, ast.Name) and node.id not in known and node.id not in functions:
            raise StudyError(f"{where}: unknown name '{node.id}' (variables: "
                             + ", ".join(sorted(known)) + ")")
    return compile(tree, where, "eval")


def evaluate_reference(reference: Reference, variables: dict) -> np.ndarray:
    """The reference at the sample's x, y, z, t, distance (arrays of one shape)."""
    shape = np.shape(variables["t"])
    if reference.kind == "value":
        return np.full(shape, reference.value)
    if reference.kind == "csv":
        where = np.asarray(variables["t" if reference.along == "time" else reference.along],
                           dtype=float)
        # Outside the reference's range there is nothing to compare with: NaN, excluded later.
        return np.interp(where, reference.abscissa, reference.ordinate, left=np.nan,
                         right=np.nan)
    namespace = dict(expression_functions())
    namespace.update({name: np.asarray(value, dtype=float) for name, value in variables.items()})
    with np.errstate(all="ignore"):
        for name, _, code in reference.definitions:
            namespace[name] = eval(code, {"__builtins__": {}}, namespace)  # noqa: S307
        result = eval(reference.code, {"__builtins__": {}}, namespace)  # noqa: S307
    return np.broadcast_to(np.asarray(result, dtype=float), shape).copy()


# ---- Running points ---------------------------------------------------------------------------

@dataclass
class Sample:
    """The simulated quantity of one point, with where (and when) each value was taken."""
    values: np.ndarray
    variables: dict  # x, y, z, t, distance: arrays shaped like values
    abscissa: np.ndarray  # for plots: the coordinate along the profile, or time
    abscissa_name: str
    field_name: str


@dataclass
class PointResult:
    point: Point
    status: str = "ok"  # ok, failed or diverged
    message: str = ""
    error: float = math.nan
    wall_seconds: float = math.nan
    cpu_seconds: float = math.nan
    particles: float = math.nan
    steps: float = math.nan
    particle_steps_per_second: float = math.nan
    threads: float = math.nan
    sample: Optional[Sample] = None
    reference_values: Optional[np.ndarray] = None
    arrivals: Optional[tuple] = None  # (simulated, reference) arrival times
    members: tuple = ()  # an ensemble point's member values (the point's value is their mean)
    reused: bool = False  # taken from the run cache, not run by this invocation


def format_value(value: Any) -> str:
    """A scene value as --set and labels want it (YAML spelling: true/false, [a, b])."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return f"{value:g}" if float(f"{value:g}") == value else repr(value)
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(format_value(v) for v in value) + "]"
    return str(value)


def cosph_command(cosph: Path, scene: Path, overrides: dict, out_dir: Path,
                  action: str = "run") -> list:
    command = [str(cosph), action, str(scene)]
    for key, value in overrides.items():
        command += ["--set", f"{key}={format_value(value)}"]
    if action == "run":
        command += ["--output", str(out_dir), "--quiet"]
    return command


def check_first_point(study: Study, cosph: Path) -> None:
    """Validates the scene with the first point's overrides (`cosph check`), so that a misspelt
    sweep key stops the study at once instead of failing every point."""
    point = study.points()[0]
    if study.ensemble is not None:
        point = ensemble_members(study, point)[0]
    command = cosph_command(cosph, study.scene, point.overrides, Path("."), action="check")
    done = subprocess.run(command, capture_output=True, text=True, check=False)
    if done.returncode == 2:
        raise StudyError(f"{study.path}: the scene rejects the overrides of point "
                         f"'{point.label}': {first_line(done.stderr)}")


def first_line(text: str) -> str:
    for line in text.splitlines():
        if line.strip():
            return line.strip()
    return ""


def _referenced_files(scene: Path, overrides: dict) -> list:
    """Files the scene (or an override) names by a relative or absolute path: point clouds,
    fibre tables. Their bytes are part of a run's key."""
    text = scene.read_text() + " " + " ".join(str(v) for v in overrides.values())
    files = []
    for token in set(re.findall(r"[\w./-]+\.(?:csv|stl|txt|dat)\b", text)):
        path = (scene.parent / token) if not os.path.isabs(token) else Path(token)
        if path.is_file():
            files.append(path)
    return sorted(files)


def run_key(cosph: Path, scene: Path, overrides: dict, repeat: int) -> str:
    """What a run's outputs and timings depend on: the executable's bytes, the scene's text, the
    files it names, the overrides, the number of repeats (the fastest wall time is reported) and
    the machine (host name and CPU count), so that no timing comes from another machine."""
    digest = hashlib.sha256()
    with open(cosph, "rb") as stream:
        for block in iter(lambda: stream.read(1 << 20), b""):
            digest.update(block)
    digest.update(scene.read_bytes())
    for path in _referenced_files(scene, overrides):
        digest.update(str(path.name).encode())
        digest.update(path.read_bytes())
    digest.update(f"{platform.node()} {os.cpu_count()}".encode())
    digest.update(json.dumps([[k, format_value(v)] for k, v in overrides.items()]).encode())
    digest.update(str(repeat).encode())
    return digest.hexdigest()[:24]


def run_point(study: Study, point: Point, cosph: Path, out_dir: Path, repeat: int,
              timeout: float, cache: Optional[Path] = None, refresh: bool = False) -> PointResult:
    """Runs one point (the fastest of `repeat` runs counts) and compares it with the reference.
    With a cache directory, a run with the same executable, scene and overrides (from this or
    another study) is reused instead of repeated."""
    result = PointResult(point)
    best_summary = None
    if cache is not None:
        out_dir = cache / run_key(cosph, study.scene, point.overrides, repeat)
        if refresh and out_dir.exists():
            shutil.rmtree(out_dir)
        try:
            best_summary = json.loads((out_dir / "summary.json").read_text())
            result.message, result.reused = "reused", True
        except (OSError, ValueError):
            best_summary = None
    for _ in range(0 if best_summary is not None else repeat):
        if out_dir.exists():
            shutil.rmtree(out_dir)
        command = cosph_command(cosph, study.scene, point.overrides, out_dir)
        try:
            done = subprocess.run(command, capture_output=True, text=True, timeout=timeout,
                                  check=False)
        except subprocess.TimeoutExpired:
            result.status, result.message = "failed", f"timed out after {timeout:g} s"
            return result
        out_dir.mkdir(parents=True, exist_ok=True)
        (out_dir / "cosph.log").write_text(f"$ {' '.join(command)}\n{done.stdout}{done.stderr}")
        if done.returncode != 0:
            diverged = "health check failed" in done.stderr
            result.status = "diverged" if diverged else "failed"
            result.message = first_line(done.stderr) or f"exit code {done.returncode}"
            return result
        try:
            summary = json.loads((out_dir / "summary.json").read_text())
        except (OSError, ValueError) as error:
            result.status, result.message = "failed", f"summary.json: {error}"
            return result
        if best_summary is None or summary["wall_seconds"] < best_summary["wall_seconds"]:
            best_summary = summary
    if cache is not None and not result.reused:
        (out_dir / "summary.json").write_text(json.dumps(best_summary))
    for name in RESULT_COLUMNS:
        setattr(result, name, float(best_summary.get(name, math.nan)))
    try:
        compare(study, out_dir, result)
    except ComparisonError as error:
        result.status, result.message = "failed", f"comparison: {error}"
    return result


# ---- Probes and comparison --------------------------------------------------------------------

def read_probe(out_dir: Path, probe: str) -> tuple:
    """(times, column names, values[row, column], {label: (x, y, z)}) of a probe's CSV files."""
    path = out_dir / f"{probe}.csv"
    try:
        with open(path, newline="") as stream:
            rows = list(csv.reader(stream))
    except OSError:
        raise ComparisonError(f"no probe file {path.name}") from None
    if len(rows) < 2 or rows[0][0] != "time":
        raise ComparisonError(f"{path.name} has no data rows")
    data = np.array([[float(cell) for cell in row] for row in rows[1:] if row])
    coordinates = {}
    points_path = out_dir / f"{probe}.points.csv"
    if points_path.exists():
        with open(points_path, newline="") as stream:
            for row in list(csv.reader(stream))[1:]:
                if row:
                    xyz = [float(v) for v in row[1:]] + [0.0] * (4 - len(row))
                    coordinates[row[0]] = tuple(xyz[:3])
    return data[:, 0], rows[0][1:], data[:, 1:], coordinates


def _field_of(column: str) -> str:
    return column.split("@", 1)[0]


def extract_sample(quantity: Quantity, out_dir: Path) -> Sample:
    times, columns, values, coordinates = read_probe(out_dir, quantity.probe)
    if quantity.kind == "profile":
        return _profile_sample(quantity, times, columns, values, coordinates)
    if quantity.combine is not None:
        return _combined_sample(quantity, times, columns, values)
    if quantity.column not in columns:
        shown = ", ".join(columns[:6]) + (", ..." if len(columns) > 6 else "")
        raise ComparisonError(f"probe '{quantity.probe}' has no column '{quantity.column}' "
                              f"(it has {shown})")
    series = values[:, columns.index(quantity.column)] * quantity.scale
    times, series = _prepare_series(quantity, times, series)
    label = quantity.column.split("@", 1)[1] if "@" in quantity.column else None
    origin = next(iter(coordinates.values()), None)
    xyz = coordinates.get(label, (math.nan,) * 3)
    distance = math.dist(xyz, origin) if origin and label in coordinates else math.nan
    name = _field_of(quantity.column)
    if quantity.kind in SCALAR_KINDS:  # one value of the series, placed at its last time
        value = SERIES_VALUES[quantity.kind](quantity, times, series)
        times, series, name = times[-1:], np.array([value]), quantity.kind
    if quantity.kind == "final":
        times, series = times[-1:], series[-1:]
    variables = {"x": np.full_like(times, xyz[0]), "y": np.full_like(times, xyz[1]),
                 "z": np.full_like(times, xyz[2]), "t": times,
                 "distance": np.full_like(times, distance)}
    return Sample(series, variables, times, "time", name)


def dominant_oscillation(times, series) -> tuple:
    """(period, amplitude) of the strongest sinusoid in a series: resampled uniformly, mean
    removed, Hann-windowed and zero-padded 16x so that the peak's frequency is resolved to a
    small fraction of 1 / duration; the amplitude is 2 |X(f)| / sum(window), exact for a pure
    sinusoid at a bin."""
    if len(times) < 8:
        raise ComparisonError("an oscillation needs at least 8 samples (run longer)")
    n = len(times)
    uniform = np.linspace(times[0], times[-1], n)
    values = np.interp(uniform, times, series)
    values = values - values.mean()
    window = np.hanning(n)
    size = 16 * n
    spectrum = np.abs(np.fft.rfft(values * window, size))
    frequencies = np.fft.rfftfreq(size, uniform[1] - uniform[0])
    # Skip the bins of the window's main lobe at zero frequency (the remaining trend).
    lowest = 2.0 / (times[-1] - times[0])
    spectrum[frequencies < lowest] = 0.0
    peak = int(np.argmax(spectrum))
    if spectrum[peak] == 0.0:
        raise ComparisonError("no oscillation: the series is constant over the window")
    return 1.0 / frequencies[peak], 2.0 * spectrum[peak] / window.sum()


def cycle_statistics(times, series) -> tuple:
    """(mean, amplitude) as benchmarks of periodic flows state them: over each whole period of
    the dominant oscillation, counted from the window's start, (max + min) / 2 and
    (max - min) / 2; each averaged over the periods. Any interval one period long holds one
    maximum and one minimum, so the split needs no zero crossings, which harmonics and noise
    multiply."""
    # dominant_oscillation finds no period longer than half the window: two cycles at least.
    period, _ = dominant_oscillation(times, series)
    cycles = int(np.floor((times[-1] - times[0]) / period * (1.0 + 1e-9)))
    means, amplitudes = [], []
    for cycle in range(cycles):
        start = times[0] + cycle * period
        inside = (times >= start) & (times <= start + period)
        high, low = float(np.max(series[inside])), float(np.min(series[inside]))
        means.append(0.5 * (high + low))
        amplitudes.append(0.5 * (high - low))
    return float(np.mean(means)), float(np.mean(amplitudes))


def _prepare_series(quantity: Quantity, times, series) -> tuple:
    """The series smoothed by a centred moving average (over the whole record, so the window's
    edges are averaged with their neighbours), or for kind noise its difference from that
    average, then cut to the window."""
    if quantity.smooth is not None and len(times) > 2:
        dt = float(np.median(np.diff(times)))
        width = max(1, int(round(quantity.smooth / dt)))
        width += 1 - width % 2  # odd, so that the average is centred on each sample
        if width < 3 and quantity.kind == "noise":
            raise ComparisonError(f"smooth {quantity.smooth:g} spans fewer than three samples "
                                  f"(every {dt:g}): the noise around it would be the series' "
                                  "own spread")
        if width > 1:
            kernel = np.ones(width) / width
            padded = np.pad(series, (width // 2, width - 1 - width // 2), mode="edge")
            smoothed = np.convolve(padded, kernel, mode="valid")
            series = series - smoothed if quantity.kind == "noise" else smoothed
    if quantity.window is not None:
        inside = (times >= quantity.window[0]) & (times <= quantity.window[1])
        if not inside.any():
            raise ComparisonError(f"no samples of {quantity.column} in the window "
                                  f"[{quantity.window[0]:g}, {quantity.window[1]:g}] (run longer)")
        times, series = times[inside], series[inside]
    return times, series


def _mean_period(quantity: Quantity, times, series) -> float:
    """Mean period between the first and last downward zero crossings of the series."""
    down = np.nonzero((series[:-1] > 0.0) & (series[1:] <= 0.0))[0]
    if len(down) < 2:
        raise ComparisonError(f"{quantity.column} crosses zero downwards {len(down)} time(s); "
                              "a period needs two crossings (run longer)")
    t0, t1, v0, v1 = times[down], times[down + 1], series[down], series[down + 1]
    crossings = t0 + v0 * (t1 - t0) / (v0 - v1)
    return float((crossings[-1] - crossings[0]) / (len(crossings) - 1))


# The one value each scalar kind takes from a (windowed, smoothed, scaled) time series.
SERIES_VALUES = {
    "period": _mean_period,
    "mean": lambda q, t, s: float(np.mean(s)),
    "maximum": lambda q, t, s: float(np.max(s)),
    "amplitude": lambda q, t, s: 0.5 * float(np.max(s) - np.min(s)),
    "dominant_period": lambda q, t, s: dominant_oscillation(t, s)[0],
    "dominant_amplitude": lambda q, t, s: dominant_oscillation(t, s)[1],
    "cycle_mean": lambda q, t, s: cycle_statistics(t, s)[0],
    "cycle_amplitude": lambda q, t, s: cycle_statistics(t, s)[1],
    "noise": lambda q, t, s: float(np.std(s)),
}


def _combined_sample(quantity: Quantity, times, columns, values) -> Sample:
    """A final value derived from the last row of several columns (no single position: x, y, z
    and distance are NaN)."""
    missing = [c for c in quantity.columns if c not in columns]
    if missing:
        shown = ", ".join(columns[:6]) + (", ..." if len(columns) > 6 else "")
        raise ComparisonError(f"probe '{quantity.probe}' has no column '{missing[0]}' "
                              f"(it has {shown})")
    namespace = dict(expression_functions())
    namespace.update({f"c{i}": float(values[-1, columns.index(c)])
                      for i, c in enumerate(quantity.columns)})
    with np.errstate(all="ignore"):
        try:
            value = float(eval(quantity.combine_code, {"__builtins__": {}}, namespace))  # noqa: S307
        except ArithmeticError:  # 1 / 0 of Python floats, overflow
            value = math.nan
    if not math.isfinite(value):
        shown = ", ".join(f"c{i} = {namespace[f'c{i}']:g}" for i in range(len(quantity.columns)))
        raise ComparisonError(f"combine '{quantity.combine}' is not finite ({shown})")
    t = times[-1:]
    nan = np.full_like(t, math.nan)
    variables = {"x": nan, "y": nan.copy(), "z": nan.copy(), "t": t, "distance": nan.copy()}
    return Sample(np.array([value]), variables, t, "time", quantity_name(quantity))


def _profile_sample(quantity: Quantity, times, columns, values, coordinates) -> Sample:
    fields = sorted({_field_of(c) for c in columns})
    name = quantity.field or (fields[0] if len(fields) == 1 else None)
    if name is None or name not in fields:
        raise ComparisonError(f"quantity.field: choose one of {', '.join(fields)}")
    chosen = [i for i, c in enumerate(columns) if _field_of(c) == name]
    labels = [columns[i].split("@", 1)[1] for i in chosen]
    missing = [label for label in labels if label not in coordinates]
    if missing:
        raise ComparisonError(f"no coordinates for {missing[0]} in {quantity.probe}.points.csv")
    row = len(times) - 1 if quantity.time == "last" else int(np.argmin(abs(times - quantity.time)))
    xyz = np.array([coordinates[label] for label in labels])
    distance = np.linalg.norm(xyz - xyz[0], axis=1)
    variables = {"x": xyz[:, 0], "y": xyz[:, 1], "z": xyz[:, 2],
                 "t": np.full(len(labels), times[row]), "distance": distance}
    # Plot against the one coordinate that varies along the probe, else the distance along it.
    varying = [axis for i, axis in enumerate("xyz") if np.ptp(xyz[:, i]) > 0]
    axis = varying[0] if len(varying) == 1 else "distance"
    return Sample(values[row, chosen], variables, variables[axis], axis, name)


def arrival_time(times: np.ndarray, values: np.ndarray, threshold: float) -> float:
    """First upward crossing of the threshold, linear between rows; NaN when there is none."""
    below = values[:-1] < threshold
    reaches = values[1:] >= threshold
    crossings = np.nonzero(below & reaches)[0]
    if len(crossings) == 0:
        return math.nan
    i = crossings[0]
    t0, t1, v0, v1 = times[i], times[i + 1], values[i], values[i + 1]
    return float(t0 + (threshold - v0) * (t1 - t0) / (v1 - v0))


def _reference_arrival(study: Study, sample: Sample) -> float:
    reference = study.reference
    if reference.kind == "value":
        return reference.value  # the reference arrival time itself
    if reference.kind == "csv":
        return arrival_time(reference.abscissa, reference.ordinate, study.threshold)
    # An analytic reference is sampled much finer than the probe rows, so that its own
    # arrival time carries no interpolation error.
    t = np.linspace(sample.variables["t"][0], sample.variables["t"][-1], 4001)
    fine = {name: np.full_like(t, values[0]) for name, values in sample.variables.items()}
    fine["t"] = t
    return arrival_time(t, evaluate_reference(reference, fine), study.threshold)


def compare(study: Study, out_dir: Path, result: PointResult) -> None:
    """Fills result.sample, reference_values and error."""
    sample = extract_sample(study.quantity, out_dir)
    reference = evaluate_reference(study.reference, sample.variables)
    result.sample, result.reference_values = sample, reference
    if study.norm == "arrival_time":
        simulated = arrival_time(sample.abscissa, sample.values, study.threshold)
        expected = _reference_arrival(study, sample)
        result.arrivals = (simulated, expected)
        if math.isnan(simulated):
            raise ComparisonError(f"{study.quantity.column} never crosses {study.threshold:g}")
        if math.isnan(expected):
            raise ComparisonError(f"the reference never crosses {study.threshold:g}")
        result.error = abs(simulated - expected)
        return
    usable = np.isfinite(reference)
    if not usable.any():
        raise ComparisonError("the reference is not finite at any sample")
    if not usable.all():
        # Outside a CSV reference's range, or where an expression is singular (t = 0 of a
        # discontinuous start): nothing to compare with. Said in the table, not hidden.
        result.message = (f"{np.count_nonzero(~usable)} of {usable.size} samples without a "
                          "finite reference, left out")
    result.error = norm_error(study.norm, sample.values[usable], reference[usable])


def norm_error(norm: str, s: np.ndarray, r: np.ndarray) -> float:
    """The error of simulated values s against reference values r in a study's norm (all but
    arrival_time, which compares crossing times)."""
    if norm == "max":
        return float(np.max(np.abs(s - r)))
    if norm in ("l2_relative", "l2_time"):
        return float(np.sqrt(np.sum((s - r) ** 2) / np.sum(r ** 2)))
    if norm == "relative_at_point":
        return float(abs(s[-1] - r[-1]) / abs(r[-1]))
    raise ValueError(f"norm_error: no value norm {norm!r}")


def ensemble_members(study: Study, point: Point) -> list:
    """The point once per ensemble value (the same index: they are one point)."""
    axis = study.ensemble
    return [Point(point.index, f"{point.label}, {axis.label}={format_value(value)}",
                  {**point.overrides, axis.key: value}, point.axis_values)
            for value in axis.values]


def combine_members(study: Study, point: Point, members: list) -> PointResult:
    """An ensemble point: the mean of its members' values, compared with the reference as one
    run would be; its cost is the mean member's. A failed member fails the point."""
    result = PointResult(point)
    for j, member in enumerate(members):
        if member.status != "ok":
            result.status, result.message = member.status, f"member {j}: {member.message}"
            return result
    values = np.array([m.sample.values[-1] for m in members])
    mean = float(values.mean())
    first = members[0]
    references = np.array([m.reference_values[-1] for m in members])
    if not np.allclose(references, references[0], rtol=1e-12, atol=0.0):
        result.status = "failed"
        result.message = (f"the members' references differ ({references.min():.6g} to "
                          f"{references.max():.6g}): their mean has no one reference")
        return result
    result.sample = Sample(np.array([mean]), first.sample.variables, first.sample.abscissa,
                           first.sample.abscissa_name, first.sample.field_name)
    result.reference_values = first.reference_values
    result.error = norm_error(study.norm, result.sample.values, first.reference_values[-1:])
    result.members = tuple(float(v) for v in values)
    for name in RESULT_COLUMNS:
        setattr(result, name, float(np.mean([getattr(m, name) for m in members])))
    result.reused = all(m.reused for m in members)
    reused = sum(m.reused for m in members)
    result.message = (f"mean of {len(values)} runs ({study.ensemble.label}), values "
                      f"{values.min():.4g} to {values.max():.4g}"
                      + (f"; {reused} reused" if reused else ""))
    return result


# ---- Outputs ----------------------------------------------------------------------------------

RESULT_COLUMNS = ("wall_seconds", "cpu_seconds", "particles", "steps",
                  "particle_steps_per_second", "threads")


def write_results_csv(path: Path, study: Study, results: list) -> None:
    axis_labels = [axis.label for axis in study.axes]
    with open(path, "w", newline="") as stream:
        writer = csv.writer(stream)
        writer.writerow(["point", "label", *axis_labels, "overrides", "status", "message",
                         "error", *RESULT_COLUMNS, "members"])
        for r in results:
            overrides = "; ".join(f"{k}={format_value(v)}" for k, v in r.point.overrides.items())
            writer.writerow([r.point.index, r.point.label,
                             *(format_value(r.point.axis_values.get(a, "")) for a in axis_labels),
                             overrides, r.status, r.message, repr(r.error),
                             *(repr(getattr(r, name)) for name in RESULT_COLUMNS),
                             "; ".join(repr(v) for v in r.members)])


def best_result(results: list) -> Optional[PointResult]:
    usable = [r for r in results if r.status == "ok" and math.isfinite(r.error)]
    return min(usable, key=lambda r: r.error) if usable else None


def _cell(value: float, spec: str) -> str:
    if not math.isfinite(value):
        return "–"
    return format(int(value), "d") if spec == "d" else format(value, spec)


def markdown_table(results: list) -> str:
    """The results as a Markdown table; the best point's error is bold."""
    best = best_result(results)
    lines = ["| point | particles | steps | error | wall s | particle-steps/s | status |",
             "|---|---:|---:|---:|---:|---:|---|"]
    for r in results:
        error = _cell(r.error, ".3e")
        if r is best:
            error = f"**{error}**"
        status = r.status if not r.message else f"{r.status}: {r.message}".replace("|", "\\|")
        lines.append(f"| {r.point.label} | {_cell(r.particles, 'd')} | {_cell(r.steps, 'd')} | "
                     f"{error} | {_cell(r.wall_seconds, '.3f')} | "
                     f"{_cell(r.particle_steps_per_second, '.3g')} | {status} |")
    return "\n".join(lines) + "\n"


def write_table(path: Path, study: Study, results: list) -> None:
    caption = (f"{study.title}: {NORM_TEXT[study.norm]} of `{study.quantity.probe}` "
               f"({quantity_text(study.quantity)}) against the reference. Bold: lowest error.\n\n")
    path.write_text(caption + markdown_table(results))


def quantity_name(quantity: Quantity) -> str:
    """A short name of the quantity for axis labels."""
    if quantity.label:
        return quantity.label
    if quantity.combine is not None:
        return quantity.combine
    if quantity.column is not None:
        return _field_of(quantity.column)
    return quantity.field or "value"


def quantity_text(quantity: Quantity) -> str:
    if quantity.combine is not None:
        given = ", ".join(f"c{i} = {c}" for i, c in enumerate(quantity.columns))
        name = f"{quantity.label} = " if quantity.label else ""
        return f"{name}{quantity.combine} of the final values {given}"
    if quantity.kind == "profile":
        when = "last row" if quantity.time == "last" else f"row nearest t = {quantity.time:g}"
        return f"profile, {when}"
    name = f"{quantity.label}: " if quantity.label else ""
    extra = ""
    if quantity.scale != 1.0:
        extra += f" times {quantity.scale:g}"
    if quantity.smooth is not None:
        extra += f", moving average over {quantity.smooth:g}"
    if quantity.window is not None:
        extra += f", t in [{quantity.window[0]:g}, {quantity.window[1]:g}]"
    what = {"time_series": "time series of", "period": "mean period of the downward zero "
            "crossings of", "mean": "time mean of", "maximum": "largest value of",
            "amplitude": "half the peak-to-peak range of",
            "dominant_period": "period of the strongest sinusoid in",
            "dominant_amplitude": "amplitude of the strongest sinusoid in",
            "cycle_mean": "mean over its periods of (max + min) / 2 of",
            "cycle_amplitude": "mean over its periods of (max - min) / 2 of"}
    if quantity.kind in what:
        return f"{name}{what[quantity.kind]} {quantity.column}{extra}"
    return f"{name}final value of {quantity.column}"


@dataclass
class PlotGroup:
    name: str  # legend entry; empty for none
    members: list
    connect: bool  # the points form one convergence curve: join them
    label_axis: Optional[Axis]  # points are labelled by this axis's value, else by their label


def _plot_groups(study: Study, results: list) -> list:
    """Groups of results for the plots.

    With two axes the swept points are grouped by the axis that is not the resolution (the one
    whose key names a spacing, else the first), so that each group is one convergence curve.
    Explicit points are unrelated settings: a group of their own, not joined by lines."""
    swept = [r for r in results if r.point.axis_values]
    explicit = [r for r in results if not r.point.axis_values]
    groups = []
    if swept:
        resolution = next((a for a in study.axes if a.key.endswith("spacing")), study.axes[0])
        if len(study.axes) == 2:
            other = next(a for a in study.axes if a is not resolution)
            groups += [PlotGroup(f"{other.label} = {format_value(value)}",
                                 [r for r in swept if r.point.axis_values[other.label] == value],
                                 True, resolution)
                       for value in other.values]
        elif len(study.axes) == 1:
            groups.append(PlotGroup("sweep" if explicit else "", swept, True, resolution))
        else:
            groups.append(PlotGroup("sweep" if explicit else "", swept, False, None))
    if explicit:
        groups.append(PlotGroup("points" if swept else "", explicit, False, None))
    return groups


def _plot_error_cost(ax, study: Study, results: list) -> None:
    groups = _plot_groups(study, results)
    markers = "osD^v<>p"
    # Points of different groups at one resolution sit close together: each group's labels go
    # to another side of its points, in the group's colour, so that they overlap less.
    placements = [((6, 3), "left", "bottom"), ((6, -3), "left", "top"),
                  ((-6, 3), "right", "bottom"), ((-6, -3), "right", "top")]
    plotted = 0
    for g, group in enumerate(groups):
        ok = [r for r in group.members if r.status == "ok" and math.isfinite(r.error)
              and r.error > 0 and r.wall_seconds > 0]
        if not ok:
            continue
        plotted += len(ok)
        wall = [r.wall_seconds for r in ok]
        error = [r.error for r in ok]
        (line,) = ax.plot(wall, error, marker=markers[g % len(markers)], ms=6,
                          lw=1.2 if group.connect else 0, label=group.name or None, alpha=0.9)
        offset, ha, va = placements[g % len(placements)]
        for r in ok:
            text = (format_value(r.point.axis_values[group.label_axis.label])
                    if group.label_axis else r.point.label)
            ax.annotate(text, (r.wall_seconds, r.error), textcoords="offset points",
                        xytext=offset, ha=ha, va=va, fontsize=7, color=line.get_color())
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.margins(0.12)  # room for the labels of the outermost points
    ax.set_xlabel("wall time per run [s]")
    ax.set_ylabel(f"error ({study.norm})")
    title = "error versus cost"
    label_axes = {g.label_axis.label for g in groups if g.label_axis is not None}
    if label_axes:
        title += f" (labels: {', '.join(sorted(label_axes))})"
    ax.set_title(title, fontsize=10)
    ax.grid(True, which="both", alpha=0.25)
    if any(g.name for g in groups):
        ax.legend(fontsize=8, loc="best")
    failed = len(results) - plotted
    if failed:
        ax.text(0.02, 0.02, f"{failed} point(s) not shown (failed, diverged or zero error; "
                "see the table)", transform=ax.transAxes, fontsize=7, color="tab:red")


def _plot_best(ax, study: Study, results: list) -> None:
    best = best_result(results)
    if best is None or best.sample is None:
        ax.text(0.5, 0.5, "no point could be compared", ha="center", transform=ax.transAxes)
        ax.set_axis_off()
        return
    sample, reference = best.sample, best.reference_values
    if study.quantity.kind in ("final",) + SCALAR_KINDS:
        _plot_final_values(ax, study, results)
        return
    every = max(1, len(sample.values) // 40)
    ax.plot(sample.abscissa, reference, "k-", lw=1.6, label="reference")
    ax.plot(sample.abscissa, sample.values, "o--", ms=3.5, lw=0.9, color="tab:red",
            markevery=every, mfc="none", label=f"cosph, {best.point.label}")
    if best.arrivals is not None:
        ax.axhline(study.threshold, color="0.5", lw=0.8, ls=":", label="threshold")
        for t, style in zip(best.arrivals, ("tab:red", "k")):
            ax.axvline(t, color=style, lw=0.8, ls=":")
    when = ""
    if study.quantity.kind == "profile":
        when = f" at t = {sample.variables['t'][0]:g}"
    if best.arrivals is not None:
        when = f", arrival {best.arrivals[0]:.4g} (reference {best.arrivals[1]:.4g})"
    ax.set_xlabel("distance along the probe" if sample.abscissa_name == "distance"
                  else sample.abscissa_name)
    ax.set_ylabel(sample.field_name)
    ax.set_title(f"best point{when}: error {best.error:.3g}", fontsize=10)
    ax.grid(True, alpha=0.25)
    # At small errors the two curves are indistinguishable: the difference, on its own scale,
    # shows where the error is.
    twin = ax.twinx()
    twin.plot(sample.abscissa, sample.values - reference, color="tab:blue", lw=0.8, alpha=0.6,
              label="cosph - reference (right axis)")
    twin.set_ylabel("cosph - reference", color="tab:blue", fontsize=9)
    twin.tick_params(axis="y", labelcolor="tab:blue", labelsize=8)
    limit = np.nanmax(np.abs(sample.values - reference)) * 3.0
    if np.isfinite(limit) and limit > 0:
        twin.set_ylim(-limit, limit)  # zero in the middle, the curve in the middle third
    handles = ax.get_legend_handles_labels()
    extra = twin.get_legend_handles_labels()
    # Below the axes: inside, a long point label would cover the curves.
    ax.legend(handles[0] + extra[0], handles[1] + extra[1], fontsize=8, loc="upper center",
              bbox_to_anchor=(0.5, -0.13), ncol=3, frameon=False)


def _plot_final_values(ax, study: Study, results: list) -> None:
    """A single final value has no curve: every point's value against particle count."""
    reference = None
    for group in _plot_groups(study, results):
        ok = [r for r in group.members if r.status == "ok" and r.sample is not None]
        if ok:
            lines = ax.plot([r.particles for r in ok], [r.sample.values[-1] for r in ok],
                            "o-" if group.connect else "o",
                            label=f"cosph, {group.name}" if group.name else "cosph")
            spread = [r for r in ok if r.members]
            if spread:  # an ensemble: its members' range
                means = np.array([r.sample.values[-1] for r in spread])
                # The mean of equal members can round past them: no negative bar.
                low = np.maximum(means - np.array([min(r.members) for r in spread]), 0.0)
                high = np.maximum(np.array([max(r.members) for r in spread]) - means, 0.0)
                ax.errorbar([r.particles for r in spread], means, yerr=[low, high], fmt="none",
                            ecolor=lines[0].get_color(), capsize=4)
            reference = ok[0].reference_values[-1]
    ax.axhline(reference, color="k", lw=1.4, label="reference")
    if study.reference.band is not None:
        low, high, label = study.reference.band
        ax.axhspan(low, high, color="0.85", zorder=0, label=label)
    for comparison in study.comparisons:
        ax.plot(comparison.particles, comparison.values, "s--", mfc="none", label=comparison.label)
    ax.set_xscale("log")
    ax.set_xlabel("particles")
    ax.set_ylabel(ok[0].sample.field_name)
    ax.set_title("final value per point", fontsize=10)
    ax.grid(True, alpha=0.25)
    ax.legend(fontsize=8)


def write_plot(path: Path, study: Study, results: list) -> None:
    fig, (left, right) = plt.subplots(1, 2, figsize=(13, 5.2))
    try:
        _plot_error_cost(left, study, results)
        _plot_best(right, study, results)
        fig.suptitle(study.title, fontsize=12)
        fig.tight_layout()
        fig.savefig(path, dpi=110)
    finally:
        plt.close(fig)


# ---- Driver -----------------------------------------------------------------------------------

@dataclass
class StudyRun:
    study: Study
    results: list
    out_dir: Path
    repeat: int
    seconds: float
    files: dict = field(default_factory=dict)  # results, table, plot -> path


def run_study(study: Study, cosph: Path, out_dir: Path, repeat: int, timeout: float,
              log: Callable[[str], None] = print, cache: Optional[Path] = None,
              refresh: bool = False) -> StudyRun:
    """Runs every point of a study and writes results.csv, table.md and plot.png (OSError when
    one cannot be written)."""
    start = time.monotonic()
    points = study.points()
    results = []
    for point in points:
        point_dir = out_dir / "points" / str(point.index)
        if study.ensemble is None:
            result = run_point(study, point, cosph, point_dir, repeat, timeout, cache, refresh)
        else:
            members = [run_point(study, member, cosph, point_dir / str(j), repeat, timeout,
                                 cache, refresh)
                       for j, member in enumerate(ensemble_members(study, point))]
            result = combine_members(study, point, members)
        results.append(result)
        log(f"[{point.index + 1}/{len(points)}] {point.label}: {result.status}"
            + (f" ({result.message})" if result.message else "")
            + f"  error {result.error:.3e}  wall {result.wall_seconds:.3f} s")
    out_dir.mkdir(parents=True, exist_ok=True)
    files = {"results": out_dir / "results.csv", "table": out_dir / "table.md",
             "plot": out_dir / "plot.png"}
    write_results_csv(files["results"], study, results)
    write_table(files["table"], study, results)
    write_plot(files["plot"], study, results)
    return StudyRun(study, results, out_dir, repeat, time.monotonic() - start, files)


def parse_args(argv: Optional[list]) -> argparse.Namespace:
    parser = argparse.ArgumentParser(
        description="Run an accuracy-versus-cost study of cosph (see bench/studies/).")
    parser.add_argument("study", type=Path, help="study file (YAML)")
    parser.add_argument("--cosph", type=Path, default=DEFAULT_COSPH,
                        help="cosph executable (default: %(default)s)")
    parser.add_argument("--out", type=Path,
                        help="output directory (default: bench/results/<study name>/)")
    parser.add_argument("--repeat", type=int,
                        help="runs per point; the minimum wall time counts (default: the "
                             "study's 'repeat', else 1)")
    parser.add_argument("--timeout", type=float, default=None,
                        help="seconds before one run counts as failed (default: the study's "
                             "'timeout', else 900)")
    parser.add_argument("--cache", type=Path, metavar="DIR",
                        help="reuse runs with the same executable, scene and overrides from DIR "
                             "(and keep new ones there)")
    parser.add_argument("--expect-max-error", type=float, metavar="X",
                        help="exit 1 unless the best point's error is at most X (CI checks)")
    args = parser.parse_args(argv)
    if args.repeat is not None and args.repeat < 1:
        parser.error("--repeat must be >= 1")
    return args


def resolve_cosph(path: Path) -> Path:
    path = path.resolve()
    if not (path.is_file() and os.access(path, os.X_OK)):
        raise StudyError(f"no cosph executable at {path} (build it, or pass --cosph)")
    return path


def main(argv: Optional[list] = None) -> int:
    args = parse_args(argv)
    try:
        study = load_study(args.study)
        cosph = resolve_cosph(args.cosph)
        check_first_point(study, cosph)
    except StudyError as error:
        print(f"study.py: error: {error}", file=sys.stderr)
        return 2
    out_dir = (args.out or REPO_ROOT / "bench" / "results" / study.name).resolve()
    repeat = args.repeat or study.repeat
    print(f"study {study.name}: {len(study.points())} point(s), scene {study.scene}, "
          f"output {out_dir}")
    try:
        done = run_study(study, cosph, out_dir, repeat, args.timeout or study.timeout or 900.0,
                         cache=args.cache.resolve() if args.cache else None)
    except OSError as error:
        print(f"study.py: error: cannot write the results: {error}", file=sys.stderr)
        return 1
    best = best_result(done.results)
    failed = sum(r.status != "ok" for r in done.results)
    print(f"wrote {done.files['results']}, table.md, plot.png ({done.seconds:.1f} s, "
          f"{failed} point(s) not ok)")
    if best is not None:
        print(f"best point: {best.point.label}  error {best.error:.4e}")
    if args.expect_max_error is not None:
        if best is None or not best.error <= args.expect_max_error:
            found = "no point could be compared" if best is None else f"{best.error:.4e}"
            print(f"study.py: error: best error {found} exceeds --expect-max-error "
                  f"{args.expect_max_error:g}", file=sys.stderr)
            return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
