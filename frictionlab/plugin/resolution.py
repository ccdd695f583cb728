"""How many pixels a spectrum's short cut-off needs before xi stops depending on the grid.

The contact spots of the lightest loads are a few short cut-off wavelengths apart and a
pixel or two wide when that wavelength spans few pixels: then xi measures the grid. The
thresholds and the changes quoted in the caveat were measured with the same spectrum on
ever finer grids (docs/explanation/physics.md, "Pixels on the short cut-off").
"""

from __future__ import annotations

# the fewest pixels on the short cut-off that no caveat flags, by the profile's dimension: xi is
# within about 5 % of its 32-pixel value from 8 on for lines (MDR; 3 % at f >= 1e-3) and only from
# 16 on for surfaces (exact half-space; 8 pixels: 30 % above it at f = 0.01)
MIN_SHORT_CUTOFF_PIXELS = {1: 8, 2: 16}

# what xi did on finer grids, as measured, by dimension (the caveat quotes it)
_MEASURED = {
    1: "on MDR lines at H = 0.3 and f = 1e-4 it fell by 15 % from 4 to 8 pixels and by 8 % more up to 32",
    2: "on exact half-space surfaces at H = 0.5 and f = 0.01 it fell by 22 % from 4 to 8 pixels "
       "and by 15 % more from 8 to 16",
}  # fmt: skip


def short_cutoff_caveat(pixels: float, dimension: int) -> str | None:
    """The caveat of a spectrum whose short cut-off wavelength spans ``pixels`` grid
    spacings on a profile of ``dimension`` (1: a line, 2: a surface); None when that is
    enough (``MIN_SHORT_CUTOFF_PIXELS``)."""
    least = MIN_SHORT_CUTOFF_PIXELS[dimension]
    if pixels >= least * (1 - 1e-9):
        return None
    return (f"the short cut-off spans {pixels:.3g} pixels: contact spots are a pixel or two wide and xi depends "
            f"on the grid ({_MEASURED[dimension]}); put {least} or more pixels on it")  # fmt: skip
