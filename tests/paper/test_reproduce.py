"""The reproduction report: averaging readings against brute force, the h calibration
against a known h, and the report's content on tiny presets (numbers from summary.json),
its --json and where it writes, from one ``frictionlab report`` run for the module."""

import io
import json
import math
import os
import re
import shutil
from pathlib import Path

import numpy as np
import pytest
import yaml

from frictionlab.compute import engine
from frictionlab.cli import main
from frictionlab.errors import ExitCode, OutputRefused
from frictionlab.options import RunOptions
from frictionlab.paper.calibration import COUNT_TARGETS, calibrated_rms_height
from frictionlab.paper.figures import FIGURES, find_presets, run_figures
from frictionlab.paper.markdown import fig5_calibrated_markdown, readings_markdown
from frictionlab.paper.plots import plot_fig5_calibrated
from frictionlab.paper.reproduce import report_paths
from frictionlab.paper.readings import (
    Reading,
    average_curve,
    fig5_calibrated_readings,
    refit,
    run_readings,
)
from frictionlab.preset import apply_overrides, build_scene, load_preset_file
from frictionlab.runs.runner import run_to_folder

from ..conftest import PRESETS, SMALL_PRESET, run_cli

TINY = ["realizations=6", "spectrum.params.points=1024", "spectrum.params.length=1024.0", "output.plot=false",
        "spectrum.params.rms_height=300.0", "loading.steps=12", "fit.bootstrap=40"]  # fmt: skip


@pytest.fixture(scope="module")
def tiny_presets(tmp_path_factory):
    folder = tmp_path_factory.mktemp("presets")
    for fig in FIGURES:
        data = apply_overrides(load_preset_file(PRESETS / fig.preset), TINY)
        if data.get("sweep"):
            data["sweep"]["parameters"] = {"spectrum.params.hurst": {"values": [0.6, 1.0]}}
        (folder / fig.preset).write_text(yaml.safe_dump(data, sort_keys=False))
    return folder


def synthetic_lines(seed=3, m=5, forces=4):
    """Per-realization arrays made from explicit contact slopes, for brute force."""
    rng = np.random.default_rng(seed)
    line = rng.uniform(0.5, 2.0, m)
    slopes = [[rng.normal(0, line[r], rng.integers(1, 9)) for _ in range(forces)] for r in range(m)]
    per = {
        "xi": np.array([[np.sqrt(np.mean(s**2)) / line[r] for s in row] for r, row in enumerate(slopes)]),
        "contact_count": np.array([[s.size for s in row] for row in slopes]),
        "slope_rms_line": line,
    }
    return per, slopes, line


def test_averages_against_brute_force():
    per, slopes, line = synthetic_lines()
    for k in range(4):
        pooled = np.concatenate([row[k] for row in slopes])
        expected = math.sqrt(np.mean(pooled**2)) / math.sqrt(np.mean(line**2))
        assert average_curve(per, "pooled")[k] == pytest.approx(expected, rel=1e-12)
        xi_k = per["xi"][:, k]
        assert average_curve(per, "rms")[k] == pytest.approx(math.sqrt(np.mean(xi_k**2)), rel=1e-12)
        assert average_curve(per, "mean")[k] == pytest.approx(np.mean(xi_k), rel=1e-12)


@pytest.mark.parametrize("method", ["mean", "pooled", "rms"])
def test_bootstrap_weights_equal_repeated_realizations(method):
    per, _, _ = synthetic_lines()
    counts = np.array([[2, 0, 1, 1, 1], [0, 0, 5, 0, 0]])
    repeated = [{k: np.repeat(v, c, axis=0) for k, v in per.items()} for c in counts]
    weighted = average_curve(per, method, counts)
    for row, data in zip(weighted, repeated, strict=True):
        assert row == pytest.approx(average_curve(data, method), rel=1e-12)


def test_refit_of_the_mean_is_the_runs_own_fit(make_scene):
    scene = make_scene({"realizations": 12})
    outcome = engine.run(scene, RunOptions(workers=1))
    fit = refit(outcome.f, outcome.per_realization, "mean", bootstrap=200, confidence=0.95, seed=scene.preset.seed)
    assert (fit.a, fit.b) == pytest.approx((outcome.fit.a, outcome.fit.b), rel=1e-12)
    assert fit.a_ci == pytest.approx(outcome.fit.a_ci, rel=1e-12)
    assert fit.b_ci == pytest.approx(outcome.fit.b_ci, rel=1e-12)


def test_calibration_recovers_a_known_rms_height(registry):
    # counts measured at h = 37 must calibrate back to h = 37 (3 significant digits, grid interpolation)
    data = {**SMALL_PRESET, "realizations": 8, "loading": {"start": 0.5, "stop": 20.0, "steps": 2}}
    data = apply_overrides(data, ["spectrum.params.rms_height=37.0"])
    outcome = engine.run(build_scene(data, registry=registry), RunOptions(workers=1))
    targets = dict(zip(outcome.loads.tolist(), outcome.contact_count.tolist(), strict=True))
    assert calibrated_rms_height(data, targets, options=RunOptions(workers=1)) == pytest.approx(37.0, rel=0.03)


MINE = "# my tracked report\n\n## Readings\n"


@pytest.fixture(scope="module")
def tiny_report(tmp_path_factory, tiny_presets):
    """``frictionlab report --json`` of the tiny presets, run once for the module in a
    folder that holds a REPRODUCTION.md of the user's: (that folder, the CompletedProcess)."""
    folder = tmp_path_factory.mktemp("report")
    (folder / "REPRODUCTION.md").write_text(MINE)
    done = run_cli("report", "--presets", tiny_presets, "--quiet", "--workers", "1", "--json", cwd=folder)
    assert done.returncode == ExitCode.OK, done.stderr
    return folder, done


def test_report_on_tiny_presets(tiny_report):
    folder, done = tiny_report
    md = folder / json.loads(done.stdout)["report"]
    text, runs = md.read_text(), md.parent
    assert "Wall time of the whole report (Figs. 2 to 5):" in text
    for fig in FIGURES:
        assert f"![{fig.title}](figures/{fig.key}.png)" in text
        assert (runs / "figures" / f"{fig.key}.png").stat().st_size > 1000
    for key in ("fig2", "fig3", "fig4"):
        fit = json.loads((runs / key / "summary.json").read_text())["fit"]
        study = next(s for s in FIGURES if s.key == key)
        cell = f"| {study.a} | {fit['a']:.4f} [{fit['a_ci'][0]:.4f}, {fit['a_ci'][1]:.4f}]"
        assert cell in text
        assert f"{fit['b']:.4f} [{fit['b_ci'][0]:.4f}, {fit['b_ci'][1]:.4f}]" in text
    rows = list(json.loads((runs / "fig5" / "sweep.json").read_text())["points"])
    for row in rows:
        assert f"| {row['spectrum.params.hurst']:g} | {row['a']:.4f} [{row['a_lo']:.4f}, {row['a_hi']:.4f}]" in text
    assert "| Fig. 5 at H = 0.6 | about 2.9 |" in text  # the point nearest H = 0.7
    for key in ("fig2", "fig3", "fig4"):  # f as a plain number (was "1.22e+04e-9")
        with np.load(runs / key / "realizations.npz") as data:
            f = data["f"]
        assert f"Over f = {f[0]:.3g} .. {f[-1]:.3g} the paper's law" in text
    assert not re.search(r"\de[+-]\d+e-9", text)


def test_report_json_names_the_report_and_the_figures_it_shows(tiny_report):
    folder, done = tiny_report
    printed = json.loads(done.stdout)  # stdout is only the JSON
    report = Path(printed["report"])
    assert report.name == "REPRODUCTION.md"
    assert printed["figures"] == [str(report.parent / "figures" / f"{fig.key}.png") for fig in FIGURES]
    assert all(os.path.getsize(folder / figure) > 1000 for figure in printed["figures"])


def test_report_writes_into_a_fresh_folder_and_overwrites_nothing_without_force(tiny_report, tiny_presets, tmp_path, monkeypatch, capsys):
    folder, done = tiny_report
    assert (folder / "REPRODUCTION.md").read_text() == MINE  # the user's, in the folder the report ran from
    written = Path(json.loads(done.stdout)["report"])
    assert written.parent.parent == Path("runs") and written.parent.name.startswith("report-")
    monkeypatch.chdir(tmp_path)
    (tmp_path / "REPRODUCTION.md").write_text(MINE)
    assert main(["report", "--presets", str(tiny_presets), "--markdown", "REPRODUCTION.md"]) == ExitCode.OUTPUT_REFUSED
    assert "the report would overwrite REPRODUCTION.md" in capsys.readouterr().err
    assert (tmp_path / "REPRODUCTION.md").read_text() == MINE
    assert not (tmp_path / "runs").exists()  # refused before its default folder was made


def test_a_report_run_again_into_its_out_shows_the_wall_time_recorded_when_each_run_was_computed(tiny_report, tiny_presets, tmp_path):
    """Run again into the same --out, the runs read back were shown as '6 realizations in 0.00 s' (the
    time of reading them back), their summary.json rewritten with it: the recorded time is shown, kept."""
    folder, done = tiny_report
    out = tmp_path / "out"
    shutil.copytree(folder / Path(json.loads(done.stdout)["report"]).parent, out)
    summaries = {key: (out / key / "summary.json").read_bytes() for key in ("fig2", "fig3", "fig4")}
    again = run_cli("report", "--presets", tiny_presets, "--out", out, "--markdown", tmp_path / "again.md",
                    "--figures", tmp_path / "figures", "--quiet", "--workers", "1")  # fmt: skip
    assert again.returncode == ExitCode.OK, again.stderr
    text = (tmp_path / "again.md").read_text()
    for key, summary in summaries.items():
        assert (out / key / "summary.json").read_bytes() == summary  # read back, not rewritten
        took = json.loads(summary)["elapsed_seconds"]
        assert f"realizations in {took:.2f} s when computed (read back)" in text
    points = json.loads((out / "fig5" / "sweep.json").read_text())["points"]
    assert all(point["elapsed_s"] > 0 for point in points)  # each point's own time, kept (was 0.0)
    assert "were read back, not run again" in text


@pytest.mark.parametrize("linked", ["fig5", "figures"])
def test_a_link_at_a_figures_or_a_runs_folder_is_refused_before_anything_runs(tiny_presets, tmp_path, capsys, linked):
    """--out holding a link at fig5 (a figure's run folder) or figures/: the report wrote the run,
    or the PNGs, where the link pointed, outside --out. Refused before any figure runs."""
    out, elsewhere = tmp_path / "out", tmp_path / "elsewhere"
    out.mkdir()
    elsewhere.mkdir()
    (out / linked).symlink_to(elsewhere)
    assert main(["report", "--presets", str(tiny_presets), "--out", str(out), "--quiet"]) == ExitCode.OUTPUT_REFUSED
    err = capsys.readouterr().err
    assert f"{out / linked} is a symbolic link or not a folder, which is never followed: move it aside" in err
    assert not any(elsewhere.iterdir()) and sorted(p.name for p in out.iterdir()) == [linked]  # fig2 did not run


@pytest.mark.parametrize("blocked", ["REPRODUCTION.md", "figures/fig3.png"])
def test_a_report_file_that_is_a_folder_is_refused_before_the_runs_even_with_force(tiny_presets, tmp_path, capsys, blocked):
    """--force over an --out whose REPRODUCTION.md (or a figure) is a folder ran every figure,
    then ended with 'error: is a folder, not a file: ...' (exit code 1). Refused before any run."""
    out = tmp_path / "out"
    (out / blocked).mkdir(parents=True)
    assert main(["report", "--presets", str(tiny_presets), "--out", str(out), "--force", "--quiet"]) == ExitCode.OUTPUT_REFUSED
    err = capsys.readouterr().err
    assert f"{out / blocked} is a folder, not a file: the report writes its {Path(blocked).name} there; move it aside" in err
    assert not (out / "fig2").exists()


@pytest.fixture(scope="module")
def tiny_runs(tmp_path_factory, tiny_presets):
    return run_figures(tiny_presets, tmp_path_factory.mktemp("runs"), RunOptions(workers=1))


def test_readings_rerun_as_documented(tmp_path, tiny_presets, tiny_runs):
    runs = tiny_runs
    readings = (Reading("fig4", "same C0 as Fig. 2", same_c0_as="fig2"),
                Reading("fig2", "spectral", ("slope.name=spectral",)), Reading("fig2", "pooled", average="pooled"))  # fmt: skip
    rows = run_readings(runs, tmp_path, RunOptions(workers=1), readings=readings)
    c0 = runs[0].scene.spectrum.c0()
    assert rows[0].overrides[-1].startswith("spectrum.params.c0=")
    assert float(rows[0].overrides[-1].split("=")[1]) == pytest.approx(c0, rel=1e-5)
    for row in rows[:2]:  # each row reruns from its preset and --set options, as the table says
        preset = next(s.preset for s in FIGURES if s.key == row.reading.figure)
        data = apply_overrides(load_preset_file(tiny_presets / preset), row.overrides)
        outcome, _ = run_to_folder(build_scene(data), tmp_path / f"again-{row.reading.name}", RunOptions(workers=1))
        assert (outcome.fit.a, outcome.fit.b) == pytest.approx((row.fit.a, row.fit.b), rel=1e-12)
    pooled = average_curve(runs[0].outcome.per_realization, "pooled")
    assert rows[2].fit.a == pytest.approx(np.polyfit(np.log(runs[0].outcome.f), pooled, 1)[1], rel=1e-9)
    text = "\n".join(readings_markdown(rows))
    assert "`slope.name=spectral`" in text and f"{rows[1].fit.a:.4f}" in text
    summary = (tmp_path / "readings" / "02-fig2" / "summary.json").read_bytes()
    again = run_readings(runs, tmp_path, RunOptions(workers=1), readings=readings)  # the report run again: read back
    assert (tmp_path / "readings" / "02-fig2" / "summary.json").read_bytes() == summary  # not rewritten
    assert [(r.fit.a, r.fit.b) for r in again] == pytest.approx([(r.fit.a, r.fit.b) for r in rows], rel=1e-12)


def test_a_readings_folder_of_other_files_is_refused_saying_what_helps(tmp_path, tiny_runs):
    """A reading's folder holding files of the user's: its run's refusal advised --force, which the
    report never applies there (it replaces only what a run wrote); said as the report says it."""
    from frictionlab.errors import OutputRefused

    (tmp_path / "readings" / "01-fig2").mkdir(parents=True)
    (tmp_path / "readings" / "01-fig2" / "notes.txt").write_text("mine")
    for force in (False, True):
        with pytest.raises(OutputRefused) as refused:
            run_readings(tiny_runs, tmp_path, RunOptions(workers=1, force=force),
                         readings=(Reading("fig2", "spectral", ("slope.name=spectral",)),))  # fmt: skip
        said = str(refused.value)
        assert said.startswith(f"{tmp_path / 'readings' / '01-fig2'} holds files that no frictionlab run wrote ('notes.txt')")
        assert "--force or not; move them aside, or give another --out" in said and "force it (--force" not in said
    assert (tmp_path / "readings" / "01-fig2" / "notes.txt").read_text() == "mine"


def test_presets_folder_errors(tmp_path, capsys):
    with pytest.raises(Exception, match="no folder with the paper's presets"):
        find_presets(tmp_path)
    assert main(["report", "--presets", str(tmp_path), "--quiet"]) == 2
    assert "--presets: no folder with the paper's presets" in capsys.readouterr().err


def test_a_presets_folder_names_the_files_it_lacks_or_cannot_read(tmp_path, capsys):
    """The folder exists: which of the paper's presets is missing, or not a regular file."""
    os.mkfifo(tmp_path / FIGURES[1].preset)
    for fig in FIGURES[2:]:
        (tmp_path / fig.preset).write_text("name: x\n")
    assert main(["report", "--presets", str(tmp_path), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert f"{FIGURES[0].preset}: no such file; {FIGURES[1].preset}: is a FIFO (named pipe), not a regular file)" in err
    assert FIGURES[2].preset + ":" not in err  # the ones that are there are not named


def test_fig5_calibrated_at_each_hurst(tmp_path, tiny_presets, tiny_runs):
    fig5 = next(run for run in tiny_runs if run.sweep is not None)
    rows = run_readings(tiny_runs, tmp_path, RunOptions(workers=1), readings=fig5_calibrated_readings(fig5.sweep))
    assert [r.overrides[:2] for r in rows] == [["sweep=null", "spectrum.params.hurst=0.6"],
                                               ["sweep=null", "spectrum.params.hurst=1.0"]]  # fmt: skip
    targets = (COUNT_TARGETS[1.0], COUNT_TARGETS[20.0])
    for r in rows:  # each point's own lines hit Fig. 2's counts at F = 1 and 20
        assert r.loads == (1.0, 20.0)
        assert r.overrides[2] == f"spectrum.params.rms_height={r.rms_height!r}"
        # least squares in log balances the two misfits: geometric mean of count/target near 1
        # (6 lines: the mean count moves in steps of 1/6, hence the tolerance; h off by 1.5 gives ~1.2)
        assert math.sqrt(r.counts[0] / targets[0] * r.counts[1] / targets[1]) == pytest.approx(1.0, abs=0.12)
        assert r.counts == pytest.approx(targets, rel=0.35)
    # at fixed h the rougher line (smaller H) has fewer points near its top (the default
    # sweep's counts at h = 300), so it needs a smaller h for the same counts
    default = {row["spectrum.params.hurst"]: row for row in fig5.sweep_outcome.rows}
    assert default[0.6]["contact_last"] < default[1.0]["contact_last"]
    assert rows[0].rms_height < rows[1].rms_height / 1.5
    # a point reruns from the preset and its --set options, as the section says
    data = apply_overrides(load_preset_file(tiny_presets / fig5.preset_path.name), rows[0].overrides)
    outcome, _ = run_to_folder(build_scene(data), tmp_path / "again", RunOptions(workers=1))
    assert (outcome.fit.a, outcome.fit.b) == pytest.approx((rows[0].fit.a, rows[0].fit.b), rel=1e-12)
    text = "\n".join(fig5_calibrated_markdown(fig5, rows, "fig.png", elapsed=1.0))
    assert f"| 0.6 | {rows[0].rms_height:g} | {rows[0].fit.a:.4f} [{rows[0].fit.a_ci[0]:.4f}, {rows[0].fit.a_ci[1]:.4f}] |" in text
    at_one = next(line for line in text.splitlines() if line.startswith(f"| 1 | {rows[1].rms_height:g} | "))
    assert at_one.endswith("| Fig. 2: 1.8847, 0.0805 |")  # the paper's value at H = 1, Fig. 2's
    outside = not (rows[1].fit.a_ci[0] <= 1.8847 <= rows[1].fit.a_ci[1] and rows[1].fit.b_ci[0] <= 0.0805 <= rows[1].fit.b_ci[1])
    assert ("†" in at_one) == outside
    image = io.BytesIO()
    plot_fig5_calibrated(fig5, rows, image)
    assert image.getvalue().startswith(b"\x89PNG") and len(image.getvalue()) > 1000


def test_replicates_are_independent_runs_and_their_spread_is_theirs(tmp_path, tiny_presets, tiny_runs):
    """Each of K ensembles is the preset run with one of K seeds (the preset's, then one SeedSequence's):
    rerun alone with ``--set seed=...``, each gives the same fit; the spread and the count of ensembles
    holding the paper's pair are those of the K independent fits."""
    from frictionlab.preset.seeds import replicate_seeds

    reading = Reading("fig2", "literal, h measured, last point without slope",
                      ("spectrum.params.series=cosine", "spectrum.params.short_cutoff=20.0",
                       "spectrum.params.height_reference=measured", "slope.params.line_end=undefined"))  # fmt: skip
    (row,) = run_readings(tiny_runs, tmp_path, RunOptions(workers=1), readings=(reading,), replicates=4)
    seeds = replicate_seeds(2012, 4)
    assert row.seeds == seeds and seeds[0] == 2012 and len(set(seeds)) == 4
    data = load_preset_file(tiny_presets / "benad2012-fig2.yaml")
    fits = []
    for seed in seeds:
        scene = build_scene(apply_overrides(data, [*reading.overrides, f"seed={seed}"]))
        fits.append(engine.run(scene, RunOptions(workers=1)).fit)
    for mine, alone in zip(row.replicates, fits, strict=True):
        assert (mine.a, mine.b, mine.a_ci, mine.b_ci) == (alone.a, alone.b, alone.a_ci, alone.b_ci)
    assert row.fit is row.replicates[0]
    a = [fit.a for fit in fits]
    b = [fit.b for fit in fits]
    (a_mean, a_sd), (b_mean, b_sd) = row.spread()
    assert a_mean == pytest.approx(sum(a) / 4, rel=1e-12)
    assert a_sd == pytest.approx(math.sqrt(sum((x - a_mean) ** 2 for x in a) / 3), rel=1e-12)
    assert b_sd == pytest.approx(math.sqrt(sum((x - b_mean) ** 2 for x in b) / 3), rel=1e-12)
    assert a_sd > 0 and b_sd > 0  # the ensembles differ
    inside = lambda fit, pa, pb: fit.a_ci[0] <= pa <= fit.a_ci[1] and fit.b_ci[0] <= pb <= fit.b_ci[1]  # noqa: E731
    for pa, pb in ((fits[0].a, fits[0].b), (a_mean, b_mean), (10.0, 1.0)):
        assert row.holding(pa, pb) == sum(inside(fit, pa, pb) for fit in fits)
    assert row.holding(10.0, 1.0) == 0 and row.holding(fits[0].a, fits[0].b) >= 1
    text = "\n".join(readings_markdown([row]))
    assert "a, b between ensembles | paper inside |" in text
    assert f"{a_mean:.3f} ± {a_sd:.3f}, {b_mean:.4f} ± {b_sd:.4f} | {row.holding(1.8847, 0.0805)} of 4 |" in text
    assert "**Fig. 2: H = 1, F = 1..20**: closest reading: literal, h measured" in text


def test_replicates_need_readings(capsys):
    assert main(["report", "--replicates", "3", "--quiet"]) == 2
    assert "--replicates 3 needs --readings" in capsys.readouterr().err
    assert main(["report", "--readings", "--replicates", "0", "--quiet"]) == 2
    assert "--replicates must be a whole number from 1 to 100. Got 0 instead." in capsys.readouterr().err


def test_a_report_run_again_continues_its_stopped_and_finished_runs(tiny_presets, tmp_path, recwarn):
    """A report stopped part way (Ctrl-C in Fig. 2), run again into its --out, refused Fig. 2 ('an
    unfinished run: continue it with --resume', an option report lacks), and ran every finished
    figure again from its start; after `frictionlab resume` of Fig. 2, as its message said, too."""
    out = tmp_path / "out"
    run_figures(tiny_presets, out, RunOptions(workers=1))
    state = json.loads((out / "fig2" / "run.json").read_text())
    (out / "fig2" / "run.json").write_text(json.dumps({**state, "status": "interrupted"}))
    point = out / "fig5" / "points" / "01-hurst-0.6" / "summary.json"
    before = {path: path.read_bytes() for path in (point, out / "fig3" / "summary.json", out / "fig4" / "summary.json")}
    recwarn.clear()
    runs = run_figures(tiny_presets, out, RunOptions(workers=1))
    assert all((run.sweep_outcome or run.outcome).status == "completed" for run in runs)
    assert json.loads((out / "fig2" / "summary.json").read_text())["resumed_realizations"] == 6
    assert [bool(run.outcome.extra.get("read_back")) for run in runs[:3]] == [False, True, True]
    assert all(path.read_bytes() == held for path, held in before.items())  # finished runs read back, not run again
    assert not [w for w in recwarn if "runs again" in str(w.message)]
    run_figures(tiny_presets, out, RunOptions(workers=1, force=True))  # --force: every run afresh
    assert json.loads((out / "fig2" / "summary.json").read_text())["resumed_realizations"] == 0


def test_force_replaces_a_report_s_figures_never_a_figure_of_the_user_s(tiny_report, tmp_path, capsys):
    """--force wrote its fig2.png over a file of the user's in --figures (its help: never files
    it did not write). A figure the report drew, or one its own markdown shows, is replaced."""
    folder, done = tiny_report
    drawn = folder / Path(json.loads(done.stdout)["report"]).parent / "figures"
    mine, theirs = tmp_path / "mine", tmp_path / "theirs"
    shutil.copytree(drawn, theirs)
    mine.mkdir()
    (mine / "fig2.png").write_bytes(b"\x89PNG\r\n\x1a\n my own plot, drawn by hand")
    with pytest.raises(OutputRefused, match=r"fig2.png was not drawn by frictionlab report: .* --force or not"):
        report_paths(tmp_path / "out", tmp_path / "mine.md", mine, force=True)
    assert (mine / "fig2.png").read_bytes().endswith(b"drawn by hand")
    report_paths(tmp_path / "out", tmp_path / "again.md", theirs, force=True)  # each bears the report's mark
    capsys.readouterr()


def test_force_replaces_the_unmarked_figures_an_earlier_report_s_markdown_shows(tiny_report, tmp_path):
    """A report drawn before its figures carried a mark: its own markdown's image links name them."""
    folder, done = tiny_report
    report = Path(json.loads(done.stdout)["report"])
    figures = tmp_path / "figures"
    figures.mkdir()
    for name in ("fig2.png", "fig3.png"):
        (figures / name).write_bytes(b"\x89PNG\r\n\x1a\n an older report's figure, unmarked")
    markdown = tmp_path / "REPRODUCTION.md"
    shutil.copy(folder / report, markdown)  # links figures/fig2.png ... as a report in tmp_path would
    report_paths(tmp_path / "out", markdown, figures, force=True)
    markdown.write_text(markdown.read_text().replace("](figures/fig3.png)", "](elsewhere/fig3.png)"))
    with pytest.raises(OutputRefused, match=r"fig3.png was not drawn by frictionlab report"):
        report_paths(tmp_path / "out", markdown, figures, force=True)
