"""Command line: contactfx solve|study SCENE [options]; thin layers over contactfx.api.

Nothing in the library imports this package.
"""

from __future__ import annotations

import argparse
import gc
import io
import logging
import sys
from contextlib import redirect_stderr, redirect_stdout

from mpi4py import MPI

from .failure import fail
from .params import check_outputs
from .parser import parser


def entry() -> int:
    """The process entry (`python -m contactfx`, the `contactfx` script): main() on sys.argv."""
    # The command owns its process and the imported modules live as long as it: frozen, the
    # collector never walks them again (docs/scale.md, "Time to the first answer"). Not in
    # main(), which a test or a script may call in a process of its own.
    gc.freeze()
    return main()


def parse(argv: list[str] | None, rank: int) -> argparse.Namespace:
    """The parsed arguments; a usage error or --help is printed by rank 0 only.

    Every rank parses the same command line and exits alike (argparse's SystemExit); the
    other ranks' copies of the text go nowhere.
    """
    if rank == 0:
        return parser().parse_args(argv)
    with redirect_stdout(io.StringIO()), redirect_stderr(io.StringIO()):
        return parser().parse_args(argv)


def main(argv: list[str] | None = None) -> int:
    """Entry point: parse, run, and turn any error into one message and exit code 2.

    Under mpirun an error on one rank only ends every rank (cli/failure.py).
    """
    world = MPI.COMM_WORLD
    args = parse(argv, world.rank)
    logging.basicConfig(
        level=logging.WARNING if args.quiet or world.rank else logging.INFO,
        format="%(message)s",
        stream=sys.stdout,
    )
    # The failure path's own communicator: its barrier cannot match one of the run's.
    errors = world.Dup() if world.size > 1 else None
    try:
        code = _run(args)
    except Exception as err:
        return fail(err, errors)
    if errors is not None:
        errors.Free()
    return code


def _run(args: argparse.Namespace) -> int:
    """The subcommand of `args`."""
    check_outputs(args)
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
