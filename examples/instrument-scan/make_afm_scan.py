"""Write a realistic AFM file to try frictionlab on: afm.gwy (Gwyddion), as a microscope
leaves it. Four channels of heights: "Height" twice (the trace and the retrace, a
little noisier), "Height Sensor" and "Z Sensor" (the scanner's own, smoother). The heights: a self-affine map (H = 0.8), rms 20 nm, 160 x 64 pixels
of 0.1 x 0.25 um (the slow axis coarser, 2.5:1), on a tilt of 1 in 200 along x, with a
2-pixel spike 15 rms high and 12 points left undefined (the tip lost contact).
Needs the extra topography (pip install "frictionlab[topography]").

    python examples/instrument-scan/make_afm_scan.py [FOLDER]   (default: beside this script)
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
from SurfaceTopography.IO.GWY import _gwy_write_object

from frictionlab_spectra import PowerLawSurface
from frictionlab_spectra.scan_shaping import cosine_resample

NX, NY, DX_UM, DY_UM, RMS_NM = 160, 64, 0.1, 0.25, 20.0


def heights_nm(seed: int = 2026) -> np.ndarray:
    """z[row, column] = z[y, x] in nm: roughness on pixels of DX_UM, sampled every DY_UM along y."""
    surface = PowerLawSurface(hurst=0.8, points=NX, rms_height=RMS_NM, spacing=DX_UM * 1e3)
    z = surface.generate(np.random.default_rng(np.random.SeedSequence(seed))).heights  # square, NX x NX
    z = cosine_resample(z, 0, DX_UM, DY_UM)[:NY]  # the slow axis: rows every DY_UM, the tip's low-pass

    x_nm = np.arange(NX) * DX_UM * 1e3
    z = z + x_nm[None, :] / 200.0  # the sample's tilt
    z[30, 70:72] += 15 * RMS_NM  # a spike: dust on the sample
    return z


def _field(values: np.ndarray, unit_z: str) -> tuple:
    """A GwyDataField of a map z[y, x] in SI units (Gwyddion stores metres, row by row along x)."""
    return ("o", ("GwyDataField", {
        "xres": ("i", NX), "yres": ("i", NY), "xreal": ("d", NX * DX_UM * 1e-6), "yreal": ("d", NY * DY_UM * 1e-6),
        "xoff": ("d", 0.0), "yoff": ("d", 0.0), "si_unit_xy": ("o", ("GwySIUnit", {"unitstr": ("s", "m")})),
        "si_unit_z": ("o", ("GwySIUnit", {"unitstr": ("s", unit_z)})), "data": ("D", values.astype("<f8").ravel()),
    }))  # fmt: skip


def main(folder: Path) -> Path:
    z = heights_nm()
    undefined = np.zeros(z.shape)
    undefined[50, 100:112] = 1.0  # the tip lost the surface for 12 points
    rng = np.random.default_rng(np.random.SeedSequence(7))
    container = {
        "/0/data/title": ("s", "Height"), "/0/data": _field(z * 1e-9, "m"), "/0/mask": _field(undefined, ""),
        "/1/data/title": ("s", "Height"), "/1/data": _field((z + rng.normal(0, 1.0, z.shape)) * 1e-9, "m"),
        "/2/data/title": ("s", "Height Sensor"), "/2/data": _field(0.9 * z * 1e-9, "m"),
        "/3/data/title": ("s", "Z Sensor"), "/3/data": _field(0.8 * z * 1e-9, "m"),
    }  # fmt: skip
    path = folder / "afm.gwy"
    with open(path, "wb") as fh:
        fh.write(b"GWYP")
        _gwy_write_object(fh, "GwyContainer", container)
    print(f"wrote {path.name}: 4 channels, {NX} x {NY} pixels of {DX_UM} x {DY_UM} um, rms roughness {RMS_NM:g} nm")
    return path


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).resolve().parent)
