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


def test_warnings_of_the_plugin_registry_built_on_first_use_name_the_callers_line(monkeypatch):
    """The registry is built by a notebook's first run: its warnings (a typo in a
    FRICTIONLAB_* variable) named a line of frictionlab's registry.py, not the cell's."""
    from frictionlab.plugin.registry import default_registry

    monkeypatch.setenv("FRICTIONLAB_TRACE_HOOKS", "ture")
    monkeypatch.setenv("FRICTIONLAB_PLUGINS", "gausian")
    default_registry.cache_clear()
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            frictionlab.validate(SMALL_PRESET)
    finally:
        default_registry.cache_clear()  # the next test's registry reads its own environment
    said = [w for w in caught if "FRICTIONLAB_" in str(w.message)]
    assert len(said) == 2, [str(w.message) for w in caught]
    assert all(w.filename == __file__ and w.category is RuntimeWarning for w in said), [w.filename for w in said]


def test_a_failed_run_says_why_at_the_callers_line_and_its_result_keeps_the_reason(tmp_path):
    """A run whose loads all press the same points fits no law: in a notebook the cell showed
    "run failed: 8 of 8 realizations finished" and, for the result, "no fit: no realization
    finished"; why was nowhere to be seen (the CLI says it as its error)."""
    from .conftest import merge

    preset = merge(SMALL_PRESET, {"loading": {"start": 1e-30, "stop": 1e-25, "steps": 6}})
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = frictionlab.run(preset, out=tmp_path / "run", **FAST)
    assert result.status == "failed" and result.error.startswith("no law: every load")
    [warning] = [w for w in caught if "run failed" in str(w.message)]
    assert str(warning.message) == f"small: run failed: {result.error}"
    assert warning.filename == __file__ and warning.category is UserWarning
    html = result._repr_html_()
    assert "no fit: no law: every load" in html and "no realization finished" not in html
    assert html.count("no law: every load") == 1  # the caveat that says the same is not said twice
    assert frictionlab.load(tmp_path / "run").error == result.error


def test_a_bad_preset_comes_out_of_the_call_with_a_short_traceback():
    """A notebook showed every frame between the call and the check that refused (run,
    _run, build_scene, ...: six for the memory check): only the call's frame is left."""
    import traceback

    import pytest

    from frictionlab.errors import PresetError, RunFolderError

    calls = [
        (lambda: frictionlab.run(SMALL_PRESET, {"spectrum.params.hurst": 2.0}, **FAST), PresetError),
        (lambda: frictionlab.validate(SMALL_PRESET, {"realizations": 0}), PresetError),
        (lambda: frictionlab.load("no-such-folder"), RunFolderError),
    ]
    for call, kind in calls:
        with pytest.raises(kind) as raised:
            call()
        frames = traceback.extract_tb(raised.value.__traceback__)
        assert [frame.name for frame in frames] == ["test_a_bad_preset_comes_out_of_the_call_with_a_short_traceback", "<lambda>", "called"]
        assert raised.value.__context__ is None or raised.value.__suppress_context__
