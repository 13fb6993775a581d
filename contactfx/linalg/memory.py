"""Freed heap memory handed back to the system, so that resident memory is the live data.

glibc keeps freed small and medium blocks in its heap: after meshing and assembly a few
hundred bytes per DOF stay resident though free, and PETSc's large arrays (mapped apart from
the heap) cannot reuse them (docs/scale.md, "Memory of the condensed path").
"""

from __future__ import annotations

import ctypes
import ctypes.util
from collections.abc import Callable
from functools import cache


@cache
def _trim() -> Callable[[ctypes.c_size_t], object] | None:
    """The C library's malloc_trim (glibc), or None on another C library."""
    name = ctypes.util.find_library("c")
    try:
        return ctypes.CDLL(name).malloc_trim if name else None
    except (OSError, AttributeError):
        return None


def release_freed_memory() -> bool:
    """Return the heap's free pages to the system (glibc's malloc_trim); False if unavailable."""
    trim = _trim()
    if trim is None:
        return False
    trim(ctypes.c_size_t(0))
    return True
