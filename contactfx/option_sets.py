"""The PETSc option sets of the solver presets (contactfx.options.SOLVERS)."""

from __future__ import annotations

# The condensed solver's CG with GAMG (docs/scale.md, "GAMG on stretched cells", "Setup cost
# and growth"): ICC(0) smooths along stretched cells; 2 aggressive levels cheapen the coarse
# products.
GAMG: dict[str, object] = {
    "ksp_type": "cg",
    "ksp_norm_type": "unpreconditioned",
    "ksp_max_it": 5000,
    "pc_type": "gamg",
    "pc_gamg_threshold": 0.05,
    "pc_gamg_aggressive_coarsening": 2,
    "pc_gamg_mis_k_minimum_degree_ordering": True,
    "mg_levels_pc_type": "bjacobi",
    "mg_levels_sub_pc_type": "icc",
    "mg_levels_ksp_max_it": 4,
}
# The same CG on coarser grids (a structured grid's own, discretize/grid_mg.py, or the scene
# remeshed, discretize/remesh_mg.py): Galerkin coarse operators, the same ICC(0)-preconditioned
# Chebyshev smoother, the coarsest grid factorized (docs/scale.md, "Geometric multigrid on
# the structured grid" and "A geometric multigrid on gmsh meshes").
GEOMETRIC_MG: dict[str, object] = {
    "ksp_type": "cg",
    "ksp_norm_type": "unpreconditioned",
    "ksp_max_it": 5000,
    "pc_type": "mg",
    "pc_mg_galerkin": "both",
    "pc_mg_type": "multiplicative",
    "mg_levels_ksp_type": "chebyshev",
    "mg_levels_ksp_max_it": 4,
    "mg_levels_ksp_chebyshev_esteig": "0,0.1,0,1.1",
    "mg_levels_esteig_ksp_type": "cg",
    "mg_levels_esteig_ksp_max_it": 10,
    "mg_levels_pc_type": "bjacobi",
    "mg_levels_sub_pc_type": "icc",
    "mg_coarse_ksp_type": "preonly",
    "mg_coarse_pc_type": "lu",
    "mg_coarse_pc_factor_mat_solver_type": "mumps",
}
MUMPS_LU: dict[str, object] = {
    "ksp_type": "preonly",
    "pc_type": "lu",
    "pc_factor_mat_solver_type": "mumps",
    # The ordering (ICNTL(7)) is chosen by size in methods/solvers.py. CNTL(1) = 0.1 (default
    # 0.01): AMD's LDL^T is as accurate as LU then (docs/scale.md, "The ordering rule").
    "mat_mumps_cntl_1": 0.1,
}
# The saddle point is symmetric (indefinite): LDL^T (docs/scale.md, "Symmetric default").
MUMPS_LDLT: dict[str, object] = {**MUMPS_LU, "pc_type": "cholesky"}
