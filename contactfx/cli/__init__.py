"""Command line: contactfx solve|study SCENE [options]; thin layers over contactfx.api.

Nothing in the library imports this package.
"""

from __future__ import annotations

import logging
import sys

from mpi4py import MPI

from ..errors import ContactFxError
from .adapt import run_adapt
from .parser import parser
from .solve import run
from .study import run_command


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
        if args.command == "adapt":
            return run_adapt(args)
        return run_command(args) if args.command == "study" else run(args)
    except ContactFxError as err:
        if rank == 0:
            print(f"contactfx: error: {err}", file=sys.stderr)
        return 2
