"""curve.csv writes each number as Python's repr of the float (ints as floats, 3.0),
and an empty cell where the number is NaN or infinite: the cells are formatted from
Python floats, column by column, with the text a cell-by-cell numpy formatting gave."""

from __future__ import annotations

import csv
import dataclasses
import io

import numpy as np

from frictionlab.compute import engine
from frictionlab.options import RunOptions
from frictionlab.runs.results import _write_curve


def cell(value) -> str:
    return "" if not np.isfinite(value) else repr(float(value))


def test_each_cell_is_the_float_s_repr_and_nan_or_inf_is_empty(make_scene):
    scene = make_scene({"realizations": 3})
    outcome = engine.run(scene, RunOptions(workers=1))
    xi = outcome.xi.copy()
    xi[0], xi[1], xi[2] = np.nan, np.inf, 1 / 3
    outcome = dataclasses.replace(outcome, xi=xi, half_load_points=None)
    fh = io.StringIO()
    _write_curve(scene, outcome, fh)
    rows = list(csv.reader(io.StringIO(fh.getvalue())))
    header, rows = rows[0], rows[1:]
    assert len(rows) == outcome.f.size
    column = {name.split(" [")[0]: [row[i] for row in rows] for i, name in enumerate(header)}
    assert column["xi"][:3] == ["", "", repr(1 / 3)]
    assert column["xi"][3:] == [cell(v) for v in xi[3:]]
    assert column["lines_used"] == [cell(v) for v in outcome.lines_used] and column["lines_used"][0].endswith(".0")
    assert column["contact_count"] == [cell(v) for v in outcome.contact_count]
    assert set(column["half_load_points"]) == {""}  # the solver does not say: NaN, an empty cell
