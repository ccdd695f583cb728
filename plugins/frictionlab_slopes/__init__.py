"""Built-in slope estimators of frictionlab."""

from frictionlab import hookimpl

from .estimators import CentralDifference, ForwardDifference, Spectral


@hookimpl
def register_slope_estimators(register):
    register(ForwardDifference)
    register(CentralDifference)
    register(Spectral)
