"""What a measured map goes through between the file and the solver, each step a pure
function of the heights, one module each: levelling (``levelling``), removing spikes
(``spikes``), band-limited resampling onto square or coarser pixels (``resampling``), and
the caveats of heights that are not a surface's (``height_caveats``: outliers, steps,
clipping, flat maps; ``line_offsets``: a scanner's lines standing apart; ``edge_lines``: the
lines a scan starts or ends with, or a line's first or last points, carrying its slope), and
filling a table's points not measured (``filling``). Their public names are imported from here."""

from .edge_lines import edge_lines_warning, edge_points_warning
from .filling import fill_harmonic
from .height_caveats import FLAT, flat_neighbours_warning, flat_rms, outlier_warning
from .levelling import LEVELS, Levelling, level, level_line, levelling_warning, line_form_warning
from .line_offsets import line_offset_warning
from .resampling import cosine_resample, resampled_points
from .spikes import despike, line_spike_warning, spike_warning

__all__ = [
    "FLAT", "LEVELS", "Levelling", "cosine_resample", "despike", "edge_lines_warning", "edge_points_warning",
    "fill_harmonic", "flat_neighbours_warning", "flat_rms", "level", "level_line", "levelling_warning",
    "line_form_warning", "line_offset_warning", "line_spike_warning", "outlier_warning", "resampled_points",
    "spike_warning",
]  # fmt: skip
