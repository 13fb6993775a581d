"""A model of MUMPS' memory estimate from the saddle point's graph, without its analysis.

MUMPS' analysis of a large saddle point is sequential and costly (docs/scale.md), and where
its factorization cannot fit it only decides that the condensed path runs. On the family it
was measured on (2D P1 displacements: nonzeros per DOF of K in NNZ_PER_DOF, the Hertz
scenes' structured and gmsh meshes with accurate grading) MUMPS' estimate summed over the
ranks grows like N (a + b ln N) KB (nested dissection's fill in 2D): `model_mb` is that fit
per rank count, and `LOWER` x it stays below every estimate of the sweep
(benchmarks/mumps_model.json; docs/scale.md, "How `auto` decides"). `auto` asks the model
first and skips the analysis where even its lower bound does not fit; the analysis decides
everywhere else, as before.
"""

from __future__ import annotations

import math

# KB per DOF of MUMPS' estimate (INFO(15) summed over the ranks) = a + b ln(N / 1e6), fitted
# by least squares on the sweep's sizes from MODEL_MIN_DOFS (benchmarks/mumps_model.json),
# per number of ranks; other rank counts are not modelled (the analysis decides).
# The fit's constants rounded down (the fitted values: benchmarks/mumps_model.json).
FIT: dict[int, tuple[float, float]] = {1: (1.38, 0.11), 2: (1.47, 0.11)}
# Below the sweep's smallest ratio of estimate to rounded model, with a margin: model x LOWER
# is below MUMPS' estimate at every size measured on the accurate families
# (benchmarks/mumps_model.json, benchmarks/README.md).
LOWER = 0.95
# The sizes whose growth was fitted: below them a rank's fixed share makes the estimate per
# DOF fall with N, and the analysis is cheap anyway.
MODEL_MIN_DOFS = 400_000
# K's nonzeros per DOF on the measured family (P1 quadrilaterals, two components): a denser
# or sparser graph fills differently, and the model does not apply.
NNZ_PER_DOF = (17.5, 18.1)
# The accurate families measured have moderately stretched cells; the default grading's,
# stretched far more, fill less per DOF than the fit (benchmarks/README.md, "Deciding the
# solver without MUMPS' analysis"): the model applies up to this aspect only.
MODEL_MAX_ASPECT = 100.0


def model_mb(dofs: int, ranks: int, *, lower: bool = False) -> float:
    """MUMPS' estimate (MB summed over `ranks`) for `dofs` DOFs on the measured family.

    `lower`: the sweep's lower bound instead of the fit. NaN where `ranks` is not modelled.
    """
    if ranks not in FIT:
        return math.nan
    a, b = FIT[ranks]
    kb = max(a + b * math.log(dofs / 1e6), 0.0)
    return dofs * kb / 1e3 * (LOWER if lower else 1.0)


def model_bound(dofs: int, nnz_k: int, ranks: int) -> float | None:
    """The model's lower bound of MUMPS' estimate (MB, all ranks), None where it does not apply.

    It applies from MODEL_MIN_DOFS on graphs with K's nonzeros per DOF in NNZ_PER_DOF, on a
    modelled number of ranks (and, checked by the caller, cells up to MODEL_MAX_ASPECT).
    """
    if dofs < MODEL_MIN_DOFS or ranks not in FIT:
        return None
    if not NNZ_PER_DOF[0] <= nnz_k / dofs <= NNZ_PER_DOF[1]:
        return None
    return model_mb(dofs, ranks, lower=True)
