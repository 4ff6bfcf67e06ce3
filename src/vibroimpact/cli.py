"""``run-study SCENE.yaml [--out DIR]``: run a scene, write ``DIR/<name>.nc`` and the comparison report."""

from __future__ import annotations

import argparse
import os
import resource
import shutil
import sys
import time
from pathlib import Path

import numpy as np

from .scene import SceneError, find_scene, load_scene
from .study import run_study, write_dataset

EXIT_BAD_INPUT = 2
EXIT_FAILURE = 1


def build_parser() -> argparse.ArgumentParser:
    """The command-line interface of ``run-study``."""
    parser = argparse.ArgumentParser(
        prog="run-study",
        description="Run a vibroimpact scene (YAML) and write its netCDF dataset and comparison report.",
    )
    parser.add_argument("scene", help="scene file; a bare name (with or without .yaml) is also looked up in ./studies/ and the shipped studies")
    parser.add_argument("--out", type=Path, default=None, help="output folder (default: results/<scene name>/)")
    parser.add_argument("--no-report", action="store_true", help="write the dataset only")
    parser.add_argument("--jobs", type=int, default=os.cpu_count() or 1, help="processes for the simulations (default: all cores)")
    parser.add_argument("--estimate", action="store_true", help="print the predicted wall time and memory of the scene, and run nothing")
    return parser


def main(argv: list[str] | None = None) -> int:
    """Entry point; returns the process exit code (2 for a bad scene or arguments)."""
    args = build_parser().parse_args(argv)
    try:
        scene = load_scene(find_scene(args.scene))
    except (SceneError, OSError) as error:  # OSError: missing, a directory, unreadable
        print(f"run-study: error: {error}", file=sys.stderr)
        return EXIT_BAD_INPUT
    out_dir = args.out if args.out is not None else Path("results") / scene.name
    if out_dir.exists() and not out_dir.is_dir():
        print(f"run-study: error: --out {out_dir} exists and is not a folder", file=sys.stderr)
        return EXIT_BAD_INPUT
    if args.jobs < 1:
        print(f"run-study: error: --jobs {args.jobs} is out of range: allowed [1, inf)", file=sys.stderr)
        return EXIT_BAD_INPUT
    if args.estimate:
        from .estimate import estimate_scene

        print(estimate_scene(scene, jobs=args.jobs).text())
        return 0
    started = time.perf_counter()
    cache = out_dir / ".cache"  # finished simulation cases: an interrupted run resumes from here
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
            from .report import write_report  # matplotlib is imported only when a report is made

            report = write_report(dataset, out_dir)
            print(f"wrote {report}")
    except (OSError, ValueError, ArithmeticError, np.linalg.LinAlgError, RuntimeError) as error:
        print(f"run-study: error while running {scene.name!r}: {type(error).__name__}: {error}", file=sys.stderr)
        return EXIT_FAILURE
    print(f"done in {time.perf_counter() - started:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
