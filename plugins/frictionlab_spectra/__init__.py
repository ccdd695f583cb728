"""Built-in spectrum generators of frictionlab."""

from frictionlab import hookimpl

from .power_law import PowerLaw, Rolloff
from .profile_file import ProfileFile
from .surface import PowerLawSurface, RolloffSurface
from .surface_file import SurfaceFile


@hookimpl
def register_spectra(register):
    register(PowerLaw)
    register(Rolloff)
    register(ProfileFile)
    register(PowerLawSurface)
    register(RolloffSurface)
    register(SurfaceFile)
