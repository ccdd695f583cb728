"""Every shipped preset validates, and the study's Fig. 2 scene reproduces its contact counts."""

import math
import re

import numpy as np
import pytest

from frictionlab.compute import engine
from frictionlab.compute.realization import compute_realization
from frictionlab.preset import load_scene

from .conftest import PRESETS

PRESET_FILES = sorted(PRESETS.glob("*.yaml"))


def test_presets_folder_is_not_empty():
    names = {p.name for p in PRESET_FILES}
    assert {"quickstart.yaml", "benad2012-fig2.yaml", "benad2012-fig3.yaml", "benad2012-fig4.yaml"} <= names


@pytest.mark.parametrize("path", PRESET_FILES, ids=[p.stem for p in PRESET_FILES])
def test_every_preset_validates(path, registry):
    scene = load_scene(path, registry=registry)
    assert scene.preset.name == path.stem


def test_fig2_scene_matches_the_study_setup(registry):
    scene = load_scene(PRESETS / "benad2012-fig2.yaml", registry=registry)
    p = scene.spectrum.params
    assert (p.hurst, p.points, scene.preset.realizations) == (1.0, 100_000, 300)
    assert scene.loads[0] == 1.0 and scene.loads[-1] == 20.0 and scene.loads.size == 400
    assert scene.solver.stiffness() == 1.0
    # h = 1e4 makes f = F * 1e-9 exactly, the study's axis units
    assert scene.spectrum.rms_height() * scene.spectrum.params.length == pytest.approx(1e9)


@pytest.mark.long  # 300 lines of 100 000 points
def test_fig2_run_in_full_lands_on_the_studys_contact_counts(registry):
    """The paper: about 4 points in contact at F = 1 and 12 at F = 20, over 300 lines.
    "About 4" is read as 4 +- 0.5 (a rounded count); we allow that plus three
    standard errors of our ensemble mean."""
    scene = load_scene(PRESETS / "benad2012-fig2.yaml", registry=registry)
    outcome = engine.run(scene)
    assert outcome.done == 300
    counts = outcome.per_realization["contact_count"]
    sem = counts.std(axis=0, ddof=1) / math.sqrt(counts.shape[0])
    for column, study in ((0, 4.0), (-1, 12.0)):
        assert abs(counts[:, column].mean() - study) <= 0.5 + 3 * sem[column]
    # the counts grow with force in every realization
    assert np.all(np.diff(counts, axis=1) >= 0)
    # f runs over the study's axis, 1e-9 .. 2e-8
    assert outcome.f[0] == pytest.approx(1e-9) and outcome.f[-1] == pytest.approx(2e-8)


@pytest.mark.parametrize(
    "realizations, steps",
    [pytest.param(1, 40, id="reduced"), pytest.param(3, 400, id="full", marks=pytest.mark.slow)],
)
def test_fig2_lines_solved_exactly_agree_with_the_naive_bisection(registry, realizations, steps):
    """At full scale (N = 1e5, the study's force grid) the one-sort sweep and the
    bisection per force give the same contact counts and rms slopes."""
    overrides = {"loading.steps": steps}
    exact = load_scene(PRESETS / "benad2012-fig2.yaml", [f"{k}={v}" for k, v in overrides.items()], registry)
    naive = load_scene(
        PRESETS / "benad2012-fig2.yaml",
        [f"{k}={v}" for k, v in overrides.items()] + ["solver.name=mdr-bisection"],
        registry,
    )
    for index in range(realizations):
        one, two = compute_realization(exact, index), compute_realization(naive, index)
        np.testing.assert_array_equal(one.contact_count, two.contact_count)
        np.testing.assert_allclose(one.xi, two.xi, rtol=1e-12)
        np.testing.assert_allclose(one.indentation, two.indentation, rtol=1e-8)


@pytest.mark.parametrize("text, got", [("", "got an empty file (or comments only)"),
                                       ("# a comment\n", "got an empty file (or comments only)"),
                                       ("- a\n- b\n", "got ['a', 'b']"), ("5\n", "got 5")])  # fmt: skip
def test_a_preset_file_that_is_no_mapping_says_what_it_holds(tmp_path, capsys, text, got):
    """An empty preset was refused as 'Got NoneType instead', a list as 'Got list': Python's
    names for what the file held, not the file's own words."""
    from frictionlab.cli import main

    (tmp_path / "p.yaml").write_text(text)
    assert main(["validate", str(tmp_path / "p.yaml")]) == 2
    err = "".join(capsys.readouterr())
    assert f"(file): a preset must be a mapping of keys to values (name: ..., spectrum: ...), {got}" in err
    assert "NoneType" not in err


def test_a_run_folder_given_as_a_preset_points_to_its_preset(tmp_path, capsys):
    """`frictionlab run runs/x` (the folder, not its preset.yaml) was refused as 'preset file is
    a folder, not a regular file', the preset beside it unsaid."""
    from frictionlab.cli import main

    folder = tmp_path / "run"
    folder.mkdir()
    (folder / "preset.yaml").write_text((PRESETS / "quickstart.yaml").read_text())
    for command in ("validate", "run"):
        assert main([command, str(folder)]) == 3
        err = "".join(capsys.readouterr())
        assert f"a folder, not a preset; it holds a run, whose preset is {folder / 'preset.yaml'}" in err
    (tmp_path / "sweep").mkdir()
    (tmp_path / "sweep" / "sweep.json").write_text("{}")
    assert main(["validate", str(tmp_path / "sweep")]) == 3
    assert "a folder, not a preset; it holds a sweep (frictionlab resume" in "".join(capsys.readouterr())
    (tmp_path / "empty").mkdir()
    assert main(["validate", str(tmp_path / "empty")]) == 3
    assert "preset file is a folder, not a regular file" in "".join(capsys.readouterr())


@pytest.mark.parametrize("record", ["summary.json", "run.json"])
def test_a_runs_record_given_as_a_preset_points_to_its_preset(tmp_path, capsys, record):
    """`frictionlab run runs/x/summary.json` listed the summary's fields as 37 problems of a preset."""
    from frictionlab.cli import main

    folder = tmp_path / "run"
    folder.mkdir()
    (folder / "preset.yaml").write_text((PRESETS / "quickstart.yaml").read_text())
    (folder / record).write_text('{"schema_version": 2, "preset": {}}')
    assert main(["validate", str(folder / record)]) == 3
    err = "".join(capsys.readouterr())
    assert f"(file): the {record} of a run, not a preset; the run's preset is {folder / 'preset.yaml'}" in err
    assert "problems in preset" not in err


def test_a_preset_file_of_two_documents_says_so():
    """Two YAML documents in one file (a --- line between them) were refused as 'not valid YAML
    at line 6, column 1: but found another document', the parser's half sentence."""
    from frictionlab.io.safe_yaml import YamlProblem, load_yaml

    with pytest.raises(YamlProblem, match=r"^a second YAML document \(a --- line\) starts at line 3: a preset is one "
                                          r"document; put the other in a file of its own$"):  # fmt: skip
        load_yaml("name: a\nseed: 1\n---\nname: b\n")
    assert load_yaml("---\nname: a\n...\n") == {"name": "a"}  # one document, marked so



def test_a_tab_or_a_stray_colon_in_a_preset_file_is_named():
    """A tab indenting a line (an editor's) was refused in PyYAML's words: 'found character
    '\\t' that cannot start any token'."""
    from frictionlab.io.safe_yaml import YamlProblem, load_yaml

    with pytest.raises(YamlProblem, match=r"^not valid YAML at line 3, column 1: a tab, where YAML takes spaces only "
                                          r"\(to indent, say\); replace it with spaces$"):  # fmt: skip
        load_yaml("name: a\nspectrum:\n\tname: power-law\n")
    assert load_yaml('name: "a\tb"\n') == {"name": "a\tb"}  # in a quoted string, a tab is text
    for text, line in (("name: a\n  seed: 1\n", 2), ("description: a: b\n", 1)):  # 'mapping values are not allowed here'
        with pytest.raises(YamlProblem, match=rf"^not valid YAML at line {line}, column \d+: a ': ' where YAML takes none: "
                                              r"a key indented under a value, or a value holding ': ' \(quote it\)$"):  # fmt: skip
            load_yaml(text)
    for text, line in (("name: a\nseed 1\nrealizations: 3\n", 2), ("name: a\nseed 1\n", 2)):  # at the next line, or the end
        with pytest.raises(YamlProblem, match=rf"^not valid YAML at line {line}, column 1: a line that is neither 'key: "
                                              r"value' nor part of a value \(a key without its ':', as 'seed 1'"):  # fmt: skip
            load_yaml(text)


@pytest.mark.parametrize("text", ['description: "a scene"\n  of lines\nseed: 1\n', "seed: [1]\n  - 2\n"])
def test_a_line_indented_under_a_whole_value_is_named(text):
    """Words after a closing quote, or a list item under 'key: [..]', indented as part of the
    value: refused in PyYAML's words, "expected <block end>, but found '<scalar>'"."""
    from frictionlab.io.safe_yaml import YamlProblem, load_yaml

    with pytest.raises(YamlProblem, match=r"^not valid YAML at line 2, column 3: a line indented under a value that is "
                                          r"already whole \(words after a closing quote, say, or a list item under 'key: "
                                          r"value'\); indent it as the keys beside it, or make it part of that value$"):  # fmt: skip
        load_yaml(text)


@pytest.mark.parametrize("text, tag", [("name: !!python/object:os.system x\n", "'tag:yaml.org,2002:python/object:os.system'"),
                                       ("name: !Custom x\n", "'!Custom'")])  # fmt: skip
def test_a_tag_a_preset_does_not_take_is_named_with_the_remedy(text, tag):
    """'could not determine a constructor for the tag ...': PyYAML's internals, no remedy."""
    from frictionlab.io.safe_yaml import YamlProblem, load_yaml

    with pytest.raises(YamlProblem, match=re.escape(f"at line 1: its tag {tag} is none a preset takes; write the value "
                                                    "without it")):  # fmt: skip
        load_yaml(text)


def test_a_name_with_an_accent_is_told_which_letters_a_name_takes():
    """'héllo' was refused as 'must be 1 to 100 letters, digits, ...': é is a letter."""
    from frictionlab.errors import PresetError
    from frictionlab.preset import build_scene

    from .conftest import SMALL_PRESET, merge

    with pytest.raises(PresetError, match=r"name: must be 1 to 100 of a-z, A-Z, 0-9, .* got 'héllo'"):
        build_scene(merge(SMALL_PRESET, {"name": "héllo"}))


@pytest.mark.parametrize("text, got", [("# a comment\n", "got empty text (or comments only)"),
                                       ("- a\n- b\n", "got ['a', 'b']")])  # fmt: skip
def test_preset_text_that_is_no_mapping_says_what_it_holds(text, got):
    """YAML text given to the API is told what it holds as a file is ('Got list' before)."""
    import frictionlab
    from frictionlab.errors import PresetError

    with pytest.raises(PresetError) as refused:
        frictionlab.validate(text)
    assert f"(text): a preset must be a mapping of keys to values (name: ..., spectrum: ...), {got}" in str(refused.value)
