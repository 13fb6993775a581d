"""Exception types a user of contactfx can catch; the CLI turns each into one line on stderr."""


class ContactFxError(Exception):
    """Base class of every error contactfx raises on purpose."""


class InputError(ContactFxError, ValueError):
    """A scene or method parameter is out of its physical or geometric range."""


class MeshError(ContactFxError):
    """The mesh lacks a required tag, has the wrong cell type, or the surfaces do not overlap."""


class GeometryError(ContactFxError):
    """The contact surfaces do not face each other or already penetrate beyond tolerance."""


class SingularSystemError(ContactFxError):
    """A body is held neither by supports nor by contact, so the system has no unique solution."""


class SolverError(ContactFxError):
    """A linear solve diverged (PETSc's reason is in the message)."""


class EliminationError(InputError):
    """A solver cannot eliminate a contact row (raised on every rank alike).

    Attributes:
        node_dofs: The global (x, y) dofs of the active node of the first such row; the
            caller, which knows the pairs, names the pair from them.
        reason: "prescribed" (the node has no free dof to eliminate).
    """

    def __init__(self, message: str, node_dofs: tuple[int, int], reason: str) -> None:
        super().__init__(message)
        self.node_dofs, self.reason = node_dofs, reason


class ActiveSetError(ContactFxError):
    """The active-set iteration cycled or hit its iteration limit."""


class ConvergenceError(ContactFxError):
    """An outer iteration (e.g. the alternating Schwarz method) diverged or hit its limit.

    Attributes:
        history: The iteration records up to the failure (set by the raiser, e.g. schwarz).
    """

    history: list[dict[str, float | None]]


def error_type(name: str) -> type[ContactFxError]:
    """The contactfx error class called `name` (MeshError if there is none by that name).

    Lets a rank that only received an error's name and text (a broadcast from rank 0) raise
    the same type as the rank where it happened.
    """
    found = {cls.__name__: cls for cls in _subclasses(ContactFxError)}
    return found.get(name, MeshError)


def _subclasses(cls: type[ContactFxError]) -> list[type[ContactFxError]]:
    out = [cls]
    for sub in cls.__subclasses__():
        out += _subclasses(sub)
    return out
