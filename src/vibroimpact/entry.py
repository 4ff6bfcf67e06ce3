"""The ``run-study`` command's entry point: imports nothing heavy before it can answer a Ctrl-C.

The command line (:mod:`vibroimpact.cli`) takes ~0.3 s to import (numpy, the scene grammar); a Ctrl-C meanwhile, when
no handler of the study is in place yet, used to end in a ``KeyboardInterrupt`` traceback. Here it ends in one line
and exit status 130, like a Ctrl-C at any later moment.
"""

from __future__ import annotations

import sys

__all__ = ["main", "EXIT_INTERRUPTED"]

#: Exit status of an interrupted run (128 + SIGINT), as :mod:`vibroimpact.cli` gives it.
EXIT_INTERRUPTED = 130


def main(argv: list[str] | None = None) -> int:
    """``run-study``: :func:`vibroimpact.cli.main`, with a Ctrl-C before the study takes it over said in one line."""
    try:
        from vibroimpact.cli import main as run_study

        return run_study(argv)
    except KeyboardInterrupt:
        print("\ninterrupted: nothing had started yet", file=sys.stderr, flush=True)
        return EXIT_INTERRUPTED


if __name__ == "__main__":
    sys.exit(main())
