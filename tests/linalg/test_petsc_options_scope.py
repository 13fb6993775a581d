"""The PETSc options a solver inserts are scoped: present for the block only."""

from __future__ import annotations

from petsc4py import PETSc

from contactfx.linalg.petsc_options import global_options


def test_global_options_are_removed_and_user_keys_kept() -> None:
    """An unprefixed key lives for the block; a key the user had set stays untouched."""
    db = PETSc.Options()
    db["contactfx_test_user_key"] = "7"
    try:
        with global_options({"contactfx_test_scoped": True, "contactfx_test_user_key": "1"}):
            assert db.hasName("contactfx_test_scoped")
            assert db.getString("contactfx_test_user_key") == "7"
        assert not db.hasName("contactfx_test_scoped")
        assert db.getString("contactfx_test_user_key") == "7"
    finally:
        db.delValue("contactfx_test_user_key")
