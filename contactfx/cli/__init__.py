"""Command line: contactfx solve|study SCENE [options]; thin layers over contactfx.api.

Nothing in the library imports this package.
"""

from __future__ import annotations

import gc
import logging
import sys

from mpi4py import MPI

from ..errors import ContactFxError
from .parser import parser


def entry() -> int:
    """The process entry (`python -m contactfx`, the `contactfx` script): main() on sys.argv."""
    # The command owns its process and the imported modules live as long as it: frozen, the
    # collector never walks them again (docs/scale.md, "Time to the first answer"). Not in
    # main(), which a test or a script may call in a process of its own.
    gc.freeze()
    return main()


def main(argv: list[str] | None = None) -> int:
    """Entry point: parse, run, and turn contactfx errors into one line on stderr."""
    args = parser().parse_args(argv)
    rank = MPI.COMM_WORLD.rank
    logging.basicConfig(
        level=logging.WARNING if args.quiet or rank else logging.INFO,
        format="%(message)s",
        stream=sys.stdout,
    )
    try:
        # Each subcommand's module is imported when it runs: a plain solve loads neither the
        # adapt loop's charts (matplotlib) nor the study's tables.
        if args.command == "adapt":
            from .adapt import run_adapt

            return run_adapt(args)
        if args.command == "study":
            from .study import run_command

            return run_command(args)
        from .solve import run

        return run(args)
    except ContactFxError as err:
        if rank == 0:
            print(f"contactfx: error: {err}", file=sys.stderr)
        return 2
