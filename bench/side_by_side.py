#!/usr/bin/python3
"""Times cosph's FSI cases side by side with SPHinXsys's own (the two programs alternating, each
run a whole process, same case, resolution and physical time) and writes docs/PERFORMANCE_FSI.md.

usage: /usr/bin/python3 bench/side_by_side.py --peer DIR [--cosph PATH] [--repeat N] [--output FILE]
  DIR: SPHinXsys's build folder of its 2D examples (tests/2d_examples, with test_2d_fsi2,
       test_2d_elastic_gate and test_2d_hydrostatic_fsi built; ../shared/peers/sphinxsys/build.sh)

Run it on an otherwise idle machine: the figure is the ratio of the fastest runs, and other work
inflates both programs' times unevenly.
"""
import argparse
import datetime
import subprocess
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import performance  # noqa: E402  (machine(), commit(), scene_bench())

REPO_ROOT = Path(__file__).resolve().parent.parent

# (label, cosph scene, overrides, SPHinXsys target, the peer's particles): SPHinXsys's cases at
# its resolutions and end times. FSI2 runs in SPHinXsys's 11 D channel.
CASES = [
    ("elastic gate (fluid 2.5 mm, gate 1.25 mm, 0.4 s)", "examples/fsi_elastic_gate.yaml",
     ["modules[0].fluid.body.spacing=0.0025"], "test_2d_elastic_gate", "2240 / 480 / 2304"),
    ("hydrostatic plate (0.0125 m, 0.5 s)", "examples/fsi_hydrostatic_plate.yaml",
     ["modules[0].fluid.body.spacing=0.0125", "end_time=0.5"], "test_2d_hydrostatic_fsi",
     "12800 / 352 / 1344"),
    ("FSI2, 11 D channel (fluid D/10, solid D/20, 20 s; one transport-velocity sweep per step, "
     "as SPHinXsys)", "examples/fsi_turek_hron_fsi2.yaml",
     ["modules[0].fluid.body.shape.difference.base.box.upper=[1.1,0.41]",
      "modules[0].fluid.outflow.position=1.1"], "test_2d_fsi2", "5180 / 596 / 1104"),
    # The same cases with the solid's linear gradient correction, SPHinXsys's: the scenes' quadratic
    # one is more accurate in bending and shortens the solid's stable step (docs/ARCHITECTURE.md).
    ("elastic gate as above, linear correction", "examples/fsi_elastic_gate.yaml",
     ["modules[0].fluid.body.spacing=0.0025", "modules[1].solid.gradient_correction=linear"],
     "test_2d_elastic_gate", "2240 / 480 / 2304"),
    ("hydrostatic plate as above, linear correction", "examples/fsi_hydrostatic_plate.yaml",
     ["modules[0].fluid.body.spacing=0.0125", "end_time=0.5",
      "modules[1].solid.gradient_correction=linear"], "test_2d_hydrostatic_fsi", "12800 / 352 / 1344"),
    ("FSI2 as above, linear correction", "examples/fsi_turek_hron_fsi2.yaml",
     ["modules[0].fluid.body.shape.difference.base.box.upper=[1.1,0.41]",
      "modules[0].fluid.outflow.position=1.1", "modules[1].solid.gradient_correction=linear"],
     "test_2d_fsi2", "5180 / 596 / 1104"),
]


def run_peer(peer: Path, target: str) -> float:
    """Wall seconds of one SPHinXsys run from its bin folder, writing no state files."""
    bin_dir = peer / target / "bin"
    start = time.perf_counter()
    # Its exit status is its own regression test's verdict against its stored results, which
    # test_2d_hydrostatic_fsi's random-choice damping fails now and then after a complete run.
    done = subprocess.run([str(bin_dir / target), "--state_recording=false"], cwd=bin_dir,
                          stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    seconds = time.perf_counter() - start
    if done.returncode != 0:
        print(f"note: {target} exited with {done.returncode} (its regression check) after "
              f"{seconds:.1f} s", flush=True)
    return seconds


def run_cosph(cosph: str, scene: str, overrides: list) -> tuple:
    """Wall seconds of one cosph run (whole process) and its run summary."""
    start = time.perf_counter()
    summary = performance.scene_bench(cosph, str(REPO_ROOT / scene), overrides, 2)
    return time.perf_counter() - start, summary


def prepare_peer(peer: Path) -> None:
    """test_2d_fsi2 reloads relaxed particles: relax them once (under a second)."""
    bin_dir = peer / "test_2d_fsi2" / "bin"
    if not (bin_dir / "reload").is_dir():
        subprocess.run([str(bin_dir / "test_2d_fsi2"), "--relax=true"], cwd=bin_dir, check=True,
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


def peer_commit(peer: Path) -> str:
    cache = peer.parent.parent / "CMakeCache.txt"
    try:
        for line in cache.read_text().splitlines():
            if line.startswith("CMAKE_HOME_DIRECTORY"):
                source = line.split("=", 1)[1]
                return subprocess.check_output(["git", "-C", source, "rev-parse", "--short",
                                                "HEAD"], text=True).strip()
    except (OSError, subprocess.CalledProcessError):
        pass
    return "unknown"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--peer", type=Path, required=True)
    parser.add_argument("--cosph", default=str(REPO_ROOT / "build/release/app/cosph"))
    parser.add_argument("--repeat", type=int, default=2)
    parser.add_argument("--output", type=Path, default=REPO_ROOT / "docs/PERFORMANCE_FSI.md")
    args = parser.parse_args()
    for _, _, _, target, _ in CASES:
        if not (args.peer / target / "bin" / target).is_file():
            sys.exit(f"side_by_side.py: no SPHinXsys executable {args.peer / target / 'bin' / target}")
    prepare_peer(args.peer)
    rows = []
    for label, scene, overrides, target, peer_particles in CASES:
        peer_times, cosph_times, summary = [], [], {}
        for _ in range(args.repeat):  # alternating, so that drifts of the machine hit both
            peer_times.append(run_peer(args.peer, target))
            seconds, summary = run_cosph(args.cosph, scene, overrides)
            cosph_times.append(seconds)
            print(f"{label}: SPHinXsys {peer_times[-1]:.1f} s, cosph {seconds:.1f} s", flush=True)
        rows.append((label, scene, overrides, peer_particles, peer_times, cosph_times, summary))
    write_document(args, rows)


def write_document(args, rows: list) -> None:
    now = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    lines = [
        "# FSI performance, side by side with SPHinXsys",
        "",
        "Generated by `/usr/bin/python3 bench/side_by_side.py` (do not edit by hand: regenerate). "
        "Each case runs SPHinXsys's own program and the cosph scene at SPHinXsys's resolution and "
        "end time, alternating, each a whole process (set-up included, no output files); cosph on "
        "2 threads, SPHinXsys with its default (all cores). Target (the couplers issue): half "
        "SPHinXsys's time or less, with the coupler's own time under 5% of the run.",
        "",
        f"- **Date:** {now}",
        f"- **Machine:** {performance.machine()}",
        f"- **cosph commit:** `{performance.commit()}`; **SPHinXsys commit:** "
        f"`{peer_commit(args.peer)}` (../shared/peers/sphinxsys/build.sh)",
        f"- **Runs:** {args.repeat} of each program per case, alternating; the ratio is of the "
        "fastest runs, its range over the pairs of runs",
        "",
        "| case | particles cosph (SPHinXsys fluid / solid / wall) | cosph wall s | SPHinXsys wall s "
        "| ratio (range) | cosph coupler's own share |",
        "|---|---|---|---|---:|---:|",
    ]
    for label, scene, overrides, peer_particles, peer_times, cosph_times, summary in rows:
        ratios = [c / p for c, p in zip(cosph_times, peer_times)]
        share = summary.get("coupler share")
        lines.append(
            f"| {label} | {int(summary.get('particles', 0))} ({peer_particles}) | "
            f"{', '.join(f'{t:.1f}' for t in cosph_times)} | "
            f"{', '.join(f'{t:.1f}' for t in peer_times)} | "
            f"{min(cosph_times) / min(peer_times):.2f} ({min(ratios):.2f}-{max(ratios):.2f}) | "
            f"{'' if share is None else f'{100 * share:.1f}%'} |")
    lines += ["", "cosph's commands (add `--bench --threads 2`):", ""]
    for label, scene, overrides, *_ in rows:
        sets = " ".join(f"--set '{o}'" for o in overrides)
        lines.append(f"- {label}: `cosph run {scene} {sets}`")
    args.output.write_text("\n".join(lines) + "\n")
    print(f"wrote {args.output}")


if __name__ == "__main__":
    main()
