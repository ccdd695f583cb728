"""RunOptions from Python: numpy's integers are whole numbers; other types are named."""

import numpy as np
import pytest

import frictionlab
from frictionlab.errors import FrictionlabError
from frictionlab.options import RunOptions

from .conftest import SMALL_PRESET


def test_numpy_integers_are_whole_numbers():
    options = RunOptions(workers=np.int64(2), retries=np.int32(1))
    assert (options.workers, options.retries) == (2, 1) and type(options.workers) is int
    result = frictionlab.run(SMALL_PRESET, workers=np.int64(1), progress=False)  # a count from an arange
    assert result.status == "completed"


@pytest.mark.parametrize("workers", [True, 2.0, "2", np.float64(2.0)])
def test_other_types_are_refused_by_name(workers):
    with pytest.raises(FrictionlabError, match=r"^workers must be a whole number >= 1\. Got .* instead\.$"):
        RunOptions(workers=workers)


@pytest.mark.parametrize("name", ["force", "resume", "memory_check", "dashboard"])
@pytest.mark.parametrize("value", ["no", 1, None])
def test_a_flag_that_is_not_a_bool_is_refused_by_name(name, value):
    """RunOptions(force="no"): a truthy string forced the write into a folder of the user's."""
    with pytest.raises(FrictionlabError, match=rf"^{name} must be True or False\. Got .* instead\.$"):
        RunOptions(**{name: value})
