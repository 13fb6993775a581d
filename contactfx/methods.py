"""The contact methods a user can choose, and which discrete contact operator each one uses."""

from enum import StrEnum


class Method(StrEnum):
    """Contact enforcement methods."""

    NTS = "nts"
    STS = "sts"
    MORTAR = "mortar"
    PENALTY = "penalty"
    SCHWARZ = "schwarz"

    @property
    def operator(self) -> str:
        """Name of the discrete contact operator (B, weighted gap) this method is built on."""
        return {"penalty": "mortar", "schwarz": "mortar"}.get(self.value, self.value)


IMPLEMENTED: frozenset[Method] = frozenset(
    {Method.NTS, Method.STS, Method.MORTAR, Method.PENALTY, Method.SCHWARZ}
)
