"""``run-study SCENE.yaml [--out DIR] [--jobs N | --scheduler ADDRESS] [--keep-zarr] [--no-report] [--estimate [--costs
FILE]]``, ``run-study --list``: run a scene, write ``DIR/<name>.nc`` and the comparison report; ``run-study calibrate ACCURACY.nc [--out FILE]`` and
``run-study sweep-cost [options]``: the companions that measure costs.

A first argument that names a subcommand runs it (a scene file of that name is still reached as ``./calibrate.yaml``).
"""

from __future__ import annotations

import argparse
import errno
import os
import resource
import re
import shutil
import signal
import sys
import threading
import tempfile
import time
from pathlib import Path
from typing import TYPE_CHECKING, Callable

import numpy as np

from vibroimpact.scene import Scene, SceneError, find_scene, load_scene, shipped_studies
from vibroimpact.runs.cluster import SCHEDULER_VARIABLE, ClusterLost, Terminated, check_jobs, choose_scheduler, dashboard_address, leave_quietly, unreachable

if TYPE_CHECKING:  # the run's modules (xarray, zarr, dask) load only once a study runs: help, --list and a refused
    from vibroimpact.runs.store import StudyStore  # scene answer without them

EXIT_BAD_INPUT = 2
EXIT_FAILURE = 1
#: 128 + SIGINT, what a shell reports for a program ended by Ctrl-C.
EXIT_INTERRUPTED = 130
#: 128 + SIGTERM: a batch system's end of time or ``timeout``, handled like Ctrl-C (finished work kept, one line).
EXIT_TERMINATED = 143
#: Subcommands and what they do (``run-study --help`` lists them).
SUBCOMMANDS = {
    "calibrate": "calibrate ACCURACY.nc [--out FILE]: measure the costs of --estimate from an accuracy_cost dataset and write the cost file",
    "sweep-cost": "sweep-cost [options]: time the paper's swept-sine test through IDA and solve_ivp (a markdown table)",
}


def build_parser() -> argparse.ArgumentParser:
    """The command-line interface of ``run-study``."""
    parser = argparse.ArgumentParser(
        prog="run-study",
        description="Run a vibroimpact scene (YAML) and write its netCDF dataset and comparison report.",
        epilog="subcommands (run-study SUBCOMMAND --help for their options):\n" + "\n".join(f"  run-study {text}" for text in SUBCOMMANDS.values()),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("scene", nargs="?", help="scene file; a bare name (with or without .yaml) is also looked up in ./studies/ and the shipped studies (a local file wins)")
    parser.add_argument("--out", type=Path, default=None, help="output folder (default: results/<scene name>/)")
    parser.add_argument("--no-report", action="store_true", help="write the dataset only")
    parser.add_argument("--jobs", type=int, default=None, help="worker processes of a local dask cluster (default: all cores; 1: this process alone); given, it runs locally whatever $VIBROIMPACT_SCHEDULER or the scene say")
    parser.add_argument("--scheduler", default=None, metavar="ADDRESS", help=f"run on a running dask cluster, e.g. tcp://head-node:8786 (default: ${SCHEDULER_VARIABLE}, else the scene's cluster.scheduler, else a local cluster of --jobs workers)")
    parser.add_argument("--keep-zarr", action="store_true", help="keep the chunked store DIR/<name>.zarr after the netCDF file is written (for grids too large for one netCDF file)")
    parser.add_argument("--estimate", action="store_true", help="print the predicted wall time and memory of the scene, and run nothing")
    parser.add_argument("--workers", type=int, default=None, metavar="N", help="with --estimate: predict the wall time on N workers of a dask cluster (default: --jobs on this machine's cores)")
    parser.add_argument("--costs", type=Path, default=None, help="cost file of --estimate (default: the package's calibrated costs, see run-study calibrate)")
    parser.add_argument("--list", action="store_true", help="list the shipped studies with their descriptions, and run nothing")
    parser.add_argument("--keys", action="store_true", help="print every declared scene key (what it accepts, its default, what it sets) as markdown tables, and run nothing")
    return parser


def study_listing(studies: list[tuple[str, str]], width: int = 120) -> str:
    """One line per study: its name in an aligned column, then its description's first clause, cut to ``width``
    characters with an ellipsis (``run-study NAME`` runs it; the whole description is in the scene file)."""
    column = max((len(name) for name, _ in studies), default=0) + 2
    room = max(width - column, 20)
    lines = []
    for name, description in studies:
        first = _first_clause(description)
        lines.append(f"{name:<{column}}{first if len(first) <= room else first[: room - 3].rstrip() + '...'}")
    return "\n".join(lines)


def _first_clause(text: str) -> str:
    """``text`` up to its first '.', ':' or ';' followed by a space outside parentheses (a '.' ending a word of three
    letters or more: not an abbreviation such as "J." or "Vib.")."""
    depth = 0
    for i, char in enumerate(text[:-1]):
        depth += (char == "(") - (char == ")")
        if depth == 0 and char in ".:;" and text[i + 1] == " ":
            word = re.findall(r"[A-Za-z]+$", text[:i])
            if char != "." or not word or len(word[0]) >= 3:
                return text[:i]
    return text.rstrip(".")


def _print_listing(text: str) -> int:
    """Print a listing to stdout and return 0; a reader that stops early (``| head``) ends it quietly."""
    try:
        print(text, flush=True)
    except BrokenPipeError:
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())  # Python's own flush at exit must not fail too
    return 0


def main(argv: list[str] | None = None) -> int:
    """Entry point; returns the process exit code (2 for a bad scene or arguments, 130 when interrupted)."""
    argv = sys.argv[1:] if argv is None else list(argv)
    if argv and argv[0] in _COMMANDS:
        return _COMMANDS[argv[0]](argv[1:])
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.list:
        return _print_listing(study_listing(shipped_studies(), shutil.get_terminal_size((120, 24)).columns))
    if args.keys:
        from vibroimpact.scene.declared import reference_table
        from vibroimpact.scene.header import declared_sections

        return _print_listing(reference_table(declared_sections()))
    if args.scene is None:
        parser.print_usage(sys.stderr)
        print("run-study: error: a scene is required (or --list, or --keys)", file=sys.stderr)
        return EXIT_BAD_INPUT
    try:
        scene_path = find_scene(args.scene)
        scene = load_scene(scene_path)
    except (SceneError, OSError) as error:  # OSError: missing, a directory, unreadable
        print(f"run-study: error: {error}", file=sys.stderr)
        return EXIT_BAD_INPUT
    local = args.jobs is not None  # an explicit --jobs runs here, unless --scheduler is given too
    args.jobs = args.jobs if args.jobs is not None else os.cpu_count() or 1
    try:
        check_jobs(args.jobs, "--jobs")
    except ValueError as error:
        print(f"run-study: error: {error}", file=sys.stderr)
        return EXIT_BAD_INPUT
    scheduler = args.scheduler if local else choose_scheduler(args.scheduler, scene.cluster_scheduler)
    if args.workers is not None and not args.estimate:
        print("run-study: error: --workers is for --estimate (the workers of a running cluster are the scheduler's)", file=sys.stderr)
        return EXIT_BAD_INPUT
    if args.workers is not None and args.workers < 1:
        print(f"run-study: error: --workers {args.workers} is out of range: allowed [1, inf)", file=sys.stderr)
        return EXIT_BAD_INPUT
    if args.estimate:
        return _estimate(scene, args.jobs, args.costs, args.workers)
    if scheduler is None and args.jobs > 1:
        try:
            dashboard_address()  # the local cluster's dashboard: loopback unless $VIBROIMPACT_DASHBOARD says where
        except ValueError as error:
            print(f"run-study: error: {error}", file=sys.stderr)
            return EXIT_BAD_INPUT
    if scheduler is not None and (why := unreachable(scheduler)) is not None:
        print(f"run-study: error: cannot use the dask scheduler at {scheduler} (--scheduler, ${SCHEDULER_VARIABLE} or the scene's cluster.scheduler): {why}", file=sys.stderr)
        return EXIT_BAD_INPUT
    out_dir = args.out if args.out is not None else Path("results") / scene.name
    problem = unwritable(out_dir)
    if problem is not None:
        print(f"run-study: error: --out {out_dir} cannot be written: {problem}", file=sys.stderr)
        return EXIT_BAD_INPUT
    from vibroimpact.runs.output_files import OutputBusy, claim_output, finished_run
    from vibroimpact.runs.fingerprints import fingerprinted_values, store_fingerprint
    from vibroimpact.runs.store import StoreOfAnotherScene, StudyStore

    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGTERM, _terminate)  # SIGTERM ends the run as Ctrl-C does
    try:
        with claim_output(out_dir):
            for stale in out_dir.glob(".*.tmp"):  # a write cut off by a kill (runs.output_files.atomic_path): never a result
                stale.unlink(missing_ok=True)
            for doomed in out_dir.glob(".*.zarr.removed-*"):  # a finished store whose removal was cut off
                shutil.rmtree(doomed, ignore_errors=True)
            dataset_path = out_dir / f"{scene.name}.nc"
            finished, why_not = finished_run(dataset_path, scene.text)
            if finished and not (out_dir / f"{scene.name}.zarr").exists():  # a store (a kept or cut-off run) resumes
                print(f"{dataset_path}: this scene's finished run (the same values, the same code): kept as it is; remove it to compute again", file=sys.stderr)
                if bool(scene.report) and not args.no_report and not (out_dir / "report.html").exists():
                    report = _report(dataset_path, out_dir, args.jobs)
                    print(f"wrote {report}" if isinstance(report, Path) else report)
                return 0
            if why_not:
                print(f"{dataset_path}: {why_not}: computed again, and replaced when done", file=sys.stderr)
            # finished blocks and cases: a rerun of the same scene skips them
            store = StudyStore(out_dir / f"{scene.name}.zarr", store_fingerprint(scene.text), scene_path, _say, fingerprinted_values(scene.text))
            try:
                return _run(scene, args, out_dir, store, scheduler)
            except KeyboardInterrupt as interrupt:
                leave_quietly()  # before the one line: nothing dask's cut-off calls say may follow it
                what = "terminated (SIGTERM)" if isinstance(interrupt, Terminated) else "interrupted"
                print(f"\n{what}: {_kept(store)}", file=sys.stderr)
                return EXIT_TERMINATED if isinstance(interrupt, Terminated) else EXIT_INTERRUPTED
            except ClusterLost as error:
                leave_quietly()
                print(f"\nrun-study: {error}: {_kept(store)}", file=sys.stderr)
                if store.fresh and not store.block_count() and not store.case_count():
                    store.remove()  # begun by this run and nothing finished: no empty store left behind
                return EXIT_FAILURE
    except (OutputBusy, StoreOfAnotherScene) as error:
        print(f"run-study: error: {error}", file=sys.stderr)
        return EXIT_BAD_INPUT


def _terminate(_signum: int, _frame: object) -> None:
    raise Terminated()


def _say(line: str) -> None:
    """A line of the run's own (finished work discarded or recomputed), on stderr beside the progress bar."""
    print(line, file=sys.stderr, flush=True)


def _kept(store: StudyStore) -> str:
    """What an interrupted run keeps and how to go on, in words (``12 finished blocks and 3 finished cases kept in
    ...; run the same command to resume``), once the store's I/O that the interrupt cut off has ended."""
    from vibroimpact.runs.store_record import settle_io

    settle_io()
    blocks, cases = store.block_count(), store.case_count()
    if not blocks and not cases:
        return "nothing had finished yet; run the same command to start again"
    parts = [f"{n} finished {word}{'s' if n != 1 else ''}" for n, word in ((blocks, "block"), (cases, "case")) if n]
    return f"{' and '.join(parts)} kept in {store.path}; run the same command to resume"


def _estimate(scene: Scene, jobs: int, costs_file: Path | None, workers: int | None = None) -> int:
    """Print the predicted cost of ``scene`` (with the costs of ``costs_file``, by default the package's), on ``jobs``
    local workers or ``workers`` workers of a cluster."""
    from contextlib import nullcontext

    from vibroimpact.runs.estimate import Costs, cluster_cores
    from vibroimpact.runs.estimate import estimate_scene

    try:
        costs = Costs.load(costs_file) if costs_file is not None else None
    except (OSError, ValueError) as error:  # only the cost file's own problems are named as such
        print(f"run-study: error: --costs {costs_file}: {error}", file=sys.stderr)
        return EXIT_BAD_INPUT
    try:
        with cluster_cores(workers) if workers is not None else nullcontext():
            text = estimate_scene(scene, jobs=workers or jobs, costs=costs).text()
    except KeyError as error:  # a cost file without the engine the scene runs
        print(f"run-study: error: the cost file {costs_file} has no cost for {error}", file=sys.stderr)
        return EXIT_BAD_INPUT
    where = f"{workers} workers of a dask cluster" if workers is not None else (f"a local cluster of {jobs} workers" if jobs > 1 else "this process")
    print(f"{text}\n(on {where})")
    return 0


def calibrate_command(argv: list[str]) -> int:
    """``run-study calibrate ACCURACY.nc [--out FILE]``: write the costs measured by an ``accuracy_cost`` run."""
    parser = argparse.ArgumentParser(prog="run-study calibrate", description="Measure the costs of run-study --estimate from a dataset of the accuracy_cost study (and this machine's speed probe) and write the cost file.")
    parser.add_argument("accuracy", type=Path, help="dataset of the accuracy_cost study, e.g. results/accuracy_cost/accuracy_cost.nc")
    parser.add_argument("--out", type=Path, default=None, help="cost file to write (default: the package's own costs.json, where the package is writable)")
    args = parser.parse_args(argv)
    from vibroimpact.runs.estimate import calibrate, write_costs

    try:
        path = write_costs(calibrate(args.accuracy), args.out)
    except (OSError, ValueError, KeyError) as error:  # unreadable, not an accuracy_cost dataset, read-only package
        print(f"run-study calibrate: error: {error}", file=sys.stderr)
        return EXIT_BAD_INPUT
    print(f"wrote {path}", file=sys.stderr)
    return 0


def sweep_cost_command(argv: list[str]) -> int:
    """``run-study sweep-cost [options]``: the swept-sine cost table (:mod:`vibroimpact.kinds.benchmark.sweep_cost`)."""
    from vibroimpact.kinds.benchmark import sweep_cost

    parser = argparse.ArgumentParser(prog="run-study sweep-cost", description=(sweep_cost.__doc__ or "").split("\n\n")[0])
    sweep_cost.add_arguments(parser)
    args = parser.parse_args(argv)
    try:
        settings = sweep_cost.settings_from_arguments(args)
    except ValueError as error:
        print(f"run-study sweep-cost: error: {error}", file=sys.stderr)
        return EXIT_BAD_INPUT
    try:
        print(sweep_cost.markdown_table(sweep_cost.run_sweep_cost(settings, log=lambda line: print(line, flush=True))))
    except KeyboardInterrupt:
        print("\ninterrupted: the cost table is not complete", file=sys.stderr)
        return EXIT_INTERRUPTED
    return 0


#: Largest dataset [bytes] that the report reads into memory; a larger one is written without a report.
REPORT_MEMORY_LIMIT = 2e9


def _report(path: Path, out_dir: Path, jobs: int) -> Path | str:
    """Write the report of the dataset at ``path`` (read into memory), or say why not (too large to draw)."""
    import xarray as xr

    groups = xr.open_groups(path)
    size = sum(group.nbytes for group in groups.values())
    for group in groups.values():
        group.close()
    if size > REPORT_MEMORY_LIMIT:
        return f"no report: the dataset holds {size / 1e9:.1f} GB, more than the {REPORT_MEMORY_LIMIT / 1e9:.0f} GB a report reads into memory (the data are in {path})"
    from vibroimpact.reporting.page import write_report  # matplotlib is imported only when a report is made

    from vibroimpact.runs.cluster import ProgressBar
    from vibroimpact.runs.run import read_dataset

    dataset = read_dataset(path)  # the file's groups joined: the dataset the run gave
    bar = ProgressBar([1.0], [], "page", enabled=True, verb="report", status="drawing the figures")  # its heartbeat
    try:
        return write_report(dataset, out_dir, jobs=jobs)
    finally:
        bar.finish(0)
        bar.close()


def unwritable(out_dir: Path) -> str | None:
    """Why files cannot be written into ``out_dir`` (created if missing), or ``None`` if they can."""
    if out_dir.exists() and not out_dir.is_dir():
        return "it exists and is not a folder"
    for folder in (out_dir, *out_dir.parents):
        if folder.is_symlink() and not folder.exists():  # mkdir would say "File exists"
            try:
                target = f"to {os.readlink(folder)}, which does not exist"
                folder.resolve(strict=True)
            except RuntimeError:
                target = "in a loop of symbolic links"
            except OSError as error:
                target = "in a loop of symbolic links" if error.errno == errno.ELOOP else target
            return f"{folder} is a symbolic link {target}"
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
        with tempfile.NamedTemporaryFile(dir=out_dir, prefix=".write-test-"):
            pass
    except OSError as error:
        return error.strerror or str(error)
    return None


def _as_lines(value: object) -> list[str]:
    """A dataset attribute of lines (one string, or a list of them) as a list."""
    return [value] if isinstance(value, str) else [str(line) for line in value]  # type: ignore[attr-defined]


def _run(scene: Scene, args: argparse.Namespace, out_dir: Path, store: StudyStore, scheduler: str | None) -> int:
    from vibroimpact.runs.failures import console_line, run_failures
    from vibroimpact.runs.run import run_study, write_dataset

    started = time.perf_counter()
    try:
        dataset = run_study(scene, jobs=args.jobs, store=store, scheduler=scheduler, load=False)
        # what this run cost, for comparing with ``--estimate`` (simulations: excluding cases taken from the cache)
        dataset.attrs["run_wall_time_s"] = time.perf_counter() - started
        dataset.attrs["run_jobs"] = args.jobs
        dataset.attrs["run_scheduler"] = scheduler or ("local dask cluster" if args.jobs > 1 else "this process")
        dataset.attrs["run_peak_memory_bytes"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
        reported = bool(scene.report) and not args.no_report
        # streamed from the store chunk by chunk; a dataset the report reads whole anyway is read from it once (a
        # copy, freed after the write: restitution's 26 MB, 1.4 s against 4.6 s streamed)
        written = dataset.compute() if reported and dataset.nbytes <= REPORT_MEMORY_LIMIT else dataset
        path = write_dataset(written, out_dir / f"{scene.name}.nc")
        print(f"wrote {path}")
        for warning in _as_lines(dataset.attrs.get("run_warnings", ())):  # e.g. a stop never reached (a clearance typed in mm)
            print(f"warning: {warning}", file=sys.stderr)
        failures = run_failures(written)  # read before the store (which a lazy dataset reads) goes
        del written
        report: Path | str | None = None
        if reported:
            report = _report(path, out_dir, args.jobs)
            print(f"wrote {report}" if isinstance(report, Path) else report)
        if failures:
            print(console_line(failures, f"{report}" if isinstance(report, Path) else None), file=sys.stderr)
        # the store goes last: a run interrupted while drawing its report reruns from the store in seconds
        if args.keep_zarr:
            store.keep(dataset)
            print(f"kept {store.path}")
        else:
            try:
                store.remove()
            except KeyboardInterrupt as interrupt:  # the results are written: only the store's removal was cut off
                what = "terminated (SIGTERM)" if isinstance(interrupt, Terminated) else "interrupted"
                print(f"\n{what} while removing {store.path}: the results are written; what is left of it goes with the next run", file=sys.stderr)
                return EXIT_TERMINATED if isinstance(interrupt, Terminated) else EXIT_INTERRUPTED
    except ClusterLost:
        raise  # main says what was kept
    except (OSError, ValueError, ArithmeticError, np.linalg.LinAlgError, RuntimeError) as error:
        print(f"run-study: error while running {scene.name!r}: {type(error).__name__}: {error}", file=sys.stderr)
        return EXIT_FAILURE
    print(f"done in {time.perf_counter() - started:.1f} s")
    return 0


#: The subcommands of :data:`SUBCOMMANDS` and what runs them.
_COMMANDS: dict[str, Callable[[list[str]], int]] = {"calibrate": calibrate_command, "sweep-cost": sweep_cost_command}


if __name__ == "__main__":
    sys.exit(main())
