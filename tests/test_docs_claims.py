"""Claims of the docs checked against what the code does: the generated CLI reference
shows every help text as written, and the measured-profile page's exit codes are those
the commands return."""

import importlib.util
import re

import pytest
import yaml

from frictionlab.cli import main
from frictionlab.errors import ExitCode

from .conftest import ROOT, SMALL_PRESET


def _hooks():
    spec = importlib.util.spec_from_file_location("docs_reference_hooks", ROOT / "docs" / "hooks" / "reference.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _outside_code(page: str) -> list[str]:
    lines, fenced = [], False
    for line in page.splitlines():
        if line.startswith("```"):
            fenced = not fenced
        elif not fenced:
            lines.append(re.sub(r"`[^`]*`", "", line))  # an inline code span shows <name> as written
    return lines


def test_the_cli_reference_shows_angle_brackets_instead_of_dropping_them_as_tags():
    page = _hooks().cli_reference()
    assert "(default: runs/&lt;name&gt;-&lt;timestamp&gt;)" in page  # run --out
    assert page.count("-&lt;timestamp&gt;)") >= 4  # and report's, study's --out, exact3d's --runs
    assert "runs/-" not in page and "(LO &lt;= HI)" in page
    tags = [line for line in _outside_code(page) if re.search(r"<[A-Za-z/!]", line)]
    assert tags == [], tags[:3]  # Markdown would take them for HTML and show nothing


def test_the_json_reference_has_no_bare_tags_either():
    assert [line for line in _outside_code(_hooks().json_reference()) if re.search(r"<[A-Za-z/!]", line)] == []


PROFILE_PAGE = ROOT / "docs" / "tutorials" / "measured-profile.md"


@pytest.mark.parametrize(
    "heights", [None, ["1.0"] * 50 + ["nan"] + ["2.0"] * 50, ["1.0"] * 100, ["1.0", "2.0"]],
    ids=["missing", "nan", "constant", "too-short"],
)  # fmt: skip
def test_a_bad_profile_is_refused_up_front_with_the_exit_code_the_page_gives(tmp_path, capsys, heights):
    text = " ".join(PROFILE_PAGE.read_text(encoding="utf-8").split())
    assert "refuse it with exit code 2 before any run folder is made" in text and "exit code 1" not in text
    if heights is not None:
        (tmp_path / "scan.csv").write_text("\n".join(heights) + "\n")
    preset = tmp_path / "scan.yaml"
    preset.write_text(yaml.safe_dump({**SMALL_PRESET, "spectrum": {"name": "profile-file",
                                                                    "params": {"path": "scan.csv", "spacing": 1.0}}}))  # fmt: skip
    assert main(["validate", str(preset)]) == ExitCode.USAGE == 2
    assert main(["run", str(preset), "--out", str(tmp_path / "o"), "--quiet"]) == 2
    assert "scan.csv" in capsys.readouterr().err and not (tmp_path / "o").exists()


def test_ci_runs_the_long_tests_the_readmes_command_leaves_out():
    import tomllib

    options = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["tool"]["pytest"]["ini_options"]
    assert "-n auto" in options["addopts"]
    assert any(marker.startswith("long:") for marker in options["markers"])
    ci = [line.strip() for line in (ROOT / ".ci" / "run").read_text(encoding="utf-8").splitlines()]
    long = next(i for i, line in enumerate(ci) if line.startswith("pytest -m long"))
    assert long > ci.index('pip install -e ".[test]" && pytest')


def test_pytest_runs_a_worker_more_than_the_cores_unless_a_count_is_set(pytestconfig, monkeypatch):
    """The README: `pytest` runs on every core with a worker more (``-n auto``)."""
    from xdist import plugin

    monkeypatch.delenv("PYTEST_XDIST_AUTO_NUM_WORKERS", raising=False)
    cores = plugin.pytest_xdist_auto_num_workers(pytestconfig)  # pytest-xdist's own count
    assert pytestconfig.hook.pytest_xdist_auto_num_workers(config=pytestconfig) == cores + 1
    monkeypatch.setenv("PYTEST_XDIST_AUTO_NUM_WORKERS", "5")
    assert pytestconfig.hook.pytest_xdist_auto_num_workers(config=pytestconfig) == 5


def _collected(*args: str) -> str:
    import subprocess
    import sys

    done = subprocess.run([sys.executable, "-m", "pytest", "--collect-only", "-q", "-p", "no:cacheprovider", "-n", "0", *args],
                          capture_output=True, text=True, cwd=ROOT, timeout=300)  # fmt: skip
    assert done.returncode == 0, done.stdout[-2000:]
    return done.stdout.strip().splitlines()[-1]


@pytest.mark.long
def test_a_long_module_named_on_the_command_line_runs_whole():
    """`pytest tests/exact3d/test_study.py` (as one runs the file one changed) deselects nothing."""
    assert re.fullmatch(r"\d+ tests collected in .*", _collected("tests/exact3d/test_study.py"))
    assert re.fullmatch(r"\d+ tests collected in .*", _collected("tests/tui/test_form.py"))


RECORDER = """
import json, os

_deselected = []


def pytest_deselected(items):
    _deselected.extend(items)


def pytest_collection_finish(session):
    def marks(items):
        return [sorted({mark.name for mark in item.iter_markers()} & {"long", "slow"}) for item in items]

    with open(os.environ["FRICTIONLAB_COLLECTED"], "w", encoding="utf-8") as out:
        json.dump({"selected": marks(session.items), "deselected": marks(_deselected)}, out)
"""


@pytest.mark.long  # one collection of the whole suite
def test_a_bare_pytest_leaves_out_exactly_the_long_and_slow_tests(tmp_path, monkeypatch):
    import json

    (tmp_path / "collection_recorder.py").write_text(RECORDER, encoding="utf-8")
    monkeypatch.setenv("PYTHONPATH", str(tmp_path))
    monkeypatch.setenv("FRICTIONLAB_COLLECTED", str(tmp_path / "collected.json"))
    _collected("-p", "collection_recorder")
    collected = json.loads((tmp_path / "collected.json").read_text(encoding="utf-8"))
    assert all(marks == [] for marks in collected["selected"])  # nothing long or slow in the README's run
    assert all(marks for marks in collected["deselected"])  # and nothing else left out
    assert sum("long" in marks for marks in collected["deselected"]) >= 50  # the TUI sessions and the 3D study at least
    assert any(marks == ["slow"] for marks in collected["deselected"])


def test_the_set_value_the_presets_page_calls_text_is_taken_as_text():
    """how-to/presets.md's example of a --set value YAML cannot read: kept as the text typed
    (its first spelling, `a: b`, was a mapping that `description` refused)."""
    from frictionlab.preset.paths import apply_overrides

    page = " ".join((ROOT / "docs" / "how-to" / "presets.md").read_text(encoding="utf-8").split())
    assignment = re.search(r"is taken as text \(`--set '([^']+)'`", page).group(1)
    path, _, text = assignment.partition("=")
    assert apply_overrides({}, [assignment]) == {path: text}


def test_the_output_files_page_names_every_key_of_summary_json(tmp_path):
    """reference/output-files.md's summary.json row names each key a run writes there
    (python, error, resumed_ and retried_realizations were written but named nowhere)."""
    import json

    preset = tmp_path / "small.yaml"
    preset.write_text(yaml.safe_dump(SMALL_PRESET))
    assert main(["run", str(preset), "--out", str(tmp_path / "o"), "--quiet", "--no-plot", "--workers", "1"]) == 0
    keys = json.loads((tmp_path / "o" / "summary.json").read_text())
    row = next(line for line in (ROOT / "docs" / "reference" / "output-files.md").read_text(encoding="utf-8").splitlines()
               if line.startswith("| `summary.json` |"))  # fmt: skip
    assert [key for key in keys if f"`{key}`" not in row] == []


def test_the_generated_references_and_the_schema_send_no_reader_to_a_source_file():
    """The preset reference (its sweep section read "see frictionlab/runs/sweep.py"), the
    command and JSON references and `frictionlab schema` stand on their own."""
    from frictionlab.preset.schema import preset_json_schema

    hooks = _hooks()
    texts = [hooks.preset_reference(), hooks.cli_reference(), hooks.json_reference(), str(preset_json_schema())]
    assert [re.findall(r"[\w/]+\.py\b", text) for text in texts] == [[], [], [], []]


def test_the_preset_reference_spells_types_and_references_as_they_are():
    """A list that may be null reads "list of (a or null) or null", not "... or null or
    null"; a citation without a DOI (Love 1929) is not written as "doi:Love, ..."."""
    page = _hooks().preset_reference()
    assert "or null or null" not in page and "list of (string or boolean" in page
    assert re.findall(r"doi:(?!10\.)", page) == []
    assert "Love, Phil. Trans. R. Soc. A 228 (1929) 377; Hockney" in page


def test_a_plugins_joint_checks_run_once_its_own_values_pass_whatever_else_is_wrong(tmp_path, capsys):
    """how-to/presets.md: the second phase of a plugin waits for its own fields only; a bad
    value elsewhere is listed beside its problems (the page said it waited for the whole
    preset)."""
    page = " ".join((ROOT / "docs" / "how-to" / "presets.md").read_text(encoding="utf-8").split())
    assert "A plugin's second phase runs once its own values have passed" in page
    spectrum = {"name": "power-law", "params": {"hurst": 0.8, "points": 10}}  # short cut-off 10 = long cut-off
    for params, joint in (({}, True), ({"hurst": 2.0}, False)):
        preset = tmp_path / "p.yaml"
        preset.write_text(yaml.safe_dump({**SMALL_PRESET, "realizations": 0,
                                          "spectrum": {**spectrum, "params": {**spectrum["params"], **params}}}))  # fmt: skip
        assert main(["validate", str(preset)]) == 2
        err = capsys.readouterr().err
        assert "realizations: must be >= 1" in err and ("must be shorter than long_cutoff" in err) == joint


def test_the_help_and_the_dask_tutorial_say_that_a_scheduler_makes_the_executor_dask():
    """`--scheduler` alone runs on Dask; --executor's help gave only processes and serial
    as its defaults."""
    from frictionlab.cli.main import build_parser
    from frictionlab.options import RunOptions

    run = build_parser()._subparsers._group_actions[0].choices["run"]
    helps = {action.dest: " ".join(action.help.split()) for action in run._actions if action.help}
    assert "default: dask with --scheduler" in helps["executor"] and "then dask" in helps["scheduler"]
    assert RunOptions(scheduler="tcp://127.0.0.1:8786").executor_for(2) == "dask"
    tutorial = " ".join((ROOT / "docs" / "tutorials" / "dask-cluster.md").read_text(encoding="utf-8").split())
    assert "`--scheduler` alone implies `--executor dask`" in tutorial
