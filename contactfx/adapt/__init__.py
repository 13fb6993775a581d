"""Adaptivity: the error estimates, the sizing of the next mesh and the adaptive loop.

A stage of its own between the study and the API: `loop.adapt` (its records in `records`)
solves a level through `api.run_scene`, estimates its error (`estimate`, `pressure_estimate`,
`facet_jumps`; the goal estimates of `goal`, planned by `planned`), sizes the next mesh from
the indicators (`sizing`, `pressure_sizing`) and remeshes the scene's geometry; `charts` draws the
levels, `true_error` measures against an overkill solution and `mesh_file` writes the last
mesh (docs/adapt.md).
"""
