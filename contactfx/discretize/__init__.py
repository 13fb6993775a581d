"""The DOLFINx side of a contact problem: elasticity, surfaces, pairs, coupling, supports, setup."""

from .setup import ContactSetup, prepare_contact

__all__ = ["ContactSetup", "prepare_contact"]
