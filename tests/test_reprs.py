"""What a notebook shows of a result: the fit's table (rounded, with its intervals) and the curve."""

import base64
import dataclasses
import math
import re
from html.parser import HTMLParser

import numpy as np

import frictionlab
from frictionlab.compute.fit import LogFit

from .conftest import SMALL_PRESET

FAST = {"workers": 1, "progress": False}


class Cells(HTMLParser):
    """The text of every table cell and the source of every image, and whether the tags balance."""

    def __init__(self):
        super().__init__()
        self.cells, self.images, self.open, self.in_cell = [], [], [], False

    def handle_starttag(self, tag, attrs):
        if tag == "img":
            self.images.append(dict(attrs)["src"])
            return
        self.open.append(tag)
        if tag in ("td", "th"):
            self.cells.append("")
            self.in_cell = True

    def handle_endtag(self, tag):
        assert self.open.pop() == tag
        self.in_cell = self.in_cell and tag not in ("td", "th")

    def handle_data(self, data):
        if self.in_cell:
            self.cells[-1] += data


def parsed(html: str) -> Cells:
    cells = Cells()
    cells.feed(html)
    cells.close()
    assert cells.open == []
    return cells


def test_a_results_html_is_its_fit_rounded_with_intervals_and_its_curve():
    result = frictionlab.run(SMALL_PRESET, **FAST)
    html = result._repr_html_()
    cells = parsed(html).cells
    fit = result.fit
    level = f"{100 * fit.confidence:g}% CI (bootstrap {fit.bootstrap})"
    assert cells[:4] == ["xi = a + b ln f", "estimate", "std. err.", level]
    assert cells[4:8] == ["a", f"{fit.a:.4f}", f"{fit.standard_errors[0]:.4f}", f"[{fit.a_ci[0]:.4f}, {fit.a_ci[1]:.4f}]"]
    assert cells[8:12] == ["b", f"{fit.b:.4f}", f"{fit.standard_errors[1]:.4f}", f"[{fit.b_ci[0]:.4f}, {fit.b_ci[1]:.4f}]"]
    assert f"R² = {fit.r2:.4f}" in html and f"{result.realizations[0]}/{result.realizations[1]} realizations" in html
    (image,) = parsed(html).images
    png = base64.b64decode(image.removeprefix("data:image/png;base64,"))
    assert png.startswith(b"\x89PNG\r\n\x1a\n") and len(png) > 2000  # a drawn figure, not an empty one


def test_the_html_escapes_what_comes_from_data_and_says_when_there_is_no_fit():
    result = frictionlab.run(SMALL_PRESET, **FAST)
    odd = dataclasses.replace(result, caveats=["fewer than 3 points <b>in contact</b> & more"], fit=None,
                              table={name: np.array([]) for name in result.table})  # fmt: skip
    html = odd._repr_html_()
    assert "&lt;b&gt;in contact&lt;/b&gt; &amp; more" in html and "<b>" not in html
    assert "no fit" in html and "<table>" not in html and "<img" not in html
    parsed(html)


def test_a_fit_shows_rounded_and_keeps_its_exact_numbers():
    fit = LogFit(1.127512345678, 0.0312345678, a_ci=(1.035612, 1.234712), b_ci=(0.015812, 0.047612), bootstrap=500,
                 r2=0.841312345, points=40)  # fmt: skip
    text = repr(fit)
    assert text == ("LogFit(a = 1.1275 [1.0356, 1.2347], b = 0.0312 [0.0158, 0.0476] (95% CI, bootstrap 500); "
                    "R² = 0.8413, 40 points)")  # fmt: skip
    assert not re.search(r"\d{6}", text)  # no 16-digit floats
    assert fit.a == 1.127512345678  # the field itself is exact
    assert "n/a" in repr(LogFit(2.0, 0.1)) and math.isnan(LogFit(2.0, 0.1).r2)


def test_a_law_given_by_hand_shows_no_fitted_r2_or_points():
    text = repr(LogFit(1.1, 0.03, a_ci=(1.0, 1.2), b_ci=(0.02, 0.04)))
    assert text == "LogFit(a = 1.1000 [1.0000, 1.2000], b = 0.0300 [0.0200, 0.0400] (95% CI))"


def test_a_sweeps_html_is_a_row_per_point_with_its_values_and_fit(tmp_path):
    preset = {**SMALL_PRESET, "sweep": {"mode": "grid", "parameters": {"spectrum.params.hurst": {"values": [0.5, 0.8]}}}}
    sweep = frictionlab.run(preset, out=tmp_path / "sweep", plot=False, **FAST)
    cells = parsed(sweep._repr_html_()).cells
    assert cells[:6] == ["point", "spectrum.params.hurst", "status", "a", "b", "R²"]
    for row, shown in zip(sweep.rows, (cells[6:12], cells[12:18]), strict=True):
        a = f"{row['a']:.4f} [{row['a_lo']:.4f}, {row['a_hi']:.4f}]"
        assert shown == [str(row["point"]), str(row["spectrum.params.hurst"]), "completed", a,
                         f"{row['b']:.4f} [{row['b_lo']:.4f}, {row['b_hi']:.4f}]", f"{row['r2']:.4f}"]  # fmt: skip
    pending = dataclasses.replace(sweep, rows=[{**sweep.rows[0], "status": "pending", "a": None, "r2": None}])
    assert parsed(pending._repr_html_()).cells[6:] == ["1", "0.5", "pending", "n/a", cells[10], "n/a"]


def test_a_failed_point_of_a_sweep_says_why_in_its_row(tmp_path):
    """A point whose loads all press the same points fits no law: the notebook's table said
    "failed" and n/a, and the rows had lost the reason sweep.json keeps (the CLI lists it)."""
    preset = {**SMALL_PRESET, "loading": {**SMALL_PRESET["loading"], "start": 1e-30},
              "sweep": {"parameters": {"loading.stop": {"values": [1e-25, 20.0]}}}}  # fmt: skip
    sweep = frictionlab.run(preset, out=tmp_path / "sweep", plot=False, **FAST)
    failed, completed = sweep.rows
    assert failed["status"] == "failed" and failed["error"].startswith("no law: every load")
    assert completed["status"] == "completed" and completed["error"] is None
    cells = parsed(sweep._repr_html_()).cells
    assert cells[8] == f"failed: {failed['error']}" and cells[14] == "completed"
    assert frictionlab.load(tmp_path / "sweep").rows == sweep.rows


def test_a_measured_inputs_html_says_what_was_read_as_the_cli_does(tmp_path):
    """The CLI says the channel, unit and levelling read under its progress; the notebook's view
    said nothing of them. The file's name is data: escaped."""
    from html import escape

    from frictionlab.io.inputs import input_lines

    rng = np.random.default_rng(4)
    scan = tmp_path / "a<b>&c.csv"
    scan.write_text("\n".join(f"{z:.6f}" for z in np.cumsum(rng.standard_normal(256))) + "\n")
    preset = {**SMALL_PRESET, "spectrum": {"name": "profile-file", "params": {"path": str(scan), "spacing": 1.0}}}
    result = frictionlab.run(preset, **FAST, plot=False)
    html = result._repr_html_()
    lines = input_lines(result.input)
    assert lines and "a<b>&c.csv" in lines[0] and "a&lt;b&gt;&amp;c.csv" in html and "<b>" not in html
    assert all(escape(line) in html for line in lines)
    parsed(html)


def test_a_results_one_line_repr_stays_short_whatever_its_fit():
    """A forged (or absurd) summary.json read back: 1e300 is not 300 digits."""
    result = frictionlab.run(SMALL_PRESET, **FAST)
    huge = dataclasses.replace(result, fit=dataclasses.replace(result.fit, a=1e300, b=-2.5e7))
    text = repr(huge)
    assert "a = 1e+300, b = -2.5e+07" in text and len(text) < 200
    assert f"a = {result.fit.a:.4f}, b = {result.fit.b:.4f}" in repr(result)


def test_a_bad_mplbackend_is_named_by_plot_and_leaves_the_html_its_numbers(tmp_path):
    """matplotlib's import raises on it (a ValueError from deep inside): read in a fresh process."""
    import os
    import subprocess
    import sys

    frictionlab.run(SMALL_PRESET, out=tmp_path / "run", **FAST)
    code = (
        "import frictionlab\n"
        f"r = frictionlab.load({str(tmp_path / 'run')!r})\n"
        "try:\n    r.plot()\nexcept frictionlab.errors.FrictionlabError as exc:\n    print('plot:', exc)\n"
        "h = r._repr_html_()\nprint('html:', 'the curve is not drawn: MPLBACKEND' in h, f'{r.fit.a:.4f}' in h)\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          env={**os.environ, "MPLBACKEND": "no-such-backend"})  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert "plot: MPLBACKEND='no-such-backend' is no matplotlib backend; allowed:" in done.stdout
    assert "html: True True" in done.stdout
