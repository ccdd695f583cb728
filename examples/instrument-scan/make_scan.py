"""Write a synthetic instrument file to try frictionlab on: scan.x3p (ISO 25178-72 X3P),
a 128 x 128 self-affine map (H = 0.8) on pixels of 0.5 um, rms height 0.5 um, stored in
metres as X3P stores it. Needs the extra topography (pip install "frictionlab[topography]").

    python examples/instrument-scan/make_scan.py [FOLDER]   (default: beside this script)
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
from SurfaceTopography import Topography

from frictionlab_spectra import PowerLawSurface

PIXEL_UM, RMS_UM, POINTS = 0.5, 0.5, 128


def main(folder: Path) -> Path:
    surface = PowerLawSurface(hurst=0.8, points=POINTS, rms_height=RMS_UM, spacing=PIXEL_UM)
    z_um = surface.generate(np.random.default_rng(np.random.SeedSequence(2026))).heights
    # SurfaceTopography lays a map out as heights[x, y]: columns first
    scan = Topography(1e-6 * z_um.T, (1e-6 * PIXEL_UM * POINTS,) * 2, unit="m")
    path = folder / "scan.x3p"
    scan.to_x3p(str(path))
    print(f"wrote {path.name}: {POINTS} x {POINTS} pixels of {PIXEL_UM} um, rms height {np.std(z_um):.3f} um")
    return path


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).resolve().parent)
