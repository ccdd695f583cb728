"""The braille chart's axes: the numbers whole, however narrow the plot."""

import numpy as np
import pytest

from frictionlab.tui.chart import Series, render_chart


@pytest.mark.parametrize("width", [20, 26, 40, 80])
def test_the_f_range_is_whole_in_a_narrow_plot(width):
    """The Results plot at 60 columns (20 wide) showed `3.81e-06f (lo`: the upper end of f cut."""
    curve = Series(np.array([3.81e-6, 3.81e-4]), np.array([0.9, 1.0]), "")
    axis = "".join(text for text, _ in render_chart([curve], width, 6)[-1])
    low, high = axis.split()[0], axis.split()[-1]
    assert len(axis) == width
    assert (float(low), float(high)) == pytest.approx((3.81e-6, 3.81e-4), rel=1e-3)
    assert ("f (log)" in axis) == (width >= 40)
