#!/usr/bin/python3
"""Regenerates docs/VALIDATION.md: runs the accuracy-versus-cost studies (bench/studies/*.yaml by
default, through bench/study.py) and writes one section per study, with the machine and the
commit the numbers come from, and copies each study's plot to docs/validation/<study>.png.

usage: /usr/bin/python3 bench/validation.py [--studies FILE ...] [--cosph PATH] [--repeat N]
                                           [--fresh]

Runs are kept in bench/results/runs/ under a key of the executable's bytes, the scene and the
overrides: studies that share a run (the cylinder's drag, lift and period) run it once, and a
regeneration with an unchanged executable reuses every run (--fresh reruns them and replaces
the kept runs). The key includes the host name and CPU count: timings never come from another
machine. A reused run is marked "reused" in the tables.

Exit codes: 0 written (points may have failed: the tables say so), 1 a file could not be
written, 2 an invalid study file or usage.
"""
import argparse
import datetime
import math
import os
import platform
import shutil
import subprocess
import sys
import time
from pathlib import Path
from typing import Optional

sys.path.insert(0, str(Path(__file__).resolve().parent))
import study as studies  # noqa: E402  (bench/ is not a package)

REPO_ROOT = studies.REPO_ROOT
DOCS_DIR = REPO_ROOT / "docs"


# ---- The machine and the source the numbers come from -----------------------------------------

def cpu_model() -> str:
    """The CPU model from /proc/cpuinfo, else lscpu (ARM kernels often lack 'model name')."""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    try:
        done = subprocess.run(["lscpu"], capture_output=True, text=True, check=False)
        for line in done.stdout.splitlines():
            if line.startswith("Model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown CPU"


def memory_gib() -> Optional[float]:
    try:
        for line in Path("/proc/meminfo").read_text().splitlines():
            if line.startswith("MemTotal:"):
                return int(line.split()[1]) / 2**20  # the kernel reports kiB
    except (OSError, ValueError, IndexError):
        pass
    return None


def load_average() -> str:
    try:
        return " / ".join(Path("/proc/loadavg").read_text().split()[:3]) + " (1 / 5 / 15 min)"
    except OSError:
        return "unknown"


def git_commit() -> str:
    """The commit, and whether tracked files differ from it (then the numbers are of a working
    tree that no commit reproduces exactly)."""
    def git(*args: str) -> str:
        done = subprocess.run(["git", "-C", str(REPO_ROOT), *args], capture_output=True,
                              text=True, check=False)
        return done.stdout.strip() if done.returncode == 0 else ""
    commit = git("rev-parse", "--short=12", "HEAD")
    if not commit:
        return "unknown (not a git checkout)"
    dirty = git("status", "--porcelain", "--untracked-files=no")
    return f"`{commit}`" + (" (with uncommitted changes)" if dirty else "")


def machine_lines() -> list:
    memory = memory_gib()
    memory_text = f", {memory:.1f} GiB memory" if memory else ""
    return [
        f"- **Date:** {datetime.datetime.now().astimezone():%Y-%m-%d %H:%M %Z}",
        f"- **Machine:** {cpu_model()}, {os.cpu_count()} logical cores{memory_text}; "
        f"{platform.system()} {platform.release()}",
        f"- **Commit:** {git_commit()}",
        f"- **Load average before the runs:** {load_average()} (other work on the machine "
        "inflates wall times; errors do not depend on it)",
    ]


# ---- Sections ---------------------------------------------------------------------------------

def _link(path: Path, doc_dir: Path) -> str:
    relative = os.path.relpath(path, doc_dir)
    shown = os.path.relpath(path, REPO_ROOT)
    return f"[`{shown}`]({relative})"


def setup_lines(study: studies.Study, run: studies.StudyRun, doc_dir: Path) -> list:
    lines = [study.description, "",
             f"- **Scene:** {_link(study.scene, doc_dir)}; study file "
             f"{_link(study.path, doc_dir)}"]
    if study.overrides:
        fixed = ", ".join(f"`{k}={studies.format_value(v)}`" for k, v in study.overrides.items())
        lines.append(f"- **Every point:** {fixed}")
    for axis in study.axes:
        values = ", ".join(studies.format_value(v) for v in axis.values)
        lines.append(f"- **Sweep {axis.label}:** `{axis.key}` over {values}")
    for label, overrides in study.explicit_points:
        extra = ", ".join(f"`{k}={studies.format_value(v)}`" for k, v in overrides.items())
        lines.append(f"- **Point {label}:** {extra}")
    threads = sorted({int(r.threads) for r in run.results if r.threads == r.threads})
    if study.ensemble is None:
        lines.append(f"- **Points:** {len(run.results)}, each run {run.repeat} time(s) on "
                     f"{'/'.join(map(str, threads)) or '?'} thread(s); the table gives the "
                     "fastest run's wall time")
    else:
        axis = study.ensemble
        values = ", ".join(studies.format_value(v) for v in axis.values)
        lines.append(f"- **Ensemble:** each point is the mean of {len(axis.values)} runs, "
                     f"`{axis.key}` = {values}; the table gives the members' range and their "
                     f"mean wall time, each member run {run.repeat} time(s) (the fastest "
                     f"counts) on {'/'.join(map(str, threads)) or '?'} thread(s)")
    return lines


def reference_lines(study: studies.Study, doc_dir: Path) -> list:
    reference = study.reference
    lines = [f"Compared quantity: `{study.quantity.probe}` probe, "
             f"{studies.quantity_text(study.quantity)}. Norm: **{study.norm}**, the "
             f"{studies.NORM_TEXT[study.norm]}"
             + (f", threshold {study.threshold:g}" if study.threshold is not None else "") + ".",
             ""]
    if reference.kind == "expression":
        lines.append("Reference (analytic, of x, y, z, t):")
        lines.append("")
        lines.append("```python")
        lines += [f"{name} = {text}" for name, text, _ in reference.definitions]
        lines.append(reference.expression)
        lines.append("```")
    elif reference.kind == "csv":
        lines.append(f"Reference (data): {_link(reference.csv_file, doc_dir)}, interpolated "
                     f"along {reference.along}.")
    else:
        lines.append(f"Reference (a number): {reference.value:.10g}.")
        if reference.band is not None:
            low, high, label = reference.band
            lines.append(f"Band in the plot: {label}, {low:.10g} to {high:.10g}.")
    lines += ["", f"Source: {reference.source}."]
    for comparison in study.comparisons:
        values = ", ".join(f"{v:.6g} at {p:.0f}" for p, v in
                           zip(comparison.particles, comparison.values))
        lines += ["", f"Beside it in the plot: {comparison.label} ({values} particles). "
                  f"Source: {comparison.source}."]
    return lines


def study_section(number: int, run: studies.StudyRun, doc_dir: Path, image: Path) -> list:
    study = run.study
    lines = [f"## {number}. {study.title}", "", "### Setup", ""]
    lines += setup_lines(study, run, doc_dir)
    lines += ["", "### Reference", ""]
    lines += reference_lines(study, doc_dir)
    right = ("every point's value against its particle count, with the reference"
             if study.quantity.kind in ("final",) + studies.SCALAR_KINDS
             else "the reference over the simulated curve of the best point")
    lines += ["", "### Results", "",
              f"Bold: the lowest error. Study run time {run.seconds:.1f} s. "
              f"Left: error against wall time per run; right: {right}.", ""]
    lines.append(studies.markdown_table(run.results).rstrip("\n"))
    lines += ["", f"![{study.title}]({os.path.relpath(image, doc_dir)})", ""]
    return lines


def observed_order(study: studies.Study, results: list, best) -> str:
    """log(e_coarse / e_fine) / log(dp_coarse / dp_fine) over the two finest points that share
    the best point's other settings: the convergence rate the study actually shows."""
    spacing = next((a for a in study.axes if a.key.endswith("spacing")), None)
    if best is None or spacing is None:
        return "–"
    if spacing.label not in best.point.axis_values:
        return "–"  # the best point is an explicit point outside the sweep
    same = [r for r in results if r.status == "ok" and math.isfinite(r.error) and r.error > 0
            and spacing.label in r.point.axis_values  # explicit points have no axis values
            and all(v == best.point.axis_values.get(k) for k, v in r.point.axis_values.items()
                    if k != spacing.label)]
    same.sort(key=lambda r: r.point.axis_values[spacing.label])
    if len(same) < 2:
        return "–"
    fine, coarse = same[0], same[1]
    ratio = coarse.point.axis_values[spacing.label] / fine.point.axis_values[spacing.label]
    return f"{math.log(coarse.error / fine.error) / math.log(ratio):.2f}"


def summary_lines(runs: list) -> list:
    """One row per study: its best point and the observed order of convergence."""
    lines = ["| study | norm | best point | particles | error | wall s | observed order |",
             "|---|---|---|---:|---:|---:|---:|"]
    for run in runs:
        best = studies.best_result(run.results)
        cells = ("–",) * 4 if best is None else (
            best.point.label, f"{best.particles:.0f}", f"{best.error:.3e}",
            f"{best.wall_seconds:.3f}")
        lines.append(f"| {run.study.title} | {run.study.norm} | " + " | ".join(cells) + " | "
                     + observed_order(run.study, run.results, best) + " |")
    lines += ["", "Observed order: log(e_coarse / e_fine) / log(dp_coarse / dp_fine) between "
              "the two finest spacings at the best point's other settings."]
    return lines


def write_document(path: Path, runs: list, machine: list, seconds: float) -> None:
    doc_dir = path.parent
    image_dir = doc_dir / "validation"
    image_dir.mkdir(parents=True, exist_ok=True)
    lines = ["# Validation: accuracy versus cost", "",
             "Generated by `/usr/bin/python3 bench/validation.py` (do not edit by hand: "
             "regenerate). Each study runs one scene over a sweep of settings with "
             "`bench/study.py` and compares a probe with a reference; every number below comes "
             "from this regeneration.", ""]
    lines += machine
    points = [r for run in runs for r in run.results]
    reused = sum(r.reused for r in points)
    lines += [f"- **Run time:** {seconds:.1f} s for {len(runs)} studies"
              + (f"; {reused} of {len(points)} points reused runs kept in bench/results/runs/ "
                 "(the same executable, scene, files, overrides and machine; their wall times "
                 "are those of the original runs, made under the load of their own time)"
                 if reused else ""), "",
              "## Summary", ""]
    lines += summary_lines(runs)
    lines.append("")
    for number, run in enumerate(runs, start=1):
        image = image_dir / f"{run.study.name}.png"
        shutil.copyfile(run.files["plot"], image)
        lines += study_section(number, run, doc_dir, image)
    path.write_text("\n".join(lines))


# ---- Driver -----------------------------------------------------------------------------------

def parse_args(argv: Optional[list]) -> argparse.Namespace:
    parser = argparse.ArgumentParser(
        description="Run the accuracy-versus-cost studies and regenerate docs/VALIDATION.md.")
    parser.add_argument("--studies", type=Path, nargs="+",
                        help="study files (default: bench/studies/*.yaml, in their 'order')")
    parser.add_argument("--cosph", type=Path, default=studies.DEFAULT_COSPH,
                        help="cosph executable (default: %(default)s)")
    parser.add_argument("--repeat", type=int,
                        help="runs per point (default: each study's 'repeat')")
    parser.add_argument("--fresh", action="store_true",
                        help="rerun every point and replace its kept run (default: reuse "
                             "runs of the same executable, scene, files, overrides and machine "
                             "kept in bench/results/runs/)")
    parser.add_argument("--output", type=Path, default=DOCS_DIR / "VALIDATION.md",
                        help="document to write (default: %(default)s)")
    args = parser.parse_args(argv)
    if args.repeat is not None and args.repeat < 1:
        parser.error("--repeat must be >= 1")
    return args


def load_studies(paths: Optional[list]) -> list:
    """The studies, in their 'order' (then file name) so that sections keep their numbers as
    studies are added."""
    paths = paths or sorted((REPO_ROOT / "bench" / "studies").glob("*.yaml"))
    if not paths:
        raise studies.StudyError("no study files in bench/studies/")
    loaded = [studies.load_study(path) for path in paths]
    names = [s.name for s in loaded]
    if len(set(names)) != len(names):
        raise studies.StudyError("two studies share a name (their plots would overwrite)")
    return sorted(loaded, key=lambda s: (s.order if s.order is not None else 10**9, s.name))


def main(argv: Optional[list] = None) -> int:
    args = parse_args(argv)
    start = time.monotonic()
    try:
        loaded = load_studies(args.studies)
        cosph = studies.resolve_cosph(args.cosph)
        for study in loaded:
            studies.check_first_point(study, cosph)
    except studies.StudyError as error:
        print(f"validation.py: error: {error}", file=sys.stderr)
        return 2
    machine = machine_lines()  # before the runs: the load average is the others' load
    runs = []
    try:
        for study in loaded:
            print(f"== {study.name} ({len(study.points())} points)")
            out_dir = REPO_ROOT / "bench" / "results" / study.name
            runs.append(studies.run_study(study, cosph, out_dir, args.repeat or study.repeat,
                                          timeout=study.timeout or 900.0,
                                          cache=REPO_ROOT / "bench" / "results" / "runs",
                                          refresh=args.fresh))
        write_document(args.output.resolve(), runs, machine, time.monotonic() - start)
    except OSError as error:
        print(f"validation.py: error: cannot write: {error}", file=sys.stderr)
        return 1
    print(f"wrote {args.output} ({time.monotonic() - start:.1f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
