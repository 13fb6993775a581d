"""PETSc options under a private prefix (removed afterwards), PETSc's reasons and errors in words.

As dolfinx's LinearProblem: the options go into PETSc's database under a unique prefix only
around the KSP's `setFromOptions`, and are deleted right after (`petsc_options`); a solver
that reconfigures later keeps them in a `PrefixedOptions` until it is destroyed.
"""

from __future__ import annotations

import itertools
from collections.abc import Iterator, Mapping
from contextlib import contextmanager

from petsc4py import PETSc

_counter = itertools.count()


class PrefixedOptions:
    """PETSc options kept under a fresh unique prefix, in PETSc's database only while inserted.

    PETSc reads a KSP's options at `setFromOptions` and, for what is created lazily (MUMPS'
    ICNTLs, fieldsplit's inner solvers), at its first `setUp`: insert them around both.
    """

    def __init__(self, options: Mapping[str, object]) -> None:
        self.prefix = f"contactfx_{next(_counter)}_"
        self.options = dict(options)

    @contextmanager
    def inserted(self) -> Iterator[str]:
        """The options in the database for the duration of the block; yields the prefix."""
        db = PETSc.Options()
        for key, value in self.options.items():
            db[self.prefix + key] = value  # type: ignore[index]  # stub lacks Options.__setitem__
        try:
            yield self.prefix
        finally:
            for key in self.options:
                db.delValue(self.prefix + key)


@contextmanager
def global_options(options: Mapping[str, object]) -> Iterator[None]:
    """`options` in PETSc's database without a prefix for the block, then removed.

    For what reads only unprefixed keys: the products GAMG creates inside its setup carry no
    options prefix. Keys already set (by the user, e.g. PETSC_OPTIONS) are left as they are.
    """
    db = PETSc.Options()
    added = [key for key in options if not db.hasName(key)]
    for key in added:
        db[key] = options[key]  # type: ignore[index]  # stub lacks Options.__setitem__
    try:
        yield
    finally:
        for key in added:
            db.delValue(key)


@contextmanager
def petsc_options(options: Mapping[str, object]) -> Iterator[str]:
    """Set `options` under a fresh unique prefix and remove them afterwards."""
    with PrefixedOptions(options).inserted() as prefix:
        yield prefix


def petsc_error_message(err: PETSc.Error, where: str) -> str:
    """One line from a PETSc error: its code and PETSc's own last message line."""
    lines = [line.removeprefix("[0]").strip() for line in str(err).splitlines()]
    code = err.ierr  # type: ignore[attr-defined]  # set by Error.__init__, missing from the stub
    return f"PETSc error {code} in the {where}: {lines[-1] if len(lines) > 1 else 'no message'}"


def reason_name(reason: int) -> str:
    """PETSc's name of a KSP converged/diverged reason."""
    names = {v: k for k, v in vars(PETSc.KSP.ConvergedReason).items() if isinstance(v, int)}
    return names.get(reason, "unknown")
