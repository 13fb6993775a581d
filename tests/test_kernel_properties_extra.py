"""Kernel properties not covered by test_geometry_properties.py: operator-level consistency."""

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from test_geometry_properties import surface_pairs

from contactfx.contact import OPERATORS
from contactfx.contact.mortar import mortar_matrices, overlap_weights, subsegments

FAST = settings(max_examples=40, deadline=None)


@FAST
@given(surface_pairs(), st.floats(-1.0, 1.0), st.floats(-1.0, 1.0))
def test_rigid_translation_leaves_gap_unchanged(surfaces, tx, ty):
    # Moving both bodies together must not change any weighted gap: B t = 0 for a translation.
    # For mortar this is partition of unity at the operator level (sum_A M_jA = sum_k D_jk).
    active, passive, nd = surfaces
    t = np.zeros(nd)
    t[active.dofs[:, 0]] = t[passive.dofs[:, 0]] = tx
    t[active.dofs[:, 1]] = t[passive.dofs[:, 1]] = ty
    for method, build in OPERATORS.items():
        op = build(active, passive, nd)
        np.testing.assert_allclose(op.B @ t, 0.0, atol=1e-12, err_msg=method)


@FAST
@given(surface_pairs())
def test_mortar_weights_are_row_sums_of_d(surfaces):
    # The nodal weight w_j = int N_j (which turns a weighted gap into a gap) is the D row sum.
    active, passive, nd = surfaces
    D, _ = mortar_matrices(active, passive)
    op = OPERATORS["mortar"](active, passive, nd)
    d = np.asarray(D.sum(axis=1)).ravel()
    np.testing.assert_allclose(op.weights, d, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(overlap_weights(active, passive), d, rtol=1e-12, atol=1e-15)


@FAST
@given(surface_pairs())
def test_sub_segments_sum_to_whole_segment_inside_overlap(surfaces):
    # An active segment whose both ends project inside the passive polyline is covered once,
    # so its sub-segment lengths sum to its length.
    active, passive, _ = surfaces
    ea, _, xi = subsegments(active, passive)
    covered = np.bincount(ea, weights=xi[:, 1] - xi[:, 0], minlength=active.n_segments)
    xmin, xmax = passive.x[:, 0].min(), passive.x[:, 0].max()
    ends = active.x[active.segments]
    # Passive nodal normals tilt by at most ~0.1 rad here: keep a margin from the ends.
    inside = (ends[:, :, 0].min(axis=1) > xmin + 0.1) & (ends[:, :, 0].max(axis=1) < xmax - 0.1)
    np.testing.assert_allclose(covered[inside], 1.0, atol=1e-12)
