"""Progress of a study: run i of n, the elapsed time and an estimate of what is left.

The estimate scales each pending run from the same method's latest finished level by the
cost growth per level seen last (fine levels grow faster than coarse ones: the direct solver
is superlinear), and adds the meshing of the levels not meshed yet.
"""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np

from .levels import Level
from .runs import Run


def format_seconds(t: float) -> str:
    """12.3 s, 4 min 05 s, 1 h 02 min."""
    if t < 60:
        return f"{t:.1f} s"
    if t < 3600:
        return f"{int(t // 60)} min {int(t % 60):02d} s"
    return f"{int(t // 3600)} h {int(t % 3600 // 60):02d} min"


class Progress:
    """Run i of n, elapsed time and an estimate of what is left, printed on rank 0."""

    def __init__(
        self, methods: list[str], levels: int, ratio: float, say: Callable[[str], None]
    ) -> None:
        self.methods, self.levels, self.say = methods, levels, say
        self.total = len(methods) * levels
        self.t0 = time.perf_counter()
        self.done = 0
        self.cost: dict[tuple[str, int], float] = {}  # run time after meshing
        self.mesh: dict[int, float] = {}
        # Until two levels are seen: 2D meshes have ratio^2 times the elements per level.
        self.default_growth = ratio**2

    def growth(self) -> float:
        """Growth of a run's cost per level, from the latest levels (costs grow faster there)."""
        steps = [
            (k, m) for (m, k) in self.cost if (m, k - 1) in self.cost and self.cost[m, k - 1] > 0
        ]
        if not steps:
            return self.default_growth
        last = max(k for k, _ in steps)
        recent = [self.cost[m, k] / self.cost[m, k - 1] for k, m in steps if k == last]
        return min(max(float(np.median(recent)), 1.0), self.default_growth**2)

    def estimate(self, method: str, level: int, g: float) -> float:
        """Expected cost of a run not done yet, from the closest done level."""
        mine = [k for (m, k) in self.cost if m == method and k < level]
        if mine:
            k = max(mine)
            return self.cost[method, k] * g ** (level - k)
        same = [t for (m, k), t in self.cost.items() if k == level]
        if same:
            return sum(same) / len(same)
        if self.cost:
            k = max(k for _, k in self.cost)
            at = [t for (m, j), t in self.cost.items() if j == k]
            return sum(at) / len(at) * g ** (level - k)
        return 0.0

    def left(self, pending: list[tuple[str, int]]) -> float:
        """Estimated seconds for the pending runs and the levels not meshed yet."""
        g = self.growth()
        t = sum(self.estimate(m, k, g) for m, k in pending)
        if self.mesh:
            k = max(self.mesh)
            t += sum(self.mesh[k] * g ** (j - k) for j in {j for _, j in pending} if j > k)
        return t

    def meshing(self, level: Level) -> None:
        """Announce a level's meshing (fine levels take a while)."""
        sizes = ", ".join(f"{k} {v:.4g}" for k, v in level.sizes.items())
        self.say(f"level {level.index}: meshing ({sizes})")

    def finished(self, run: Run, mesh_time: float | None) -> None:
        """Record a run and print its line."""
        self.done += 1
        if mesh_time is not None:
            self.mesh[run.level] = mesh_time
        if run.ok:
            self.cost[run.method, run.level] = run.after_mesh or 0.0
        # Runs go level by level, methods in order: the pending ones are the rest of that list.
        order = [(m, k) for k in range(self.levels) for m in self.methods]
        pending = order[self.done :]
        elapsed = time.perf_counter() - self.t0
        what = (
            f"{run.dofs} dofs, {run.iterations} its, {run.after_mesh:.2f} s after mesh"
            + "".join(
                f", {k} {v:.3g}"
                for k, v in run.errors.items()
                if v is not None and "_pair" not in k
            )
            if run.ok
            else f"FAILED: {run.message}"
        )
        left = self.left(pending)
        self.say(
            f"[run {self.done}/{self.total}] level {run.level} {run.method}: {what} | "
            f"elapsed {format_seconds(elapsed)}, ~{format_seconds(left)} left"
        )
