#!/usr/bin/env python3
"""Runs one example scene for a few steps (`cosph run --steps N`) and checks what the run wrote.

The run must exit 0, and its summary.json must be valid JSON that says what the scene asked for:
the step count (N, or fewer if the scene ends sooner), one entry per module with its type and particle count (the counts summing to
`particles`), every coupler with its children, the outputs (vtp unless the scene turns it off,
`probe:<name>` for every probe, in scene order), and for every probe the same values as the last
row of its CSV file. Every probe CSV has the header `time,...` and one row per sample, times
increasing. With --coarsen F every module's body spacing is multiplied by F (`--set`): the
sanitizer job runs the steady-state examples so, where one step is a whole load increment solved
to equilibrium. Usage: example_smoke.py COSPH SCENE.yaml OUTDIR [STEPS] [--coarsen F]
"""
import csv
import json
import math
import shutil
import subprocess
import sys
from pathlib import Path

import yaml


def fail(message):
    print(f"FAIL: {message}")
    sys.exit(1)


def check(condition, message):
    if not condition:
        fail(message)


def module_type(spec):
    types = [k for k in spec if k != "name"]
    check(len(types) == 1, f"module {spec.get('name')} has keys {types}")
    return types[0]


def check_probe_csv(path, summary_values, name):
    check(path.exists(), f"probe {name}: {path} missing")
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    check(len(rows) >= 2, f"probe {name}: {path} has no sample row")
    header = rows[0]
    check(header[0] == "time", f"probe {name}: header starts with {header[0]!r}")
    times = [float(r[0]) for r in rows[1:]]
    check(all(b > a for a, b in zip(times, times[1:])), f"probe {name}: times not increasing")
    for r in rows[1:]:
        check(len(r) == len(header), f"probe {name}: row of {len(r)} fields, header {len(header)}")
    last = dict(zip(header[1:], (float(v) for v in rows[-1][1:])))
    check(set(last) == set(summary_values),
          f"probe {name}: CSV columns {sorted(last)} vs summary {sorted(summary_values)}")
    for column, value in last.items():
        expected = summary_values[column]
        same = (value == expected) or (math.isnan(value) and expected is None)
        check(same, f"probe {name}.{column}: CSV {value} vs summary {expected}")


def spacing_overrides(scene, factor):
    """`--set` arguments multiplying every module's body spacing by factor."""
    overrides = []
    for index, spec in enumerate(scene["modules"]):
        kind = module_type(spec)
        spacing = ((spec[kind] or {}).get("body") or {}).get("spacing")
        if spacing is not None:  # float(): YAML reads 1e-3 (no point) as a string
            value = float(spacing) * factor
            overrides += ["--set", f"modules[{index}].{kind}.body.spacing={value!r}"]
    check(overrides, f"--coarsen {factor}: no module of the scene has a body spacing")
    return overrides


def main():
    arguments = sys.argv[1:]
    factor = None
    if "--coarsen" in arguments:
        at = arguments.index("--coarsen")
        check(at + 1 < len(arguments), "--coarsen needs a factor")
        factor = float(arguments[at + 1])
        del arguments[at:at + 2]
    cosph, scene_file, outdir = arguments[0], Path(arguments[1]), Path(arguments[2])
    steps = int(arguments[3]) if len(arguments) > 3 else 3
    scene = yaml.safe_load(scene_file.read_text())
    shutil.rmtree(outdir, ignore_errors=True)
    command = [cosph, "run", str(scene_file), "--steps", str(steps), "--output", str(outdir),
               "--quiet", "--threads", "2"]
    if factor is not None:
        command += spacing_overrides(scene, factor)
    result = subprocess.run(command, capture_output=True, text=True, timeout=600)
    check(result.returncode == 0,
          f"{' '.join(command)} exited {result.returncode}\n{result.stdout}\n{result.stderr}")

    summary = json.loads((outdir / "summary.json").read_text())

    # N steps, or fewer where the scene ends sooner (a module without a step limit ends in one).
    ended = summary["end_time"] == scene["end_time"]
    check(summary["steps"] == steps or (ended and 0 < summary["steps"] < steps),
          f"steps {summary['steps']}, asked {steps}, end_time {summary['end_time']}")
    check(0 < summary["end_time"] <= scene["end_time"], f"end_time {summary['end_time']}")
    check(summary["dimension"] == scene["dimension"], "dimension")
    check(summary["threads"] == 2, f"threads {summary['threads']}")
    check(summary["start_time"] == 0, f"start_time {summary['start_time']}")
    for key in ("wall_seconds", "cpu_seconds", "particle_steps_per_second", "peak_memory_bytes"):
        check(summary[key] > 0, f"{key} = {summary[key]}")

    modules = {m["name"]: m for m in summary["modules"]}
    check([m["name"] for m in summary["modules"]] == [m["name"] for m in scene["modules"]],
          f"modules {list(modules)}")
    for spec in scene["modules"]:
        entry = modules[spec["name"]]
        check(entry["type"] == module_type(spec), f"module {spec['name']} type {entry['type']}")
        check(entry["particles"] > 0, f"module {spec['name']} has no particles")
        check(entry["advance_seconds"] > 0, f"module {spec['name']} never advanced")
    check(sum(m["particles"] for m in summary["modules"]) == summary["particles"],
          "module particle counts do not sum to the total")

    couplers = scene.get("couplers", [])
    check([c["name"] for c in summary["couplers"]] == [c["name"] for c in couplers],
          f"couplers {summary['couplers']}")
    for spec, entry in zip(couplers, summary["couplers"]):
        ctype = module_type(spec)
        check(entry["type"] == ctype, f"coupler {spec['name']} type {entry['type']}")
        names = {m["name"] for m in scene["modules"]} | {c["name"] for c in couplers}
        roles = [v for v in spec[ctype].values() if isinstance(v, str) and v in names]
        check(sorted(entry["children"]) == sorted(roles),
              f"coupler {spec['name']} children {entry['children']}")
        check(0 <= entry["own_seconds"] <= entry["advance_seconds"],
              f"coupler {spec['name']} own time {entry['own_seconds']}")

    probes = scene.get("probes", [])
    vtp = scene.get("output", {}).get("vtp", True)
    expected_outputs = (["vtp"] if vtp else []) + [f"probe:{p['name']}" for p in probes]
    outputs = [o for o in summary["outputs"] if o != "checkpoint"]
    check(outputs == expected_outputs, f"outputs {summary['outputs']}, expected {expected_outputs}")
    check(sorted(summary["probes"]) == sorted(p["name"] for p in probes),
          f"summary probes {sorted(summary['probes'])}")
    for p in probes:
        check_probe_csv(outdir / f"{p['name']}.csv", summary["probes"][p["name"]], p["name"])
    if vtp:
        check(any(outdir.glob("*.pvd")), "vtp output asked for, no .pvd written")
    print(f"{scene_file.name}: {steps} steps, {summary['particles']} particles, "
          f"{len(probes)} probes, {summary['wall_seconds']:.2f} s")


if __name__ == "__main__":
    main()
