"""The ``run-study`` command's entry point: imports nothing heavy before it can answer a Ctrl-C.

The command line (:mod:`vibroimpact.cli`) takes ~0.3 s to import (numpy, the scene grammar); a Ctrl-C meanwhile, when
no handler of the study is in place yet, used to end in a ``KeyboardInterrupt`` traceback. Here it ends in one line
and exit status 130, like a Ctrl-C at any later moment.
"""

from __future__ import annotations

import os
import sys

__all__ = ["main", "EXIT_INTERRUPTED", "EXIT_TERMINATED"]

#: Exit status of an interrupted run (128 + SIGINT), and of a terminated one (128 + SIGTERM), as :mod:`vibroimpact.cli`
#: gives them.
EXIT_INTERRUPTED = 130
EXIT_TERMINATED = 143


def main(argv: list[str] | None = None) -> int:
    """``run-study``: :func:`vibroimpact.cli.main`, with a Ctrl-C while it imports said in one line (the process then
    ends at once with status :data:`EXIT_INTERRUPTED`), and one outside the run's own handler too."""
    try:
        from vibroimpact.cli import main as run_study
    except BaseException as error:  # a Ctrl-C inside a class body's __set_name__ comes as a RuntimeError it caused
        if _interrupted(error):
            _say_interrupted()
        raise
    try:
        return run_study(argv)
    except KeyboardInterrupt as interrupt:  # outside the run's own handler (reading the scene, opening the store)
        from vibroimpact.runs.cluster import Terminated  # loaded with the command line

        terminated = isinstance(interrupt, Terminated)
        print(f"\n{'terminated (SIGTERM)' if terminated else 'interrupted'}: run the same command to go on (finished work in the output's store is kept)", file=sys.stderr, flush=True)
        _end(EXIT_TERMINATED if terminated else EXIT_INTERRUPTED)
        return EXIT_TERMINATED if terminated else EXIT_INTERRUPTED  # not reached: _end ends the process


def _end(status: int) -> None:
    """End the process with ``status`` after the interpreter's exit handlers (atexit) have run. A Ctrl-C that landed in
    code an extension module runs while it imports marks the interpreter as ended by an unhandled Ctrl-C whatever
    catches it, and an ordinary exit would then kill the process with SIGINT (status -2: 1 run in 19 with a Ctrl-C
    0.3 s after the start, while the command line imports its libraries)."""
    import atexit

    sys.stdout.flush()
    sys.stderr.flush()
    atexit._run_exitfuncs()
    os._exit(status)


def _interrupted(error: BaseException | None) -> bool:
    """Whether ``error`` is a KeyboardInterrupt, or was caused by one (its chain of causes and contexts)."""
    seen = 0
    while error is not None and seen < 100:
        if isinstance(error, KeyboardInterrupt):
            return True
        error, seen = error.__cause__ or error.__context__, seen + 1
    return False


def _say_interrupted() -> None:
    """One line, and the process ends at once with :data:`EXIT_INTERRUPTED`."""
    print("\ninterrupted: nothing had started yet", file=sys.stderr, flush=True)
    sys.stdout.flush()
    # at once: a Ctrl-C that lands in code an extension module runs while it imports (PyRun_*) marks the interpreter
    # as ended by an unhandled Ctrl-C whatever catches it, and its exit would then kill the process with SIGINT
    # (status -2: 7 runs in 40 at 0.1-0.15 s); nothing has started that an orderly exit would close
    os._exit(EXIT_INTERRUPTED)


if __name__ == "__main__":
    sys.exit(main())
