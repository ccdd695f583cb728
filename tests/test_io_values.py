"""Numbers read back from JSON written by someone else: true and false are not numbers."""

import math

import pytest

from frictionlab.io.values import number_or_nan, whole_or


@pytest.mark.parametrize("value, expected", [(3, 3.0), (-2.5, -2.5), (0, 0.0)])
def test_a_number_reads_as_its_float(value, expected):
    assert number_or_nan(value) == expected
    assert isinstance(number_or_nan(value), float)


@pytest.mark.parametrize("value", [True, False, None, "1.0", [1.0], {"a": 1}])
def test_anything_else_reads_as_nan(value):
    assert math.isnan(number_or_nan(value))


@pytest.mark.parametrize("value", [0, 7, 10**12])
def test_a_whole_number_at_least_zero_is_kept(value):
    assert whole_or(value, -1) == value


@pytest.mark.parametrize("value", [True, False, -1, 2.0, None, "3"])
def test_anything_else_gives_the_default(value):
    assert whole_or(value, -1) == -1
    assert whole_or(value) == 0
