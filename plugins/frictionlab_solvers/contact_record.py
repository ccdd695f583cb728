"""What the half-space solvers measure of the contact at each load of a sweep, filled load
by load and handed over as a ``ContactCurve``: one copy for the periodic and the free body,
which differ only in whether the surface's border joins its opposite side."""

from __future__ import annotations

import numpy as np

from frictionlab import ContactCurve, half_load_points

from .contact_area import contact_spots, corrected_area_fraction, corrected_gradient_rms


class ContactRecord:
    """The per-load arrays of a sweep of ``steps`` loads on ``points`` pixels. The corrected
    area, the real-contact gradient and the spot count are kept when asked for (None
    otherwise); at full contact they are 1, ``line_rms`` and one spot: no edge is left."""

    def __init__(self, steps: int, points: int, line_rms: float, *, corrected: bool, real_gradient: bool,
                 spots: bool, periodic: bool = True):  # fmt: skip
        self.points, self.line_rms, self.periodic = points, line_rms, periodic
        self.force, self.indentation = np.empty(steps), np.empty(steps)
        self.count, self.half = np.empty(steps, dtype=np.int64), np.empty(steps, dtype=np.int64)
        self.slope_rms = np.empty(steps)
        self.iterations, self.residual = np.zeros(steps, dtype=np.int64), np.zeros(steps)
        self.corrected = np.ones(steps) if corrected else None
        self.real_gradient = np.full(steps, line_rms) if real_gradient else None
        self.spots = np.ones(steps) if spots else None

    def measure(self, j: int, pressure: np.ndarray, slopes: np.ndarray) -> None:
        """The contact of load ``j``: the points of positive ``pressure``."""
        contact = pressure > 0.0
        n = int(np.count_nonzero(contact))
        self.count[j] = n
        self.half[j] = half_load_points(pressure)
        if n == self.points:  # xi = 1 to the last bit at full contact
            self.slope_rms[j] = self.line_rms
            return
        self.slope_rms[j] = float(np.sqrt(np.mean(np.square(slopes[contact]))))
        if self.corrected is not None:
            self.corrected[j] = corrected_area_fraction(contact, periodic=self.periodic)
        if self.real_gradient is not None:
            self.real_gradient[j] = corrected_gradient_rms(contact, slopes, periodic=self.periodic)
        if self.spots is not None:
            self.spots[j] = contact_spots(contact, periodic=self.periodic)

    def curve(self, **extras: np.ndarray) -> ContactCurve:
        """The sweep's curve; ``extras`` join the iterations and residual of every load."""
        return ContactCurve(
            force=self.force,
            indentation=self.indentation,
            contact_count=self.count,
            contact_fraction=self.count / self.points,
            slope_rms_contact=self.slope_rms,
            real_area_corrected=self.corrected,
            real_gradient_rms=self.real_gradient,
            contact_spots=self.spots,
            extras={"iterations": self.iterations, "residual": self.residual, **extras},
            half_load_points=self.half,
        )
