"""How a run's result shows in a notebook (``Result._repr_html_``): what a measured
input's file gave (as the CLI says it), the fit as a table with its intervals, rounded as the CLI prints it, and the curve as an inline image; a
sweep's (``SweepResult._repr_html_``): a row per point, its values and its fit.
Every text is escaped: a preset's name or a caveat is data, not markup."""

from __future__ import annotations

import base64
import html
import io
import math

from .compute.fit import format_interval, format_number
from .errors import FrictionlabError, refuse_unusable_matplotlib


def result_html(result) -> str:
    """A ``frictionlab.Result`` as HTML: status, what was read (a measured input), the fit's
    table, the curve, caveats."""
    done, requested = result.realizations
    parts = [
        f"<p><strong>{html.escape(result.name)}</strong>: {html.escape(result.status)}, "
        f"{done}/{requested} realizations in {result.elapsed:.2f} s</p>"
    ]
    if result.input:  # the channel, unit and levelling read: as the CLI says them under its progress
        from .io.inputs import input_lines

        parts.append("<p>" + "<br>".join(html.escape(line) for line in input_lines(result.input)) + "</p>")
    fit = result.fit
    if fit is None:  # why: a failed run says; an interrupted one may have finished none
        parts.append(f"<p>no fit: {html.escape(result.error or 'no realization finished')}</p>")
    else:
        level = f"{100 * fit.confidence:g}% CI" + (f" (bootstrap {fit.bootstrap})" if fit.bootstrap else "")
        rows = "".join(
            f"<tr><td>{name}</td><td>{format_number(value)}</td><td>{_number(se)}</td>"
            f"<td>{html.escape(format_interval(ci))}</td></tr>"
            for name, value, se, ci in (("a", fit.a, fit.standard_errors[0], fit.a_ci),
                                        ("b", fit.b, fit.standard_errors[1], fit.b_ci))
        )
        parts.append(
            "<table><thead><tr><th>xi = a + b ln f</th><th>estimate</th><th>std. err.</th>"
            f"<th>{html.escape(level)}</th></tr></thead><tbody>{rows}</tbody></table>"
        )
        parts.append(
            f"<p>R² = {_number(fit.r2)}, residual rms = {_number(fit.residual_rms)}, {fit.points} load steps; "
            f"{html.escape(result.normalisation)}</p>"
        )
    if len(result.table.get("f", ())):
        try:
            parts.append(f'<img alt="xi against f" src="data:image/png;base64,{_curve_png(result)}">')
        except FrictionlabError as exc:  # a bad MPLBACKEND (refuse_unusable_matplotlib): the numbers are still shown
            parts.append(f"<p>the curve is not drawn: {html.escape(str(exc))}</p>")
    parts += [f"<p>caveat: {html.escape(caveat)}</p>" for caveat in result.caveats if caveat != result.error]
    if result.folder is not None:
        parts.append(f"<p>results in <code>{html.escape(str(result.folder))}</code></p>")
    return "<div>" + "".join(parts) + "</div>"


def sweep_html(sweep) -> str:
    """A ``frictionlab.SweepResult`` as HTML: status, and a row per point with a and b in their intervals."""
    head = "".join(f"<th>{html.escape(name)}</th>" for name in ("point", *sweep.parameters, "status", "a", "b", "R²"))
    rows = "".join(
        "<tr>" + "".join(f"<td>{html.escape(str(cell))}</td>" for cell in (
            row.get("point"), *(row.get(name) for name in sweep.parameters), _status(row),
            _estimate(row, "a"), _estimate(row, "b"), _number(row.get("r2")),
        )) + "</tr>"
        for row in sweep.rows
    )  # fmt: skip
    return (
        f"<div><p><strong>{html.escape(sweep.name)}</strong>: sweep {html.escape(sweep.status)}, "
        f"{len(sweep.rows)} points in {sweep.elapsed:.2f} s; xi = a + b ln f at each</p>"
        f"<table><thead><tr>{head}</tr></thead><tbody>{rows}</tbody></table>"
        f"<p>results in <code>{html.escape(str(sweep.folder))}</code> (points/: a run folder each)</p></div>"
    )


def _status(row: dict) -> str:
    """A point's status, and why where it failed (as ``frictionlab run`` lists it)."""
    return f"{row.get('status')}: {row['error']}" if row.get("error") else str(row.get("status"))


def _estimate(row: dict, name: str) -> str:
    """A point's a or b with its interval, as sweep.csv holds them (None where unknown)."""
    value = row.get(name)
    if value is None:
        return "n/a"
    return f"{format_number(value)} {format_interval((row.get(name + '_lo'), row.get(name + '_hi')))}"


def _number(value: float | None) -> str:
    return format_number(value) if value is not None and math.isfinite(value) else "n/a"


def _curve_png(result) -> str:
    """``result.plot()`` on a bare figure (no pyplot: a notebook's backend is left alone), as base64 PNG."""
    refuse_unusable_matplotlib()
    from matplotlib.figure import Figure

    figure = Figure(figsize=(6.4, 4.2), layout="constrained")
    result.plot(figure.subplots())
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", dpi=72)
    return base64.b64encode(buffer.getvalue()).decode("ascii")
