"""Warnings of ``frictionlab.run`` name the caller's line (a notebook cell's), not frictionlab's."""

from __future__ import annotations

import warnings

import frictionlab

from .conftest import SMALL_PRESET

FAST = {"workers": 1, "progress": False, "plot": False}


def test_running_twice_into_a_folder_warns_at_the_callers_line(tmp_path):
    frictionlab.run(SMALL_PRESET, out=tmp_path / "run", **FAST)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        frictionlab.run(SMALL_PRESET, out=tmp_path / "run", **FAST)
    [warning] = [w for w in caught if "holds a completed run of this preset" in str(w.message)]
    assert warning.filename == __file__ and warning.category is UserWarning
