"""The exact elastic half-space under a non-periodic surface: ``bem-halfspace-free``.

A measured scan is one piece of a larger surface, not one period of a periodic one.
Here the elastic body is an infinite half-space, loaded only inside the scan's
rectangle: the displacement of a pressure field is the convolution of the pressure
with the surface response to a uniform pressure on one pixel (Love 1929), and that
convolution is computed exactly, without wrapping, by one FFT of twice the scan's
size each way with the pressure padded with zeros (Hockney 1970). The contact
problem is the periodic solver's (``contact_cg.ProjectedCG``): only the elastic
operator differs, ``FreeHalfSpace``.

The half-space's mean mode is finite here, so the indentation is the true approach
of the rigid surface from its first touch, against the elastic body far from the
scan (which does not move): Hertz's d for a sphere. Every approach has a finite
force, so there is no full-contact limit as on a periodic body.
"""

from __future__ import annotations

from typing import ClassVar

import numpy as np

from frictionlab import ContactCurve, Control, ForceNormalisation, Profile, SolveFailed, load_finished, mdr_length

from .arrays import host, namespace, on_device
from .bem import PeriodicBEM
from .checks import check_control, check_loads, check_profile
from .contact_area import YASTREBOV_ANCIAUX_MOLINARI
from .contact_cg import next_pressure, solve_load
from .contact_record import ContactRecord
from .elastic import FFTPair, PeriodicHalfSpace

LOVE = "Love, Phil. Trans. R. Soc. A 228 (1929) 377"
HOCKNEY = "Hockney, Methods Comput. Phys. 9 (1970) 135"


def pixel_influence(shape: tuple[int, int]) -> np.ndarray:
    """Displacement at pixel centres of a unit pressure on the pixel at the origin, on the
    padded (2 Ny, 2 Nx) grid in FFT order (offsets 0..N-1 then -N..-1); pixels of side 1,
    E* = 1. Love's closed form for a uniform pressure on a rectangle |x| < a, |y| < b
    (Johnson, Contact Mechanics, 3.25), u = F(x, y) / pi with the sum of four terms
    (x + a) ln[(y + b + r++) / (y - b + r+-)] and its mirror images."""
    offsets = [np.fft.fftfreq(2 * n, 1.0 / (2 * n)) for n in shape]
    y, x = np.meshgrid(*offsets, indexing="ij", sparse=True)
    a = b = 0.5

    def y_plus_r(x_side, y):
        # y + sqrt(x^2 + y^2) without cancellation where y < 0 (far from the pixel on that side)
        r = np.hypot(x_side, y)
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(y >= 0, y + r, np.square(x_side) / (r - y))

    def term(x_side, y_plus, y_minus):
        # x_side * ln((y_plus + r(x_side, y_plus)) / (y_minus + r(x_side, y_minus))), zero where x_side is
        with np.errstate(divide="ignore", invalid="ignore"):
            value = x_side * np.log(y_plus_r(x_side, y_plus) / y_plus_r(x_side, y_minus))
        return np.where(x_side == 0.0, 0.0, value)

    total = (
        term(x + a, y + b, y - b) + term(y + b, x + a, x - a)
        + term(x - a, y - b, y + b) + term(y - b, x - a, x + a)
    )  # fmt: skip
    return total / np.pi


class FreeHalfSpace:
    """The elastic operator (``elastic.ElasticOperator``) of a half-space loaded only on a
    (Ny, Nx) grid: the displacement of a pressure field is its linear (not circular)
    convolution with ``pixel_influence``, by zero-padded FFTs. Displacements are measured
    from the body far away, so a uniform pressure moves the surface by a finite amount.

    The preconditioner is the periodic half-space's stiffness ``|q| / 2`` on the grid
    itself, the inverse of this operator away from the edges, with the mean mode, which
    the periodic body leaves out, given the stiffness of this body under a uniform
    pressure: the mean pressure does move a free surface (an approach under indentation
    control needs it)."""

    def __init__(self, shape: tuple[int, int], xp=None, workers: int = 1):
        if len(shape) != 2:
            raise ValueError("the free-boundary half-space presses surfaces (2D height maps) only")
        self.shape = tuple(shape)
        self.axes = (0, 1)
        self.padded_shape = tuple(2 * n for n in self.shape)
        self.periodic = PeriodicHalfSpace(self.shape, xp, workers)
        self.xp = xp = self.periodic.xp
        self.pair = FFTPair(self.padded_shape, xp, workers)
        influence = pixel_influence(self.shape)
        # the influence is even in both offsets, so its spectrum is real: half the memory
        self.compliance = on_device(xp, np.fft.rfftn(influence).real)
        self.point_stiffness = 1.0 / float(influence[0, 0])
        self.padded = xp.zeros(self.padded_shape, dtype=xp.float64)  # the pressure on its quarter, zero elsewhere
        self.window = tuple(slice(0, n) for n in self.shape)
        uniform = self.displacement(xp.ones(self.shape, dtype=xp.float64), xp.empty(self.shape, dtype=xp.float64))
        self.mean_stiffness = 1.0 / float(xp.mean(uniform))  # uniform pressure per unit of mean displacement

    def displacement(self, pressure, out):
        """Surface displacement under ``pressure`` (loads outside the grid: none), into ``out``."""
        self.padded[self.window] = pressure
        out[...] = self.pair.apply(self.compliance, self.padded)[self.window]
        return out

    def displacement_estimate(self, pressure: np.ndarray, out: np.ndarray) -> np.ndarray:
        """``displacement`` itself (the padded FFTs in double precision)."""
        return self.displacement(pressure, out)

    def precondition(self, residual: np.ndarray, out: np.ndarray) -> np.ndarray:
        """``|q| / 2`` on the fluctuation of ``residual`` (zero mean), ``mean_stiffness`` on its mean."""
        mean = float(self.xp.mean(residual))  # before ``out``, which may be ``residual`` itself, is written
        self.periodic.precondition(residual, out)
        out += self.mean_stiffness * mean
        return out


class BEMHalfSpaceFree(PeriodicBEM):
    name: ClassVar[str] = "bem-halfspace-free"
    summary: ClassVar[str] = (
        "exact elastic half-space under a non-periodic surface (a scan): zero-padded FFT boundary elements, "
        "preconditioned projected CG"
    )
    references: ClassVar[tuple[str, ...]] = PeriodicBEM.references + (LOVE, HOCKNEY, YASTREBOV_ANCIAUX_MOLINARI)
    dimensions: ClassVar[tuple[int, ...]] = (2,)
    normalisations = {2: ForceNormalisation(load="force", modulus="E*", extent="mdr length", pressure_area="profile")}
    # the perimeter correction counts the edges inside the scan only: its border is no contact edge
    corrected_area: ClassVar[bool] = True
    # The CG's single-precision steps hold pressures (in units of E* s / dx) up to 3.4e38 and
    # overflow from f ~ 1e38 on (measured on 32^2 to 256^2 scans); 1e30 leaves 8 decades for
    # the grid's size. Full contact comes near f ~ 1: no physical load comes near.
    max_f: ClassVar[float | None] = 1e30
    problem: ClassVar[str] = "elastic half-space"
    indentation_reference: ClassVar[str] = "undeformed body"
    mean_displacement_known: ClassVar[bool] = False  # per surface: extras["mean_displacement"]
    periodic_only: ClassVar[bool] = False
    real_gradient: ClassVar[bool] = True
    counts_spots: ClassVar[bool] = True
    # measured 315 B per point (tracemalloc, 256^2 surfaces from first contact to full contact:
    # the CG's grids, the padded pressure, response and their spectra, four times the scan's
    # points each, and the preconditioner's periodic kernels), plus 20 %
    bytes_per_point: ClassVar[int | None] = 378

    def solve(self, profile: Profile, loads: np.ndarray, control: Control, slopes: np.ndarray) -> ContactCurve:
        """Every load of the sweep on the scan as it is (a periodic profile is pressed as one
        patch too). ``extras["mean_displacement"]``: the mean elastic displacement over the
        scan at each load, the shift from this solver's indentation to the approach to the
        mean deformed surface."""
        check_control(control)
        loads = check_loads(loads, control)
        heights, slopes, spacing = check_profile(self, profile, slopes)
        if not np.isfinite(heights).all():
            raise ValueError("heights must be finite")
        points = heights.size
        depth = heights.max() - heights
        scale = float(depth.max())  # the height range s
        force_unit = self.stiffness() * scale * spacing * points  # (scaled mean pressure) E* s / dx x area
        line_rms = float(np.sqrt(np.mean(np.square(slopes))))
        steps = loads.size
        record = ContactRecord(steps, points, line_rms, corrected=True, real_gradient=True, spots=True, periodic=False)
        shift = np.zeros(steps)
        if scale == 0.0:
            raise SolveFailed("the profile is flat: a flat punch has no contact to resolve; give a rough surface")
        if control == "force":  # f of this surface: its own rms height h, L = 2 sqrt(A / pi)
            limit = self.max_f * self.stiffness() * float(np.std(heights)) * mdr_length(profile.area)
            if float(loads.max()) > limit:
                raise SolveFailed(
                    f"load {float(loads.max()):g} is past what {self.name}'s single-precision steps hold: "
                    f"f = F / (E* h L) <= {self.max_f:g}, F <= {limit:.6g} on this surface"
                )
        elif float(loads.max()) > self.max_f * scale:  # the pressures of an approach of d grow as E* d / dx
            raise SolveFailed(
                f"indentation {float(loads.max()):g} is past what {self.name}'s single-precision steps hold: "
                f"at most {self.max_f:g} times the height range, {self.max_f * scale:.6g} on this surface"
            )
        depth /= scale
        operator = FreeHalfSpace(depth.shape, namespace(self.params.device), self.params.fft_workers)
        cg = self.contact_cg(operator, depth)
        tolerance, max_iterations = self.params.tolerance, self.params.max_iterations
        certified = self.params.stop == "certified"  # under force control only (solve_load)
        pressure, previous = None, 1.0
        for j, load in enumerate(loads):
            target = load / force_unit if control == "force" else load / scale
            pressure = next_pressure(pressure, previous, target, control, depth)
            previous = target
            pressure, approach, record.iterations[j], record.residual[j] = solve_load(
                cg, self.name, j, load, pressure, target, control, tolerance, max_iterations, certified
            )
            record.measure(j, pressure, slopes)  # a scan's border is no edge of its contact
            record.force[j] = load if control == "force" else float(pressure.mean()) * force_unit
            record.indentation[j] = approach * scale if control == "force" else load
            shift[j] = float(np.mean(host(cg.gap) - depth)) * scale  # the exact gap holds the displacement
            load_finished(j + 1, steps)
        return record.curve(mean_displacement=shift)

    def full_contact_load(self, profile: Profile) -> float | None:
        """Not known short of a solve: the border of a free scan carries the most pressure."""
        return None

    def full_contact_indentation(self, profile: Profile) -> float | None:
        """None: a free body takes any indentation, the force growing without bound."""
        return None
