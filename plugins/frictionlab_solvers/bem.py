"""Exact elastic references: a rigid periodic rough line on an elastic
half-plane (plane strain) or surface on an elastic half-space, solved by the
boundary element method.

The elastic surface answers a pressure p with the displacement
``u_q = 2 p_q / (E* |q|)`` in Fourier space (surface stiffness ``E* |q| / 2``,
``|q|`` the wave-vector norm of the line or surface). The mean mode q = 0 of a
periodic half-space has no finite stiffness; it is the rigid-body level, and
displacements are taken with zero mean. The contact problem (gap >= 0,
pressure >= 0, one of them zero at every point) is solved by a preconditioned
projected conjugate gradient (:mod:`.contact_cg`), the constrained CG of
Polonsky & Keer (1999) with the surface stiffness as preconditioner: at
prescribed mean pressure (force control) or at prescribed rigid-body approach
(indentation control).

Everything is computed in scaled variables: depths below the top
``u_i = (max z - z_i) / s`` with ``s`` the height range, lengths in pixels,
pressures in units of ``E* s / dx``. The answer is therefore the same for
heights of any scale, and the indentation ``d = max(z) - c`` (the level c
where the gap closes) is formed from depths, without cancellation.

Indentation is the approach of the rigid body to the *mean* elastic surface,
measured from the first touch: it grows with load up to ``max z - mean z``,
reached at full contact, and no finite force pushes past it.
"""

from __future__ import annotations

import math
from typing import ClassVar, Literal

import numpy as np
from pydantic import Field, field_validator

from frictionlab import ContactCurve, ContactSolver, Control, ForceNormalisation, Profile, SolveFailed, load_finished

from .arrays import namespace
from .checks import check_control, check_loads, check_profile
from .contact_area import YASTREBOV_ANCIAUX_MOLINARI
from .contact_cg import ProjectedCG, next_pressure, solve_load
from .contact_record import ContactRecord
from .elastic import ElasticParams, PeriodicHalfSpace, elastic_stiffness

POLONSKY_KEER = "10.1016/S0043-1648(99)00113-1"  # Wear 231 (1999) 206

__all__ = ["BEMHalfPlane", "BEMHalfSpace", "PeriodicBEM"]


# -------------------------------------------------------------------- plugins


class PeriodicBEM(ContactSolver):
    """Shared solver of the half-plane and half-space plugins: they differ only
    in the dimension of the wave vectors (and so of the profile)."""

    references: ClassVar[tuple[str, ...]] = (POLONSKY_KEER,)
    indentation_reference: ClassVar[str] = "mean surface"
    periodic_only: ClassVar[bool] = True
    body_params: ClassVar[tuple[str, ...]] = ("youngs_modulus", "poisson_ratio")
    tolerance_param: ClassVar[str | None] = "tolerance"
    # measured 184 B per point (tracemalloc, 128^2 to 512^2 surfaces pressed up to full contact:
    # the CG's grids, the FFT buffers of both precisions, the full-contact pressure, index arrays), plus 20 %
    bytes_per_point: ClassVar[int | None] = 224

    class Params(ElasticParams):
        tolerance: float = Field(
            1e-8,
            ge=1e-14,
            le=0.1,
            allow_inf_nan=False,
            description="relative residual: largest gap error on contact points or penetration elsewhere, over the rms height; "
            "with stop: certified a load may end before it (its indentation within 1e-4): set stop: tolerance to hold it",
        )
        max_iterations: int = Field(
            10_000, ge=1, le=10_000_000, description="conjugate-gradient steps allowed per load before giving up"
        )
        stop: Literal["certified", "tolerance"] = Field(
            "certified",
            description="when a load is solved: 'tolerance' once the residual is at most the tolerance; "
            "'certified' (force control only) also as soon as the contact set is certified (unchanged for 2 "
            "steps, every point's pressure or gap 10 times its last change): the contact set is final, the "
            "indentation only as converged as the residual reached (within 1e-4 relative)",
        )
        device: Literal["cpu", "gpu"] = Field(
            "cpu",
            description="where the FFTs and the CG run: 'cpu' (numpy) or 'gpu' (CuPy on the first CUDA GPU; "
            "needs CuPy and a GPU, refused otherwise)",
        )
        fft_workers: int = Field(
            1,
            ge=1,
            le=256,
            description="threads of each FFT on the CPU: 1 when realizations run side by side; the machine's "
            "cores for a one-realization run",
        )

        @field_validator("device")
        @classmethod
        def _device_there(cls, device: str) -> str:
            namespace(device)  # 'gpu' without CuPy or without a GPU: refused here, saying which is missing
            return device

    # the contact CG: ProjectedCG, or a class with its constructor and solve (the benchmark's baseline)
    contact_cg: ClassVar[type] = ProjectedCG

    def stiffness(self) -> float:
        """E* = E / (1 - nu^2)."""
        return elastic_stiffness(self.params)

    def solve(
        self, profile: Profile, loads: np.ndarray, control: Control, slopes: np.ndarray
    ) -> ContactCurve:
        check_control(control)
        loads = check_loads(loads, control)
        heights, slopes, spacing = check_profile(self, profile, slopes)
        if not profile.periodic:
            raise SolveFailed(
                f"{self.name} presses periodic profiles only, and this one is not (a scan whose ends do not "
                "meet). Make it periodic (remove its tilt, check that its ends meet, then set the spectrum's "
                "periodic: true) or press it with a solver of independent springs (mdr, winkler)."
            )
        if not np.isfinite(heights).all():
            raise ValueError("heights must be finite")
        points = heights.size
        depth = heights.max() - heights
        scale = float(depth.max())  # the height range s
        # F = (scaled mean pressure) * force_unit: pressure unit E* s / dx times the area
        force_unit = self.stiffness() * scale * spacing ** (heights.ndim - 1) * points
        line_rms = float(np.sqrt(np.mean(np.square(slopes))))  # as the engine forms it

        steps = loads.size
        record = ContactRecord(steps, points, line_rms, corrected=self.corrected_area, real_gradient=self.real_gradient,
                               spots=self.counts_spots)  # fmt: skip

        if scale == 0.0:  # a flat profile: every load presses every point evenly
            if control == "indentation":
                raise SolveFailed(
                    "the profile is flat: it touches everywhere at once, so any indentation past "
                    "the first touch needs an infinite force. Use control 'force'."
                )
            record.force[:], record.indentation[:] = loads, 0.0
            record.count[:], record.slope_rms[:] = points, line_rms
            record.half[:] = (points + 1) // 2  # an even pressure: half the points carry half the load
            return record.curve()

        depth /= scale
        operator = PeriodicHalfSpace(depth.shape, namespace(self.params.device), self.params.fft_workers)
        cg = self.contact_cg(operator, depth)
        full_approach = float(depth.mean())  # scaled max z - mean z (full_contact_indentation)
        tolerance, max_iterations = self.params.tolerance, self.params.max_iterations
        certified = self.params.stop == "certified"  # under force control only (solve_load)
        if control == "indentation":
            too_deep = np.flatnonzero(loads / scale >= full_approach)
            if too_deep.size:
                j = int(too_deep[0])
                raise SolveFailed(
                    f"indentation {float(loads[j])!r} (load {j}) is at or past the full-contact approach "
                    f"max(z) - mean(z) = {full_approach * scale:.6g}: on a periodic elastic body the "
                    "approach to the mean surface saturates at full contact, and no finite force "
                    "reaches it. Use control 'force' or smaller indentations."
                )
        else:
            # the pressure that closes every gap: (stiffness) (z - mean z), heights minus depths
            full_fluctuation = operator.pressure_of(-depth)
            full_threshold = -float(full_fluctuation.min())  # mean pressure of full contact

        pressure = None  # the solution at the previous load, `previous`
        previous = 1.0
        for j, load in enumerate(loads):
            target = load / force_unit if control == "force" else load / scale
            if control == "force" and target > full_threshold:
                pressure = full_fluctuation + target  # exact; the CG only checks it
            else:
                pressure = next_pressure(pressure, previous, target, control, depth)
            previous = target
            pressure, approach, record.iterations[j], record.residual[j] = solve_load(
                cg, self.name, j, load, pressure, target, control, tolerance, max_iterations, certified
            )
            record.measure(j, pressure, slopes)
            if control == "force":
                record.force[j] = load
                record.indentation[j] = approach * scale
            else:
                record.force[j] = float(pressure.mean()) * force_unit
                record.indentation[j] = load
            load_finished(j + 1, steps)  # a load of a large surface takes seconds: progress per load
        return record.curve()

    def full_contact_load(self, profile: Profile) -> float | None:
        """The load whose uniform part, added to the pressure that flattens the periodic
        profile, leaves no pressure negative (exact: the solver's own full-contact threshold)."""
        heights = np.asarray(profile.heights, dtype=float)
        depth = heights.max() - heights
        scale = float(depth.max())
        if not profile.periodic or not np.isfinite(scale) or heights.ndim not in self.dimensions:
            return None
        if scale == 0.0:
            return 0.0  # flat: every point touches at once
        force_unit = self.stiffness() * scale * profile.spacing ** (heights.ndim - 1) * heights.size
        return -float(PeriodicHalfSpace(depth.shape).pressure_of(-depth / scale).min()) * force_unit

    def full_contact_indentation(self, profile: Profile) -> float | None:
        """max z - mean z: on a periodic body the approach to the mean surface saturates there,
        at full contact, which no finite force reaches."""
        heights = np.asarray(profile.heights, dtype=float)
        approach = float(heights.max() - heights.mean())
        return approach if profile.periodic and math.isfinite(approach) and approach > 0 else None


class BEMHalfPlane(PeriodicBEM):
    name: ClassVar[str] = "bem-halfplane"
    summary: ClassVar[str] = (
        "exact elastic half-plane (plane strain) under a periodic line: FFT boundary elements, preconditioned CG"
    )
    dimensions: ClassVar[tuple[int, ...]] = (1,)
    # plane strain: the line is a ridged surface, straight in depth; its load is a force per unit depth
    normalisations = {
        1: ForceNormalisation(load="force per unit depth", modulus="E*", extent="one", pressure_area="profile")
    }
    problem: ClassVar[str] = "elastic half-plane (plane strain)"


class BEMHalfSpace(PeriodicBEM):
    name: ClassVar[str] = "bem-halfspace"
    summary: ClassVar[str] = (
        "exact elastic half-space under a periodic surface: FFT boundary elements, preconditioned CG"
    )
    dimensions: ClassVar[tuple[int, ...]] = (2,)
    normalisations = {2: ForceNormalisation(load="force", modulus="E*", extent="mdr length", pressure_area="profile")}
    problem: ClassVar[str] = "elastic half-space"
    references: ClassVar[tuple[str, ...]] = (POLONSKY_KEER, YASTREBOV_ANCIAUX_MOLINARI)
    # the pixel count's perimeter correction (contact_area.py) is derived for a surface's pixel edges
    corrected_area: ClassVar[bool] = True
    real_gradient: ClassVar[bool] = True
    counts_spots: ClassVar[bool] = True
