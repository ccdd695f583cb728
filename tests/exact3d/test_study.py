"""``frictionlab exact3d --quick``: the whole study end to end on the real presets, its page
and figures, the refusal to overwrite, and a second invocation that resumes every ensemble."""

import json

import numpy as np
import pytest

from frictionlab.cli import main
from frictionlab.errors import ExitCode
from frictionlab.exact3d.plan import HURSTS, QUICK, preset_name
from frictionlab.exact3d.report import FIGURES, FIGURES_DIR, PAGE

from ..conftest import PRESETS


@pytest.fixture(scope="module")
def quick_study(tmp_path_factory):
    out = tmp_path_factory.mktemp("exact3d")
    code = main(["exact3d", "--quick", "--presets", str(PRESETS), "--out", str(out), "--runs", str(out / "runs"), "--quiet"])
    assert code == ExitCode.OK
    return out


def test_the_presets_of_the_family_exist_and_differ_only_in_h():
    import yaml

    datas = [yaml.safe_load((PRESETS / preset_name(h)).read_text()) for h in HURSTS]
    for h, data in zip(HURSTS, datas):
        assert data["spectrum"]["params"].pop("hurst") == h
        assert data.pop("name") == preset_name(h).removesuffix(".yaml")
        data.pop("description")
    assert all(data == datas[0] for data in datas)


def test_quick_page_has_every_h_every_grid_and_mdr(quick_study):
    text = (quick_study / PAGE).read_text()
    for name in FIGURES:
        assert (quick_study / FIGURES_DIR / name).stat().st_size > 10_000
        assert f"({FIGURES_DIR}/{name})" in text
    law = [line for line in text.splitlines() if line.startswith("| ") and "|---" not in line]
    rows = {line.split("|")[1].strip() for line in law}
    assert {f"{h:g}" for h in HURSTS} <= rows
    assert "frictionlab exact3d --quick" in text and "Does a log law hold" in text
    # every ensemble ran: exact and MDR on each grid, at each H
    folders = sorted(p.name for p in (quick_study / "runs").iterdir() if p.is_dir())
    assert len(folders) == len(HURSTS) * len(QUICK.resolutions) * 2


def test_exact_and_mdr_ran_at_the_same_f_on_the_same_spectrum(quick_study):
    runs = quick_study / "runs"
    for h in HURSTS:
        for n in QUICK.resolutions:
            exact, mdr = (runs / f"h{h:.1f}-n{n}-{solver}" for solver in ("bem-halfspace", "mdr"))
            np.testing.assert_allclose(f_column(exact), f_column(mdr), rtol=1e-12)
            spectra = [json.loads((folder / "summary.json").read_text())["preset"]["spectrum"] for folder in (exact, mdr)]
            assert spectra[0] == spectra[1] and spectra[0]["params"]["points"] == n


def f_column(folder):
    return np.loadtxt(folder / "curve.csv", delimiter=",", skiprows=1, usecols=1)


def test_an_existing_page_is_refused_and_a_second_run_resumes(quick_study, capsys):
    args = ["exact3d", "--quick", "--presets", str(PRESETS), "--out", str(quick_study), "--runs", str(quick_study / "runs"), "--quiet"]
    before = (quick_study / PAGE).read_text()
    assert main(args) == ExitCode.OUTPUT_REFUSED
    assert "--force" in capsys.readouterr().err
    assert (quick_study / PAGE).read_text() == before
    chunks = {p: p.stat().st_mtime_ns for p in (quick_study / "runs").rglob("chunks/*")}
    assert main([*args, "--force"]) == ExitCode.OK
    assert {p: p.stat().st_mtime_ns for p in (quick_study / "runs").rglob("chunks/*")} == chunks  # nothing recomputed
    after = (quick_study / PAGE).read_text()
    tables = lambda text: [line for line in text.splitlines() if line.startswith("| ")]
    # the same numbers, compute times included: they are the runs' own, read back with them
    assert tables(after) == tables(before)
    # the command the page names reads these runs back rather than computing them again
    assert f"--runs {quick_study / 'runs'}" in after


@pytest.mark.parametrize("hurst", HURSTS)
def test_every_grid_samples_the_same_surfaces(registry, hurst):
    """The page compares grids on the same surfaces: a coarse grid's heights are a fine
    one's at its points (same modes, same random phases), for every realization."""
    from frictionlab.preset import build_scene, read_preset
    from frictionlab.seeds import realization_rng
    from frictionlab.variants import SceneFactory

    path = PRESETS / preset_name(hurst)
    factory = SceneFactory(read_preset(path, registry=registry), registry, source=str(path))

    def heights(points, index):
        changes = {f"spectrum.params.{k}": v for k, v in factory.base.spectrum.refined(points).items()}
        scene = factory.make(changes)
        return scene.spectrum.generate(realization_rng(scene.preset.seed, index)).heights

    for index in (0, 5):  # the full plan's grids (on 64^2 the short cut-off is at the Nyquist mode: not these)
        coarse, fine = heights(128, index), heights(512, index)
        np.testing.assert_allclose(fine[::4, ::4], coarse, rtol=0, atol=1e-12 * coarse.std())


def test_a_presets_folder_without_the_family_is_named_and_refused(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)  # its default runs/ folder is made here, not in the checkout
    code = main(["exact3d", "--quick", "--presets", str(tmp_path), "--out", str(tmp_path / "out"), "--quiet"])
    assert code == ExitCode.USAGE
    err = capsys.readouterr().err
    assert "--presets" in err and "exact3d-h03.yaml" in err and str(tmp_path) in err
    assert not (tmp_path / "out").exists()
