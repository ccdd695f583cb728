"""What the trade-off study writes: study.csv, study.md, study.png."""


import csv
import math

import matplotlib.image
import pytest

from frictionlab.tradeoff import outputs as report
from frictionlab.tradeoff.axes import COLUMNS
from frictionlab.tradeoff.options import AXES

# ------------------------------------------------------------------ outputs


def test_outputs_are_written_and_parse(tiny_study, tmp_path):
    text = report.recommendation(tiny_study)
    assert text.startswith("for 2% error in b at H = 0.8: mdr needs N = ")
    files = report.write_outputs(tiny_study, tmp_path, text, command="frictionlab study x.yaml")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["study.csv", "study.md", "study.png"]
    with open(files["csv"], newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert tuple(rows[0]) == COLUMNS and len(rows) == len(tiny_study.rows)
    for parsed, row in zip(rows, tiny_study.rows):
        assert parsed["axis"] == row.axis and float(parsed["seconds"]) == row.seconds
        assert parsed["b_err"] == ("" if math.isnan(row.b_err) else repr(row.b_err))
    markdown = files["md"].read_text()
    for axis in AXES:
        assert f"## {axis}\n\n| " in markdown
    table_lines = [line for line in markdown.splitlines() if line.startswith("| ") and not line.startswith("| N ")]
    assert sum(1 for line in table_lines if line[2].isdigit() or line.startswith("| **") or line[2:5] in ("mdr", "win")) >= len(tiny_study.rows)
    assert text in markdown and "`frictionlab study x.yaml`" in markdown
    image = matplotlib.image.imread(files["png"])
    assert image.ndim == 3 and image.shape[0] > 100


def test_a_failed_write_leaves_no_partial_file(tiny_study, tmp_path, monkeypatch):
    def broken(study, fh):
        fh.write(b"\x89PNG half")
        raise RuntimeError("disk full")

    monkeypatch.setattr(report, "plot", broken)
    with pytest.raises(RuntimeError):
        report.write_outputs(tiny_study, tmp_path, "text")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["study.csv"]  # written before; no png, no temp file
