"""The plugin base contract: constructors only store validated parameters."""

import pytest
from pydantic import ValidationError

from frictionlab_solvers import MDRSprings
from frictionlab_spectra import PowerLaw


def test_constructor_stores_validated_params_from_kwargs_or_a_params_instance():
    by_kwargs = PowerLaw(hurst=0.7, points=512)
    by_params = PowerLaw(PowerLaw.Params(hurst=0.7, points=512))
    assert by_kwargs.params == by_params.params
    assert "hurst=0.7" in repr(by_kwargs)
    with pytest.raises(ValidationError, match="hurst"):
        PowerLaw(hurst=7.0, points=512)
    with pytest.raises(TypeError, match="either a Params instance or keyword arguments"):
        PowerLaw(PowerLaw.Params(hurst=0.7, points=512), hurst=0.5)
    with pytest.raises(TypeError, match="must be an instance of MDRSprings.Params. Got Params instead."):
        MDRSprings(PowerLaw.Params(hurst=0.7, points=512))


def test_a_rejected_edit_leaves_the_old_value():
    """Editing params in place (the TUI does) must never leave an invalid value,
    also when a check across fields (not the field's own bound) rejects it."""
    params = PowerLaw.Params(hurst=0.8, points=1024)
    with pytest.raises(ValidationError):
        params.short_cutoff = 1.0  # below the Nyquist limit of 2 dx: a model-level check
    assert params.short_cutoff is None
    with pytest.raises(ValidationError):
        params.hurst = 5.0  # the field's own bound
    assert params.hurst == 0.8
    params.short_cutoff = 20.0
    assert params.short_cutoff == 20.0
