"""Progress of a study: run i of n, the elapsed time and an estimate of what is left.

The estimate extrapolates by DOFs from the levels measured so far, and is given only once
two levels are: how the DOFs grow per level depends on the mesh family (ratio^2 for
uniform refinement, about ratio^1.2 for the graded Hertz meshes) and a coarse level's time is
mostly fixed overheads such as form compilation, so one level alone can be off by a factor
of three either way. Then:
- a pending level's DOFs grow as the last two levels' did;
- a pending run costs its method's latest cost times (N / N_latest)^alpha, alpha fitted on
  the method's two latest levels and held in [1, 1.5] (a direct solver is superlinear; a
  fitted alpha < 1 is the coarse level's overhead);
- a level not meshed yet is meshed at the largest time per DOF seen: a level from the mesh
  cache loads in a fraction of gmsh's time, and a finer level misses the cache on its first
  study (a recording over the cache's size limit is never kept), so the fresh rate is the
  one to expect once it has been seen.
"""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np

from .levels import Level
from .runs import Run

# The relative errors whose bare names read as values (the half-width, the peak pressure).
HEADINGS = {"a": "a err", "p0": "p0 err", "stick": "c err", "shear": "shear L2"}


def error_heading(name: str) -> str:
    """How the table and the progress lines head an error: `a err`, not `a`."""
    return HEADINGS.get(name, name)


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
        self.dofs: dict[int, int] = {}  # DOFs of each level run so far
        self.mesh: dict[int, float] = {}
        # Until two levels are seen: 2D meshes have ratio^2 times the DOFs per level.
        self.default_growth = ratio**2

    def level_dofs(self, level: int) -> float:
        """DOFs of a level: measured, else grown from the latest level like the last step."""
        if level in self.dofs:
            return float(self.dofs[level])
        k = max(self.dofs)
        g = self.default_growth
        if k - 1 in self.dofs and self.dofs[k] > self.dofs[k - 1] > 0:
            g = self.dofs[k] / self.dofs[k - 1]
        return self.dofs[k] * g ** (level - k)

    def exponent(self, method: str) -> float:
        """The exponent alpha of cost ~ N^alpha: the method's two latest levels, in [1, 1.5]."""
        done = sorted(k for (m, k) in self.cost if m == method)
        if len(done) < 2:
            return 1.0
        k0, k1 = done[-2:]
        t0, t1, n0, n1 = self.cost[method, k0], self.cost[method, k1], self.dofs[k0], self.dofs[k1]
        if not (t0 > 0 and t1 > 0 and n1 > n0 > 0):
            return 1.0
        return float(np.clip(np.log(t1 / t0) / np.log(n1 / n0), 1.0, 1.5))

    def estimate(self, method: str, level: int) -> float:
        """Expected cost of a run not done yet, from its method's latest level (else any)."""
        mine = [k for (m, k) in self.cost if m == method]
        if mine:
            k = max(mine)
            scale = self.level_dofs(level) / self.dofs[k]
            return self.cost[method, k] * scale ** self.exponent(method)
        if not self.cost:
            return 0.0
        k = max(k for _, k in self.cost)
        per_dof = [t / self.dofs[k] for (_, j), t in self.cost.items() if j == k]
        return float(np.mean(per_dof)) * self.level_dofs(level)

    def left(self, pending: list[tuple[str, int]]) -> float | None:
        """Estimated seconds for the pending runs and the levels not meshed yet.

        None until two levels have DOFs (see the module's docstring).
        """
        if len(self.dofs) < 2:
            return None
        t = sum(self.estimate(m, k) for m, k in pending)
        rates = [self.mesh[k] / self.dofs[k] for k in self.mesh if self.dofs.get(k)]
        if rates:
            unmeshed = {j for _, j in pending if j > max(self.mesh)}
            t += max(rates) * sum(self.level_dofs(j) for j in unmeshed)
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
        if run.dofs:
            self.dofs.setdefault(run.level, run.dofs)
        if run.ok and run.dofs:
            self.cost[run.method, run.level] = run.after_mesh or 0.0
        # Runs go level by level, methods in order: the pending ones are the rest of that list.
        order = [(m, k) for k in range(self.levels) for m in self.methods]
        pending = order[self.done :]
        elapsed = time.perf_counter() - self.t0
        what = (
            f"{run.dofs} dofs, {run.iterations} its, {run.after_mesh:.2f} s after mesh"
            + "".join(
                f", {error_heading(k)} {v:.3g}"
                for k, v in run.errors.items()
                if v is not None and "_pair" not in k
            )
            if run.ok
            else f"FAILED: {run.message}"
        )
        left = self.left(pending)
        if not pending:
            ahead = "done"
        elif left is None:
            ahead = "time left estimated after level 1"
        else:
            ahead = f"~{format_seconds(left)} left"
        self.say(
            f"[run {self.done}/{self.total}] level {run.level} {run.method}: {what} | "
            f"elapsed {format_seconds(elapsed)}, {ahead}"
        )
