"""Built-in contact solvers of frictionlab."""

from frictionlab import hookimpl

from .bem import BEMHalfPlane, BEMHalfSpace
from .bem_free import BEMHalfSpaceFree
from .springs import BisectionSprings, MDRSprings, WinklerSprings


@hookimpl
def register_solvers(register):
    register(MDRSprings)
    register(WinklerSprings)
    register(BisectionSprings)
    register(BEMHalfPlane)
    register(BEMHalfSpace)
    register(BEMHalfSpaceFree)
