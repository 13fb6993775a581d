"""How a 2-rank result is compared with the serial one: one check per returned array.

Each check takes (serial, two ranks) and raises AssertionError naming the array. The
tolerances are those of the per-file tests these cases replace (tests/ranks/rank_cases.py).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass

import numpy as np

Arrays = Mapping[str, np.ndarray]


@dataclass(frozen=True)
class Exact:
    """Equal entries (active flags, iteration and probe counts); `positive`: also > 0."""

    positive: bool = False

    def __call__(self, key: str, one: np.ndarray, two: np.ndarray) -> None:
        """Raise unless `two` equals `one` (and, with `positive`, every entry is > 0)."""
        assert np.array_equal(one, two), f"{key}: serial {one} != 2 ranks {two}"
        if self.positive:
            assert np.all(one > 0), f"{key}: expected > 0, got {one}"


@dataclass(frozen=True)
class Abs:
    """max |two - one| <= tol (coordinates, the Hertz pressure profile, forces)."""

    tol: float

    def __call__(self, key: str, one: np.ndarray, two: np.ndarray) -> None:
        """Raise unless every entry differs by at most `tol`."""
        err = float(np.abs(two - one).max(initial=0.0))
        assert err <= self.tol, f"{key}: max |2 ranks - serial| = {err:.3e} > {self.tol:.1e}"


@dataclass(frozen=True)
class Rel:
    """max |two - one| < tol * max |one| (displacements, pressures): one nonzero scale."""

    tol: float

    def __call__(self, key: str, one: np.ndarray, two: np.ndarray) -> None:
        """Raise unless the largest difference is below `tol` times the serial maximum."""
        scale = float(np.abs(one).max(initial=0.0))
        assert scale > 0.0, f"{key}: the serial values are all zero (nothing to compare)"
        err = float(np.abs(two - one).max(initial=0.0))
        assert err < self.tol * scale, f"{key}: {err:.3e} >= {self.tol:.0e} * {scale:.3e}"


@dataclass(frozen=True)
class Approx:
    """Entrywise pytest.approx: |two - one| <= max(rel |one|, abs) (Hertz's a, p0, L2)."""

    rel: float
    abs: float = 1e-12

    def __call__(self, key: str, one: np.ndarray, two: np.ndarray) -> None:
        """Raise unless each entry is within max(rel |serial|, abs) of the serial one."""
        bound = np.maximum(self.rel * np.abs(one), self.abs)
        bad = np.abs(two - one) > bound
        assert not bad.any(), f"{key}: 2 ranks {two[bad]} vs serial {one[bad]}"


Check = Callable[[str, np.ndarray, np.ndarray], None]


def compare(checks: Mapping[str, Check], one: Arrays, two: Arrays) -> None:
    """Every array checked, none unchecked: the same keys and shapes, then each check."""
    assert set(one) == set(checks) == set(two), (sorted(one), sorted(checks), sorted(two))
    for key, check in checks.items():
        a, b = np.asarray(one[key]), np.asarray(two[key])
        assert a.shape == b.shape, f"{key}: serial shape {a.shape}, 2 ranks {b.shape}"
        check(key, a, b)


def u_checks() -> dict[str, Check]:
    """u_at_points split: the sorted node coordinates to 1e-12, the values to 1e-8."""
    return {"u_xy": Abs(1e-12), "u": Rel(1e-8)}
