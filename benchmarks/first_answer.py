"""Time to the first answer: a whole `contactfx solve` against a bare dolfinx import.

Alternates the commands round by round (bare import, [another checkout's solve,] this
checkout's solve) so that the load of a shared machine hits all of them alike; prints each
run, the medians and the ratios to the bare import (docs/scale.md, "Time to the first
answer"), of the wall time and of the CPU time (user + system of the child: less sensitive
to the other jobs of a shared machine, which stretch the wall time while the process waits
for a core). One untimed warm-up run of each fills the bytecode and FFCx caches first.

Run: python benchmarks/first_answer.py [--rounds 5] [--before DIR] [SCENE ARGS...]
(default `hertz`; --before DIR runs DIR's contactfx package, e.g. `git archive main
contactfx | tar -x -C DIR`, with the same venv, as the "before" column).
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--before", type=Path, default=None)
    ap.add_argument("scene", nargs="*", default=["hertz"])
    args = ap.parse_args()
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    solve = [sys.executable, "-m", "contactfx", "solve", *args.scene]
    cmds = {"bare": ([sys.executable, "-c", "import dolfinx_solver, dolfinx"], env)}
    if args.before is not None:
        cmds["before"] = (solve, dict(env, PYTHONPATH=str(args.before.resolve())))
    cmds["solve"] = (solve, env)
    times: dict[str, list[float]] = {k: [] for k in cmds}
    cpu: dict[str, list[float]] = {k: [] for k in cmds}
    with tempfile.TemporaryDirectory() as cwd:
        for rnd in range(-1, args.rounds):
            for name, (cmd, e) in cmds.items():
                t = time.perf_counter()
                before = resource.getrusage(resource.RUSAGE_CHILDREN)
                subprocess.run(cmd, env=e, cwd=cwd, check=True, capture_output=True)
                after = resource.getrusage(resource.RUSAGE_CHILDREN)
                if rnd >= 0:
                    times[name].append(time.perf_counter() - t)
                    cpu[name].append(
                        after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime
                    )
    for label, values in (("wall", times), ("cpu", cpu)):
        bare = statistics.median(values["bare"])
        for name, ts in values.items():
            med = statistics.median(ts)
            runs = " ".join(f"{t:.2f}" for t in ts)
            print(f"{label:4s} {name:6s} {runs}  median {med:.2f} s  ratio {med / bare:.2f}")


if __name__ == "__main__":
    main()
