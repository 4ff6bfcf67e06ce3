"""``run-study SCENE.yaml [--out DIR] [--jobs N] [--no-report] [--estimate]``, ``run-study --list``: run a scene, write
``DIR/<name>.nc`` and the comparison report."""

from __future__ import annotations

import argparse
import os
import resource
import shutil
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from vibroimpact.study.runner import cached_case_count
from vibroimpact.scene.core import Scene, SceneError, find_scene, load_scene, shipped_studies
from vibroimpact.study.run import run_study, write_dataset

EXIT_BAD_INPUT = 2
EXIT_FAILURE = 1
#: 128 + SIGINT, what a shell reports for a program ended by Ctrl-C.
EXIT_INTERRUPTED = 130


def build_parser() -> argparse.ArgumentParser:
    """The command-line interface of ``run-study``."""
    parser = argparse.ArgumentParser(
        prog="run-study",
        description="Run a vibroimpact scene (YAML) and write its netCDF dataset and comparison report.",
    )
    parser.add_argument("scene", nargs="?", help="scene file; a bare name (with or without .yaml) is also looked up in ./studies/ and the shipped studies (a local file wins)")
    parser.add_argument("--out", type=Path, default=None, help="output folder (default: results/<scene name>/)")
    parser.add_argument("--no-report", action="store_true", help="write the dataset only")
    parser.add_argument("--jobs", type=int, default=os.cpu_count() or 1, help="processes for the simulations (default: all cores)")
    parser.add_argument("--estimate", action="store_true", help="print the predicted wall time and memory of the scene, and run nothing")
    parser.add_argument("--list", action="store_true", help="list the shipped studies with their descriptions, and run nothing")
    return parser


def main(argv: list[str] | None = None) -> int:
    """Entry point; returns the process exit code (2 for a bad scene or arguments, 130 when interrupted)."""
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.list:
        print("\n".join(f"{name:<20} {description}" for name, description in shipped_studies()))
        return 0
    if args.scene is None:
        parser.print_usage(sys.stderr)
        print("run-study: error: a scene is required (or --list)", file=sys.stderr)
        return EXIT_BAD_INPUT
    try:
        scene = load_scene(find_scene(args.scene))
    except (SceneError, OSError) as error:  # OSError: missing, a directory, unreadable
        print(f"run-study: error: {error}", file=sys.stderr)
        return EXIT_BAD_INPUT
    if args.jobs < 1:
        print(f"run-study: error: --jobs {args.jobs} is out of range: allowed [1, inf)", file=sys.stderr)
        return EXIT_BAD_INPUT
    if args.estimate:
        from vibroimpact.study.estimate import estimate_scene

        print(estimate_scene(scene, jobs=args.jobs).text())
        return 0
    out_dir = args.out if args.out is not None else Path("results") / scene.name
    problem = unwritable(out_dir)
    if problem is not None:
        print(f"run-study: error: --out {out_dir} cannot be written: {problem}", file=sys.stderr)
        return EXIT_BAD_INPUT
    cache = out_dir / ".cache"  # finished simulation cases: an interrupted run resumes from here
    try:
        return _run(scene, args, out_dir, cache)
    except KeyboardInterrupt:
        kept = cached_case_count(cache)
        print(f"\ninterrupted: {kept} finished case{'s' if kept != 1 else ''} kept; run the same command to resume", file=sys.stderr)
        return EXIT_INTERRUPTED


def unwritable(out_dir: Path) -> str | None:
    """Why files cannot be written into ``out_dir`` (created if missing), or ``None`` if they can."""
    if out_dir.exists() and not out_dir.is_dir():
        return "it exists and is not a folder"
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
        with tempfile.NamedTemporaryFile(dir=out_dir, prefix=".write-test-"):
            pass
    except OSError as error:
        return error.strerror or str(error)
    return None


def _run(scene: Scene, args: argparse.Namespace, out_dir: Path, cache: Path) -> int:
    started = time.perf_counter()
    try:
        dataset = run_study(scene, jobs=args.jobs, cache_dir=cache)
        # what this run cost, for comparing with ``--estimate`` (simulations: excluding cases taken from the cache)
        dataset.attrs["run_wall_time_s"] = time.perf_counter() - started
        dataset.attrs["run_jobs"] = args.jobs
        dataset.attrs["run_peak_memory_bytes"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
        dataset.attrs["run_peak_memory_worker_bytes"] = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss * 1024  # largest worker
        path = write_dataset(dataset, out_dir / f"{scene.name}.nc")
        shutil.rmtree(cache, ignore_errors=True)
        print(f"wrote {path}")
        if scene.report and not args.no_report:
            from vibroimpact.reporting.report import write_report  # matplotlib is imported only when a report is made

            report = write_report(dataset, out_dir)
            print(f"wrote {report}")
    except (OSError, ValueError, ArithmeticError, np.linalg.LinAlgError, RuntimeError) as error:
        print(f"run-study: error while running {scene.name!r}: {type(error).__name__}: {error}", file=sys.stderr)
        return EXIT_FAILURE
    print(f"done in {time.perf_counter() - started:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
