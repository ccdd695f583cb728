"""``frictionlab exact3d --quick``: the whole study end to end on the real presets, its page
and figures, the refusal to overwrite, a second invocation that resumes every ensemble, and
``--finished-only``, which writes the page from what finished and names what did not."""

import json
import math
import os
import shutil

import numpy as np
import pytest

from frictionlab.cli import main
from frictionlab.errors import ExitCode
from frictionlab.exact3d.plan import BROAD_HURSTS, HURSTS, QUICK, TIME_FILE, preset_name
from frictionlab.exact3d.report import FIGURES, FIGURES_DIR, PAGE
from frictionlab.runs.rundir import RunDirectory

from ..conftest import PRESETS


@pytest.fixture(scope="module")
def quick_study(built_once):
    """The quick study, run once a session (``built_once``). Tests read it; a test that writes
    works on a copy."""

    def build(out):
        code = main(["exact3d", "--quick", "--presets", str(PRESETS), "--out", str(out), "--runs", str(out / "runs"),
                     "--quiet", "--workers", "1"])  # fmt: skip
        assert code == ExitCode.OK

    return built_once("exact3d-quick", build)


@pytest.fixture
def figures_not_drawn(monkeypatch):
    """The page's figures written as a few bytes, not drawn (some 10 s a page): for the tests of
    what a page says and what a second invocation reads back. The figures themselves: the quick
    study's, checked by test_quick_page_has_every_h_every_grid_and_mdr."""
    from frictionlab.exact3d import report

    monkeypatch.setattr(report, "PLOTS", tuple(lambda runs, numbers, fh, dpi: fh.write(b"not drawn") for _ in report.PLOTS))


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
    assert "Every ensemble of the plan finished." in text
    # the quick grids resolve the short cut-off with fewer than 16 pixels: nothing is quoted as converged
    assert "not converged" in text and "not quoted" in text
    # every ensemble ran: exact and MDR on each grid at each H, the extra grid, the comparison family, the gradients
    folders = sorted(p.name for p in (quick_study / "runs").iterdir() if p.is_dir())
    assert len(folders) == len(QUICK.jobs()) == (len(HURSTS) * (2 * len(QUICK.resolutions) + 3) + 2 * len(QUICK.extra)
                                                 + len(BROAD_HURSTS))
    # each an ordinary run's numbers, and no figure of its own: the page's figures draw them together
    for folder in folders:
        assert (quick_study / "runs" / folder / "curve.csv").is_file() and (quick_study / "runs" / folder / "summary.json").is_file()
        assert not (quick_study / "runs" / folder / "plot.png").exists()
    # the literature kappa is the corrected range, never the old bracket
    assert "about 1.6 to about 2" not in text and "2 to 2.3" in text and "2.51" in text and "1.60" in text


def test_quick_page_reads_as_a_referee_wants_it(quick_study):
    """Definitions first, the quick plan said, the evidence sections, the limitations, and
    no claim beyond the evidence: "converged" only where the grids resolve the cut-off, a
    log law "holds" only where the model test prefers it at every H."""
    text = (quick_study / PAGE).read_text()
    headings = [line for line in text.splitlines() if line.startswith("## ")]
    assert headings.index("## Definitions") < headings.index("## The answer")
    for heading in ("## Convergence in the grid", "## Which law? The model test", "## g_r and κ_r: the rms gradient "
                    "over the real contact", "## The few-spot regime", "## Limitations"):  # fmt: skip
        assert heading in headings
    assert "### κ against the breadth of the spectrum" in text
    assert "| g_r / g [95 % CI] | κ [95 % CI] | κ_r [95 % CI] |" in text  # g_r and kappa_r published with intervals
    assert "quick plan: small grids and ensembles" in text and "not converged and answer nothing" in text
    for word in ("A0", "E* = E / (1 - ν²)", "p / (E* g)", "Fixed amplitudes", "stop rule", "g_r", "κ_r"):
        assert word in text.split("## What ran")[0], word
    # the quick grids resolve nothing: no "converged" verdict, the convergence said not shown
    assert "converged within" not in text and "not shown: the grids compared" in text
    # the log law is said to hold only if the model test prefers it on every H's mean curve
    rows = [line.split("|") for line in text.splitlines() if "| main, all |" in line]
    preferred = {row[8].strip() for row in rows}
    assert rows and (("Yes, over f" in text) == (preferred == {"log law"}))
    assert "Not as a rule" in text or "Yes, over f" in text
    # the breadth trend cited to its paper, the area correction to its own, the source study named
    assert "J. Mech. Phys. Solids 2017, arXiv 1704.05650" in text and "arXiv 1701.02727" in text
    assert "J. Benad (Physical Mesomechanics, 2012)" in text and "times the real contact area in its springs" in text
    assert "approaching its vanishing-load limit" not in text and "R²" not in text
    assert "The study (quick plan) took **" in text  # every ensemble finished: the plan's time
    assert "of compute (the surfaces' solve times summed" in text  # the cost a killed invocation cannot lose
    # fixed amplitudes give every surface the same g to rounding: said as a bound, never as a bare "0"
    spread = text.split("(g spreads by ")[1].split(" of its mean")[0]
    assert spread == "less than 1e-12" or 1e-12 <= float(spread) < 1e-6


def test_mdr_runs_its_lines_per_surface_and_the_comparison_family_the_whole_side(quick_study):
    runs = quick_study / "runs"
    for h in HURSTS:
        for n in QUICK.resolutions:
            done = json.loads((runs / f"h{h:.1f}-n{n}-mdr" / "summary.json").read_text())["realizations"]["done"]
            assert done == QUICK.mdr_lines * QUICK.realizations[0]
        side = json.loads((runs / f"side-h{h:.1f}-n{QUICK.side[0]}-bem-halfspace" / "summary.json").read_text())
        main = json.loads((runs / f"h{h:.1f}-n{QUICK.side[0]}-bem-halfspace" / "summary.json").read_text())
        assert side["preset"]["spectrum"]["params"]["long_cutoff"] == side["preset"]["spectrum"]["params"]["length"]
        assert main["preset"]["spectrum"]["params"]["long_cutoff"] * 4 == main["preset"]["spectrum"]["params"]["length"]
        spectral = json.loads((runs / f"spectral-h{h:.1f}-n{QUICK.spectral[0]}-bem-halfspace" / "summary.json").read_text())
        assert spectral["preset"]["slope"]["name"] == "spectral"


def test_exact_and_mdr_ran_at_the_same_f_on_the_same_spectrum(quick_study):
    runs = quick_study / "runs"
    for h in HURSTS:
        for n in QUICK.resolutions:
            exact, mdr = (runs / f"h{h:.1f}-n{n}-{solver}" for solver in ("bem-halfspace", "mdr"))
            np.testing.assert_allclose(f_column(exact), f_column(mdr), rtol=1e-12)
            spectra = [json.loads((folder / "summary.json").read_text())["preset"]["spectrum"] for folder in (exact, mdr)]
            assert spectra[0] == spectra[1] and spectra[0]["params"]["points"] == n


def test_finished_only_never_repairs_a_finished_ensemble_whose_chunk_was_damaged(quick_study, tmp_path, capsys, figures_not_drawn):
    """A finished ensemble whose chunk no longer checks out was recomputed and rewritten by
    --finished-only (hours on the full plan, in a folder it only reads): left out, said, unwritten."""
    runs = tmp_path / "runs"
    shutil.copytree(quick_study / "runs", runs)
    damaged = runs / "h0.3-n64-bem-halfspace"
    chunk = next((damaged / "chunks").iterdir())
    os.truncate(chunk, 500)
    files = {p: (p.stat().st_mtime_ns, p.stat().st_size) for p in runs.rglob("*") if p.is_file()}
    args = ["exact3d", "--quick", "--presets", str(PRESETS), "--out", str(tmp_path / "page"), "--runs", str(runs),
            "--finished-only", "--quiet", "--workers", "1"]  # fmt: skip
    with pytest.warns(UserWarning, match=r"h0.3-n64-bem-halfspace says it finished, but its results do not check out"):
        assert main(args) == ExitCode.OK
    assert {p: (p.stat().st_mtime_ns, p.stat().st_size) for p in runs.rglob("*") if p.is_file()} == files
    assert "H = 0.3, 64² px, exact" in (tmp_path / "page" / PAGE).read_text()  # listed among those not run
    capsys.readouterr()


def test_finished_only_writes_the_page_from_what_finished_and_names_the_rest(quick_study, tmp_path, capsys, figures_not_drawn):
    import shutil

    runs = tmp_path / "runs"
    shutil.copytree(quick_study / "runs", runs)
    for name in ("h0.3-n128-bem-halfspace", "spectral-h1.0-n128-bem-halfspace"):
        shutil.rmtree(runs / name)
    chunks = {p: p.stat().st_mtime_ns for p in runs.rglob("chunks/*")}
    (runs / "notes.txt").write_text("mine")  # read only: a user's file beside the runs was refused (exit code 4)
    timed = (runs / TIME_FILE).read_bytes(), (runs / TIME_FILE).stat().st_mtime_ns  # and the time file was rewritten
    files = {p: p.stat().st_mtime_ns for p in runs.rglob("*") if p.is_file()}
    args = ["exact3d", "--quick", "--presets", str(PRESETS), "--out", str(tmp_path / "page"), "--runs", str(runs),
            "--finished-only", "--quiet"]  # fmt: skip
    with RunDirectory(runs / "h0.8-n128-bem-halfspace"):  # another process's hold on a finished one: read without its lock
        assert main(args) == ExitCode.OK
    text = (tmp_path / "page" / PAGE).read_text()
    assert {p: p.stat().st_mtime_ns for p in runs.rglob("chunks/*")} == chunks  # nothing computed
    assert {p: p.stat().st_mtime_ns for p in runs.rglob("*") if p.is_file()} == files  # nothing of the runs written
    assert "H = 0.8, 128² px, exact" not in text  # the held one is read as finished, not listed as not run
    assert ((runs / TIME_FILE).read_bytes(), (runs / TIME_FILE).stat().st_mtime_ns) == timed  # nothing written
    assert (runs / "notes.txt").read_text() == "mine"
    assert not (runs / "h0.3-n128-bem-halfspace").exists()
    assert "2 of the plan's" in text and "H = 0.3, 128² px, exact, 4 surfaces" in text
    assert "H = 1, spectral gradient, 128² px, exact, 2 surfaces" in text
    assert "--finished-only" in text  # the command that regenerates it
    assert "The ensembles that finished took **" in text and "plan) took" not in text  # not the whole plan's time
    assert f"frictionlab exact3d --quick --out {tmp_path / 'page'} --runs {runs} --force" in text  # and the one that finishes
    # H = 0.3 is quoted on its finest grid that finished, 96²
    law = [line for line in text.splitlines() if line.startswith("| 0.3 | 96² (3 px on λs), not quoted")]
    assert law
    capsys.readouterr()
    assert main(["exact3d", "--quick", "--finished-only", "--out", str(tmp_path / "p2"), "--quiet"]) == ExitCode.USAGE
    err = capsys.readouterr().err
    assert "--finished-only" in err and "--runs DIR" in err and not (tmp_path / "p2").exists()


def _presets_with_h03_edited(tmp_path, edit) -> tuple:
    """(the presets folder, its exact3d-h03.yaml): the study's presets copied, that one's text through ``edit``."""
    import shutil

    presets = tmp_path / "presets"
    presets.mkdir()
    for hurst in HURSTS:
        shutil.copy(PRESETS / preset_name(hurst), presets)
    edited = presets / preset_name(0.3)
    edited.write_text(edit(edited.read_text()))
    return presets, edited


def test_a_preset_whose_h_is_not_its_files_is_refused_before_anything_runs(tmp_path, capsys):
    """exact3d-h03.yaml with hurst: 0.9 ran, and the page reported H = 0.9 surfaces as H = 0.3."""
    presets, edited = _presets_with_h03_edited(tmp_path, lambda text: text.replace("hurst: 0.3", "hurst: 0.9"))
    runs = tmp_path / "runs"
    assert main(["exact3d", "--quick", "--presets", str(presets), "--runs", str(runs), "--workers", "1", "--quiet"]) == ExitCode.USAGE
    err = capsys.readouterr().err
    assert f"{edited}: spectrum.params.hurst is 0.9, but the study takes this file for H = 0.3" in err
    assert not list(runs.glob("*/summary.json"))  # no ensemble ran


def test_a_preset_with_a_sweep_is_refused_before_anything_runs(tmp_path, capsys):
    """exact3d-h03.yaml with a sweep of seeds ran its ensembles as if it had none, the sweep dropped without a word."""
    presets, edited = _presets_with_h03_edited(tmp_path, lambda text: text + "sweep:\n  parameters:\n    seed: {values: [1, 2]}\n")
    runs = tmp_path / "runs"
    assert main(["exact3d", "--quick", "--presets", str(presets), "--runs", str(runs), "--workers", "1", "--quiet"]) == ExitCode.USAGE
    err = capsys.readouterr().err
    assert f"{edited}: sweep: the preset sweeps seed, but the study runs its own ensembles" in err
    assert not list(runs.glob("*/summary.json"))  # no ensemble ran


@pytest.mark.parametrize("made, said", [(None, "does not exist"), ("file", "is not a folder")])
def test_finished_only_from_a_runs_folder_that_is_not_one_says_so(made, said, tmp_path, capsys):
    """It was told 'holds no finished exact ensemble', as of an empty folder of runs."""
    runs = tmp_path / "runs"
    if made:
        runs.write_text("mine")
    assert main(["exact3d", "--quick", "--finished-only", "--runs", str(runs), "--quiet"]) == ExitCode.USAGE
    err = capsys.readouterr().err
    assert f"--runs {runs} {said}" in err and "holds no" not in err and "Traceback" not in err
    assert sorted(p.name for p in tmp_path.iterdir()) == (["runs"] if made else [])


def f_column(folder):
    return np.loadtxt(folder / "curve.csv", delimiter=",", skiprows=1, usecols=1)


def test_an_existing_page_is_refused_and_a_second_run_resumes(quick_study, tmp_path, capsys, figures_not_drawn):
    import shutil

    quick_study = shutil.copytree(quick_study, tmp_path / "study", symlinks=True)  # the shared one stays as it was
    args = ["exact3d", "--quick", "--presets", str(PRESETS), "--out", str(quick_study), "--runs", str(quick_study / "runs"),
            "--quiet", "--workers", "1"]  # fmt: skip
    before = (quick_study / PAGE).read_text()
    assert main(args) == ExitCode.OUTPUT_REFUSED
    assert "--force" in capsys.readouterr().err
    assert (quick_study / PAGE).read_text() == before
    runs = quick_study / "runs"
    files = {p: p.stat().st_mtime_ns for p in runs.rglob("*") if p.is_file() and p.name != TIME_FILE}
    with RunDirectory(runs / "h0.8-n128-bem-halfspace"):  # another process's hold on a finished one: read without its lock
        assert main([*args, "--force"]) == ExitCode.OK
    # nothing of the runs was written, the held one's included: read back, not resumed
    assert {p: p.stat().st_mtime_ns for p in runs.rglob("*") if p.is_file() and p.name != TIME_FILE} == files
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
    from frictionlab.preset import read_preset
    from frictionlab.preset.seeds import realization_rng
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
    monkeypatch.chdir(tmp_path)  # its default runs/ folder would be made here, not in the checkout
    code = main(["exact3d", "--quick", "--presets", str(tmp_path), "--out", str(tmp_path / "out"), "--quiet"])
    assert code == ExitCode.USAGE
    err = capsys.readouterr().err
    assert "--presets" in err and "exact3d-h03.yaml" in err and str(tmp_path) in err
    assert not (tmp_path / "out").exists()
    assert not (tmp_path / "runs").exists()  # refused before a default runs folder is made


def test_a_broken_preset_of_a_later_h_is_refused_before_any_ensemble_runs(tmp_path, capsys):
    import shutil

    presets = tmp_path / "presets"
    presets.mkdir()
    for h in HURSTS:
        shutil.copy(PRESETS / preset_name(h), presets)
    broken = presets / preset_name(HURSTS[-1])  # read last: its H runs last
    broken.write_text(broken.read_text().replace("realizations:", "realizations: -3\nx_realizations:", 1))
    runs = tmp_path / "runs"
    code = main(["exact3d", "--quick", "--presets", str(presets), "--out", str(tmp_path / "out"), "--runs", str(runs),
                 "--quiet", "--workers", "1"])  # fmt: skip
    assert code == ExitCode.USAGE
    assert preset_name(HURSTS[-1]) in capsys.readouterr().err
    assert not runs.exists() or not any(p.is_dir() for p in runs.iterdir())  # no ensemble ran


def test_the_broad_band_family_keeps_the_long_cut_off_and_every_family_the_same_loads(quick_study):
    runs = quick_study / "runs"
    points, _, short_pixels = QUICK.broad
    first, last, steps = QUICK.loads
    for h in BROAD_HURSTS:
        broad = json.loads((runs / f"broad-h{h:.1f}-n{points}-bem-halfspace" / "summary.json").read_text())["preset"]
        main = json.loads((runs / f"h{h:.1f}-n{points}-bem-halfspace" / "summary.json").read_text())["preset"]
        b, m = broad["spectrum"]["params"], main["spectrum"]["params"]
        assert b["long_cutoff"] == m["long_cutoff"] and b["short_cutoff"] == pytest.approx(short_pixels * b["length"] / points)
        assert b["short_cutoff"] < m["short_cutoff"]
        for preset in (broad, main):
            assert (preset["loading"]["start"], preset["loading"]["stop"], preset["loading"]["steps"]) == (first, last, steps)
    header = (runs / f"h0.8-n{points}-bem-halfspace" / "curve.csv").read_text().splitlines()[0]
    assert "real_gradient_rms [" in header and "kappa_r [" in header and "contact_spots [" in header


def test_the_full_plan_pairs_three_grids_with_16_surfaces_and_a_broad_band_of_32():
    from frictionlab.exact3d.plan import FULL

    grids = dict(zip(FULL.resolutions, FULL.realizations))
    assert {512, 1024, 2048} <= set(grids) and grids[2048] >= 16
    points, surfaces, short_pixels = FULL.broad
    side, long_cutoff = 128.0, 32.0  # the presets' side and long cut-off
    assert points == 2048 and surfaces >= 16 and short_pixels >= 16
    assert long_cutoff <= side / 4 and long_cutoff / (short_pixels * side / points) >= 32
    first, last, _ = FULL.loads
    assert math.log10(last / first) >= 3.5
    assert set(FULL.broad_hursts) == {0.5, 0.8, 1.0}


def test_a_link_at_an_ensembles_folder_is_never_read_or_written_through(quick_study, tmp_path, capsys):
    """--runs with a link at an ensemble's folder: --finished-only read the run it pointed at into
    the page, and --force wrote the ensemble where it pointed, outside --runs. Both are refused
    before anything runs, naming the link; nothing is written where it points, nor the page."""
    import shutil

    runs, elsewhere = tmp_path / "runs", tmp_path / "elsewhere"
    shutil.copytree(quick_study / "runs", runs)
    shutil.move(runs / "h0.5-n64-mdr", elsewhere)
    (runs / "h0.5-n64-mdr").symlink_to(elsewhere)
    held = {p: p.stat().st_mtime_ns for p in elsewhere.rglob("*")}
    base = ["exact3d", "--quick", "--presets", str(PRESETS), "--runs", str(runs), "--workers", "1", "--quiet"]
    for extra in (["--finished-only", "--out", str(tmp_path / "page")], ["--force", "--out", str(tmp_path / "page")]):
        assert main([*base, *extra]) == ExitCode.OUTPUT_REFUSED
        err = capsys.readouterr().err
        assert f"{runs / 'h0.5-n64-mdr'} is a symbolic link or not a folder, which is never followed: move it aside" in err
        assert {p: p.stat().st_mtime_ns for p in elsewhere.rglob("*")} == held and not (tmp_path / "page" / PAGE).exists()
    shutil.rmtree(elsewhere)
    elsewhere.mkdir()
    (tmp_path / "out").mkdir()
    (tmp_path / "out" / FIGURES_DIR).symlink_to(elsewhere)  # the page's figures folder, a link
    assert main([*base, "--finished-only", "--out", str(tmp_path / "out")]) == ExitCode.OUTPUT_REFUSED
    assert f"{tmp_path / 'out' / FIGURES_DIR} is a symbolic link" in capsys.readouterr().err
    assert not any(elsewhere.iterdir())


def test_a_page_that_is_a_folder_is_refused_before_the_study_even_with_force(quick_study, tmp_path, capsys):
    """--force over an --out whose exact-3d-law.md is a folder read (or ran) every ensemble, then
    ended with 'error: is a folder, not a file: ...' (exit code 1). Refused before any."""
    (tmp_path / "out" / PAGE).mkdir(parents=True)
    args = ["exact3d", "--quick", "--presets", str(PRESETS), "--runs", str(quick_study / "runs"), "--out",
            str(tmp_path / "out"), "--finished-only", "--force", "--quiet"]  # fmt: skip
    assert main(args) == ExitCode.OUTPUT_REFUSED
    err = capsys.readouterr().err
    assert f"{tmp_path / 'out' / PAGE} is a folder, not a file: the exact 3D study writes its {PAGE} there" in err
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == [PAGE]


def test_a_full_disk_says_which_file_and_that_the_ensembles_that_finished_are_kept(tmp_path, capsys, monkeypatch):
    """A full disk in an ensemble's run said 'No space left on device: FILE', nothing of the
    ensembles kept nor of how to resume them."""
    import errno

    from frictionlab.exact3d import plan

    def full(scene, folder, options, *args, **keys):
        raise OSError(errno.ENOSPC, "No space left on device", str(folder / "summary.json"))

    monkeypatch.setattr(plan, "run_to_folder", full)
    runs = tmp_path / "runs"
    assert main(["exact3d", "--quick", "--runs", str(runs), "--quiet"]) == ExitCode.RUNTIME_FAILURE
    err = capsys.readouterr().err
    assert err.startswith(f"error: cannot write {runs}/") and err.count("\n") == 1
    assert err.endswith(f"/summary.json: No space left on device; the ensembles that finished are kept in {runs}; "
                        f"run the command again with --runs {runs} to resume\n")  # fmt: skip


def test_a_full_disk_at_a_runs_figure_says_how_to_resume_too(tmp_path, capsys, monkeypatch):
    """A run's plot.png on a full disk said only '...; the numbers are written'."""
    from frictionlab.errors import RunError
    from frictionlab.exact3d import plan

    def full(scene, folder, options, *args, **keys):
        raise RunError(f"cannot write {folder}/plot.png: No space left on device; the numbers are written")

    monkeypatch.setattr(plan, "run_to_folder", full)
    runs = tmp_path / "runs"
    assert main(["exact3d", "--quick", "--runs", str(runs), "--quiet"]) == ExitCode.RUNTIME_FAILURE
    err = capsys.readouterr().err
    assert err.endswith(f"/plot.png: No space left on device; the numbers are written; the ensembles that finished are "
                        f"kept in {runs}; run the command again with --runs {runs} to resume\n")  # fmt: skip


def test_a_presets_folder_names_the_file_that_is_not_a_regular_one(tmp_path, capsys, monkeypatch):
    """A family with exact3d-h07.yaml a FIFO was refused as 'no folder with exact3d-h03.yaml, ...' without
    a word of which file, or why: named as the report names its presets."""
    monkeypatch.chdir(tmp_path)
    folder = tmp_path / "presets"
    shutil.copytree(PRESETS, folder)
    (folder / "exact3d-h07.yaml").unlink()
    os.mkfifo(folder / "exact3d-h07.yaml")
    code = main(["exact3d", "--quick", "--presets", str(folder), "--out", str(tmp_path / "out"), "--quiet"])
    assert code == ExitCode.USAGE
    assert "exact3d-h07.yaml: is a FIFO (named pipe), not a regular file" in capsys.readouterr().err


def test_out_of_memory_making_a_presets_surface_gives_advice_that_fits_the_study(tmp_path, capsys, monkeypatch):
    """Under `ulimit -v`, the surface that scales a preset's loads (made before the memory check)
    ran out of memory, and the study was told to ask for fewer points or realizations: its
    grids and ensembles are its plan's, not a setting of the command."""
    from frictionlab.exact3d import plan

    def short(*args, **keys):
        raise MemoryError("Unable to allocate 8.00 MiB for an array with shape (1024, 1024) and data type float64")

    monkeypatch.setattr(plan, "SceneFactory", short)
    assert main(["exact3d", "--quick", "--runs", str(tmp_path / "runs"), "--quiet"]) == ExitCode.RUNTIME_FAILURE
    err = capsys.readouterr().err
    assert err.startswith("error: the exact 3D study starts nothing: out of memory making a surface of ")
    assert "(Unable to allocate 8.00 MiB" in err and "; run it where more memory is free" in err
    assert "fewer points" not in err and "internal error" not in err
