"""Reading a Solution: interface quantities, references, the JSON summary, files and figures."""

from .interface import INTERFACE_FIELDS, contacts_summary, pair_forces, pair_interface
from .records import ContactSummary, EstimateSummary, HertzErrors, PatchErrors, RunSummary
from .references import hertz_summary, uniform_stress_errors
from .stress import body_stress_deviation, nodal_stress, sigma_field
from .summary import summary

__all__ = [
    "INTERFACE_FIELDS",
    "ContactSummary",
    "EstimateSummary",
    "HertzErrors",
    "PatchErrors",
    "RunSummary",
    "body_stress_deviation",
    "contacts_summary",
    "hertz_summary",
    "nodal_stress",
    "pair_forces",
    "pair_interface",
    "sigma_field",
    "summary",
    "uniform_stress_errors",
]
