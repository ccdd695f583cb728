"""Real scans as a user brings them, written here: a tilted map, pixels 0.06 % apart, pixels
of 2.5:1, a file of four channels, an instrument's CSV export; each pressed to a law by MDR
and by the exact free half-space. And files a reader must refuse from what they declare."""

from __future__ import annotations

import json
import math
import runpy
import struct
import warnings
import zipfile

import numpy as np
import pytest
import x3pio
import yaml
from scipy.io import netcdf_file

from frictionlab.cli import main
from frictionlab.compute import memory
from frictionlab.errors import ExitCode
from frictionlab_spectra import PowerLawSurface, ProfileFile, SurfaceFile

from .conftest import ROOT


def rough_um(n: int, rms: float = 0.05, seed: int = 4) -> np.ndarray:
    surface = PowerLawSurface(hurst=0.8, points=n, rms_height=rms, spacing=0.125)
    return surface.generate(np.random.default_rng(np.random.SeedSequence(seed))).heights


def tilted_x3p(path, tilt: float = 0.05):
    z = rough_um(64)
    x = np.arange(64) * 0.125
    x3pio.write(path, (z + tilt * x[None, :]) * 1e-6, x_scale=0.125e-6, y_scale=0.125e-6,
                revision=x3pio.Revision.ISO5436_2000)  # fmt: skip


def rectangular_x3p(path):
    """0.128 x 0.315 um pixels (the X3P the issue names): the coarse rows of a finer map."""
    z = rough_um(128)[::2, :64][:40]
    x3pio.write(path, z * 1e-6, x_scale=0.128e-6, y_scale=0.315e-6, revision=x3pio.Revision.ISO5436_2000)


def near_square_nc(path):
    """NT-MDT's 1.85339 x 1.85455 (0.06 % apart), in nm, as NetCDF."""
    from SurfaceTopography import Topography  # here, not at the top: its import takes seconds, paid only where a test writes such a file

    z = rough_um(64) * 1e3 * 40
    topography = Topography(z.T.copy(), (64 * 1.85339, 64 * 1.85455), unit="nm")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        topography.to_netcdf(str(path))


def four_channel_gwy(path):
    script = runpy.run_path(str(ROOT / "examples" / "instrument-scan" / "make_afm_scan.py"))
    return script["main"](path.parent)


def csv_export(path):
    """x, y, z triples, one per line: the XYZ export of a profilometer, with no unit."""
    z = rough_um(48)[:40] + 0.01 * np.arange(48)[None, :] * 0.125
    y, x = np.mgrid[0:40, 0:48] * 0.125
    path.write_text("".join(f"{a:.6f},{b:.6f},{c:.9f}\n" for a, b, c in zip(x.ravel(), y.ravel(), z.ravel())))


CASES = {
    "tilted.x3p": (tilted_x3p, {"unit": "um"}),
    "near-square.nc": (near_square_nc, {"unit": "um"}),
    "rectangular.x3p": (rectangular_x3p, {"unit": "um"}),
    "afm.gwy": (four_channel_gwy, {"unit": "um", "undefined": "harmonic", "channel": 1}),
    "export.csv": (csv_export, {"unit": "um", "format": "instrument"}),
}


def law_preset(path, solver, surface: SurfaceFile, **params) -> dict:
    """Loads from f = 0.02 to 0.3: F = f E* h L, L = 2 sqrt(A / pi) (E* = 1 here)."""
    made = surface.generate(None)
    area = made.heights.size * made.spacing**2
    unit = surface.rms_height() * 2 * math.sqrt(area / math.pi)
    return {
        "name": "scan", "seed": 1, "realizations": 2 if solver == "mdr" else 1, "fit": {"bootstrap": 0},
        "spectrum": {"name": "surface-file", "params": {"path": str(path), **params}},
        "solver": {"name": solver, "params": {"youngs_modulus": 1.0, "poisson_ratio": 0.0}},
        "slope": {"name": "forward-difference"},
        "loading": {"start": 0.02 * unit, "stop": 0.3 * unit, "steps": 5, "spacing": "log"},
    }  # fmt: skip


@pytest.mark.parametrize("solver", ["mdr", "bem-halfspace-free"])
@pytest.mark.parametrize("name", sorted(CASES))
def test_each_kind_of_scan_gives_a_law(tmp_path, name, solver):
    import frictionlab

    write, params = CASES[name]
    path = tmp_path / name
    write(path)
    surface = SurfaceFile(path=str(path), **params)
    result = frictionlab.run(law_preset(path, solver, surface, **params), out=tmp_path / "run", workers=1,
                             progress=False, plot=False)  # fmt: skip
    assert result.fit is not None and math.isfinite(result.fit.a) and math.isfinite(result.fit.b)
    table = result.table
    assert 0 < table["contact_count"][0] < table["contact_count"][-1] < surface.generate(None).heights.size
    summary = json.loads((tmp_path / "run" / "summary.json").read_text())["input"]
    assert summary["detrend"] == "plane" and summary["detrend_from"] == "default"
    assert summary["shape"] == list(surface.generate(None).heights.shape)


def test_what_each_scan_says_it_did(tmp_path):
    tilted_x3p(tmp_path / "t.x3p")
    levelled = SurfaceFile(path=str(tmp_path / "t.x3p"), unit="um").input_summary()
    assert levelled["rms_removed_fraction"] > 0.5 and "caveats" not in levelled
    raw = SurfaceFile(path=str(tmp_path / "t.x3p"), unit="um", detrend="mean").input_summary()
    assert raw["rms_removed_fraction"] == pytest.approx(0.0, abs=1e-12) and "a tilt carries" in raw["caveats"][0]
    near_square_nc(tmp_path / "n.nc")
    near = SurfaceFile(path=str(tmp_path / "n.nc"), unit="nm")
    assert "taken as square (0.0626 % apart" in near.input_summary()["pixels"]
    assert near.generate(None).spacing == pytest.approx((1.85339 + 1.85455) / 2, rel=1e-6)
    rectangular_x3p(tmp_path / "r.x3p")
    rect = SurfaceFile(path=str(tmp_path / "r.x3p"), unit="um")
    assert rect.generate(None).spacing == pytest.approx(0.128, rel=1e-9)
    assert rect.grid_shape() == rect.generate(None).heights.shape == (math.floor(39 * 0.315 / 0.128) + 1, 64)
    assert "resampled onto square pixels of 0.128 along y" in rect.input_summary()["pixels"]



@pytest.mark.parametrize("micro", ["\u00b5m", "\u03bcm", "micron"], ids=["micro-sign", "greek-mu", "micron"])
def test_a_preset_may_write_um_with_the_micro_sign_or_the_greek_mu(tmp_path, micro):
    rectangular_x3p(tmp_path / "r.x3p")
    written = SurfaceFile(path=str(tmp_path / "r.x3p"), unit=micro)
    assert written.params.unit == "um"
    assert written.generate(None).spacing == SurfaceFile(path=str(tmp_path / "r.x3p"), unit="um").generate(None).spacing

def test_channels_are_listed_chosen_by_name_or_index_and_the_shared_name_is_said(tmp_path, capsys):
    four_channel_gwy(tmp_path / "afm.gwy")
    (tmp_path / "p.yaml").write_text(yaml.safe_dump(law_preset(
        tmp_path / "afm.gwy", "mdr", SurfaceFile(path=str(tmp_path / "afm.gwy"), unit="um", undefined="harmonic"),
        unit="um", undefined="harmonic")))  # fmt: skip
    assert main(["validate", str(tmp_path / "p.yaml")]) == ExitCode.OK
    out = capsys.readouterr().out
    assert "channel 3: 'Z Sensor', 160 x 64 points, lengths in m, values in m" in out
    assert "2 channels are named 'Height' (indices 0, 1); index 0 was taken" in out
    by_name = SurfaceFile(path=str(tmp_path / "afm.gwy"), unit="um", undefined="harmonic", channel="Z Sensor")
    by_index = SurfaceFile(path=str(tmp_path / "afm.gwy"), unit="um", undefined="harmonic", channel=3)
    np.testing.assert_array_equal(by_name.generate(None).heights, by_index.generate(None).heights)
    assert by_name.input_summary()["channel_index"] == 3
    with pytest.raises(ValueError, match="no channel named 'Phase'; the file has 0: 'Height', 1: 'Height'"):
        SurfaceFile(path=str(tmp_path / "afm.gwy"), channel="Phase").generate(None)
    with pytest.raises(ValueError, match=r"no channel named 'z sensor '; .* did you mean 'Z Sensor'\?"):
        SurfaceFile(path=str(tmp_path / "afm.gwy"), channel="z sensor ").generate(None)
    with pytest.raises(ValueError, match="channel 7 does not exist; the file has 4"):
        SurfaceFile(path=str(tmp_path / "afm.gwy"), channel=7).generate(None)


def test_despike_is_opt_in_and_recorded(tmp_path):
    four_channel_gwy(tmp_path / "afm.gwy")
    params = {"path": str(tmp_path / "afm.gwy"), "unit": "um", "undefined": "harmonic"}
    assert "despiked" not in SurfaceFile(**params).input_summary()
    summary = SurfaceFile(**params, despike=6.0).input_summary()
    assert summary["despiked"] == {"k": 6.0, "points": 2}  # the script's 2-pixel spike, and no other point


def test_a_scan_s_run_reads_back_with_all_its_input_said(tmp_path):
    """summary.json's input of a file of several channels, despiked, cropped, downsampled and left
    with its tilt (a caveat) holds mappings and lists of them: load and predict --from refused
    such a run as damaged. A value nested deeper than the input summary's is still refused."""
    import frictionlab
    from frictionlab.errors import RunFolderError

    four_channel_gwy(tmp_path / "afm.gwy")
    params = {"unit": "um", "undefined": "harmonic", "despike": 6.0, "detrend": "mean",
              "region": {"x": [0, 80], "y": [0, 32]}, "downsample": {"factor": 2}}  # fmt: skip
    surface = SurfaceFile(path=str(tmp_path / "afm.gwy"), **params)
    result = frictionlab.run(law_preset(tmp_path / "afm.gwy", "mdr", surface, **params), out=tmp_path / "run",
                             workers=1, progress=False, plot=False)  # fmt: skip
    summary = json.loads((tmp_path / "run" / "summary.json").read_text())
    assert {"channels", "despiked", "downsampled", "region_pixels", "caveats"} <= set(summary["input"])
    again = frictionlab.load(tmp_path / "run")
    assert again.input == summary["input"] and again.fit.a == result.fit.a and again.caveats == result.caveats
    given = ["--area", "1", "--modulus", "1", "--rms-height", "0.02", "--force", "0.01", "--json"]
    assert main(["predict", "--from", str(tmp_path / "run"), *given]) == 0
    summary["input"]["channels"][0]["points"] = [[160, 64]]  # a list in a list in a mapping: no summary writes it
    (tmp_path / "run" / "summary.json").write_text(json.dumps(summary))
    with pytest.raises(RunFolderError, match="summary.json is damaged: field 'input.channels"):
        frictionlab.load(tmp_path / "run")


# ------------------------------------------------------------------ files refused from what they declare


def test_a_binary_file_never_reaches_a_text_reader(tmp_path, monkeypatch):
    from SurfaceTopography.IO import AscReader, XYZReader

    def refuse(*args, **kwargs):
        raise AssertionError("a text reader was given the file")

    monkeypatch.setattr(XYZReader, "__init__", refuse)
    monkeypatch.setattr(AscReader, "__init__", refuse)
    near_square_nc(tmp_path / "map.nc")
    assert SurfaceFile(path=str(tmp_path / "map.nc")).generate(None).heights.shape == (64, 64)
    (tmp_path / "map.nc").rename(tmp_path / "map.csv")  # its first bytes say NetCDF: read as one
    assert SurfaceFile(path=str(tmp_path / "map.csv"), format="instrument").generate(None).heights.shape == (64, 64)
    (tmp_path / "noise.bin").write_bytes(bytes(range(256)) * 40)
    (tmp_path / "noise.csv").write_bytes(bytes(range(256)) * 40)
    with pytest.raises(ValueError, match=r"a \.csv file that is not text \(binary bytes at its start\)"):
        SurfaceFile(path=str(tmp_path / "noise.csv"), format="instrument").generate(None)
    with pytest.raises(ValueError, match=r"neither its suffix \.bin nor its first bytes name an instrument format"):
        SurfaceFile(path=str(tmp_path / "noise.bin")).generate(None)


def test_a_gwyddion_simple_field_file_is_named_with_what_to_do(tmp_path):
    """A .gsf (Gwyddion's simple export) has no reader: it was told to take a format's suffix, or
    under .dat that it was no text, as if renaming or damage were the matter."""
    header = b"Gwyddion Simple Field 1.0\nXRes = 16\nYRes = 16\nXReal = 1e-06\nYReal = 1e-06\nZUnits = m\n"
    data = header + b"\0" * (4 - len(header) % 4) + np.ones(256, "<f4").tobytes()
    for name in ("map.gsf", "map.dat"):
        (tmp_path / name).write_bytes(data)
        with pytest.raises(ValueError, match=r"a Gwyddion Simple Field \(\.gsf\) file.*save it as \.gwy"):
            SurfaceFile(path=str(tmp_path / name)).generate(None)


def test_an_xml_member_that_inflates_beyond_the_cap_is_refused_unread(tmp_path):
    from frictionlab_spectra.instrument_reader import XML_LIMIT

    tilted_x3p(tmp_path / "good.x3p")
    with zipfile.ZipFile(tmp_path / "good.x3p") as good, zipfile.ZipFile(tmp_path / "bomb.x3p", "w",
                                                                           zipfile.ZIP_DEFLATED) as bomb:  # fmt: skip
        for item in good.infolist():
            data = good.read(item)
            if item.filename == "main.xml":
                data = data + b" " * (XML_LIMIT + 1)
            bomb.writestr(item, data, compress_type=zipfile.ZIP_DEFLATED)
    assert (tmp_path / "bomb.x3p").stat().st_size < XML_LIMIT / 100
    with pytest.raises(ValueError, match=r"XML member 'main.xml' would inflate to 64 MiB, more than the 64 MiB"):
        SurfaceFile(path=str(tmp_path / "bomb.x3p")).generate(None)


def test_an_x3p_declaring_more_points_than_fit_is_refused_from_its_header(tmp_path, monkeypatch, capsys):
    """Its data member is deflated zeros in the forged case; here, as small as the original:
    the refusal comes from the header and the zip's directory, before the reader looks at the
    data: a payload smaller than the points declared is a damaged file (a payload of the size
    declared, a map too large to read: ``check_declared_points``)."""
    from frictionlab_spectra import instrument_reader

    tilted_x3p(tmp_path / "small.x3p")
    with zipfile.ZipFile(tmp_path / "small.x3p") as small, zipfile.ZipFile(tmp_path / "huge.x3p", "w") as huge:
        for item in small.infolist():
            data = small.read(item)
            if item.filename == "main.xml":
                data = data.replace(b"<SizeX>64</SizeX>", b"<SizeX>22000</SizeX>")
                data = data.replace(b"<SizeY>64</SizeY>", b"<SizeY>22000</SizeY>")
                assert data.count(b"22000") == 2
            huge.writestr(item.filename, data)
    monkeypatch.setattr(instrument_reader, "room_to_read", lambda: (2 * 2**30, "a test limit of 2 GiB"))
    # the run's own check (making the MDR line: 43 GiB) passes, on any machine, so the reader's is seen
    monkeypatch.setattr(memory, "available_memory", lambda: (2**40, "a test's terabyte"))
    (tmp_path / "p.yaml").write_text(yaml.safe_dump(law_preset(
        tmp_path / "small.x3p", "mdr", SurfaceFile(path=str(tmp_path / "small.x3p"), unit="um"), unit="um"
    )).replace("small.x3p", "huge.x3p"))  # fmt: skip
    code = main(["validate", str(tmp_path / "p.yaml")])
    err = capsys.readouterr().err
    assert code == ExitCode.USAGE, err
    assert "a damaged XML 3D surface profile (X3P) file: its binary heights take 32768 bytes, and its description " \
           "declares 484000000 points" in err and "Traceback" not in err  # fmt: skip
    monkeypatch.setattr(instrument_reader, "room_to_read", lambda: (2**16, "a test limit of 64 KiB"))
    (tmp_path / "small.yaml").write_text((tmp_path / "p.yaml").read_text().replace("huge.x3p", "small.x3p"))
    assert main(["validate", str(tmp_path / "small.yaml")]) == ExitCode.USAGE  # a sound file, too large for the room
    assert "declares 64 x 64 points (x by y); reading them takes about" in capsys.readouterr().err


def forged_netcdf(path, n: int):
    """A classic NetCDF (64-bit offsets) whose header declares an n x n map: a sparse file."""
    with netcdf_file(str(path), "w", version=2) as nc:
        nc.createDimension("x", 4)
        nc.createDimension("y", 4)
        heights = nc.createVariable("heights", "d", ("x", "y"))
        heights[:] = np.ones((4, 4))
        heights.unit = "um"
        for axis in "xy":
            var = nc.createVariable(axis, "d", (axis,))
            var[:] = np.arange(4.0)
            var.length, var.unit = 4.0, "um"
    header = bytearray(open(path, "rb").read())
    for name in (b"x", b"y"):  # the dimensions' lengths
        at = header.index(b"\x00\x00\x00\x01" + name + b"\x00\x00\x00") + 8
        header[at:at + 4] = struct.pack(">i", n)
    first = struct.unpack(">q", header[header.index(b"\x00\x00\x00\x06\x00\x00\x00\x80") + 8:][:8])[0]
    at = header.index(b"\x00\x00\x00\x06\x00\x00\x00\x80")  # heights: vsize, begin
    header[at + 4:at + 8] = struct.pack(">I", 0xFFFFFFFF)
    offset = first + n * n * 8
    for _ in range(2):  # x then y: vsize 32 -> 8 n, begin after the heights
        at = header.index(b"\x00\x00\x00\x06\x00\x00\x00\x20")
        header[at + 4:at + 8] = struct.pack(">I", 8 * n)
        header[at + 8:at + 16] = struct.pack(">q", offset)
        offset += 8 * n
    with open(path, "r+b") as fh:
        fh.write(header[:first])
        fh.truncate(offset)  # sparse: nothing written but the header


@pytest.mark.parametrize("solver", ["mdr", "bem-halfspace-free"])
def test_a_netcdf_declaring_100000_squared_points_is_refused_from_its_header(tmp_path, capsys, solver):
    """A sparse file of 80 GB: its header alone is read (SurfaceTopography's NetCDF reader maps the
    file); the map is refused by what it declares, before a height is read."""
    forged_netcdf(tmp_path / "huge.nc", 100_000)
    if (tmp_path / "huge.nc").stat().st_blocks * 512 > 2**20:
        pytest.skip("this file system does not keep files sparse")
    (tmp_path / "p.yaml").write_text(yaml.safe_dump({
        "name": "huge", "seed": 1, "realizations": 1, "fit": {"bootstrap": 0},
        "spectrum": {"name": "surface-file", "params": {"path": str(tmp_path / "huge.nc")}},
        "solver": {"name": solver}, "loading": {"start": 0.01, "stop": 0.1, "steps": 3}}))  # fmt: skip
    code = main(["validate", str(tmp_path / "p.yaml")])
    err = capsys.readouterr().err
    assert code in (ExitCode.USAGE, ExitCode.RUNTIME_FAILURE) and "Traceback" not in err
    assert "GiB" in err and ("declares 100000 x 100000 points" in err or "this run would need about" in err), err


def test_a_damaged_file_of_a_known_format_is_named_as_such(tmp_path):
    tilted_x3p(tmp_path / "scan.x3p")
    data = (tmp_path / "scan.x3p").read_bytes()
    (tmp_path / "cut.x3p").write_bytes(data[: len(data) // 2])
    with pytest.raises(ValueError, match=r"a damaged XML 3D surface profile \(X3P\) file"):
        SurfaceFile(path=str(tmp_path / "cut.x3p")).generate(None)



def test_an_xyz_map_off_a_regular_grid_is_named_so_not_as_damage(tmp_path):
    """SurfaceTopography's reader says why (x jittered: not a regular grid); that was
    dropped, and the file called damaged, to be copied again from the instrument."""
    rng = np.random.default_rng(1)
    rows = [f"{0.1 * i + 0.003 * rng.standard_normal():.6g} {0.1 * j:.6g} {np.sin(i / 3) + np.cos(j / 4):.6g}"
            for j in range(16) for i in range(16)]  # fmt: skip
    (tmp_path / "jittered.xyz").write_text("\n".join(rows) + "\n")
    with pytest.raises(ValueError, match=r"not on a regular grid \(XYZ file does not contain a regular grid") as said:
        SurfaceFile(path=str(tmp_path / "jittered.xyz"), unit="um").generate(None)
    assert "damaged" not in str(said.value) and "copy it again" not in str(said.value)


@pytest.mark.parametrize("plugin", [SurfaceFile, ProfileFile])
@pytest.mark.parametrize("layout", ["one row", "each point twice", "one point"])
def test_an_xyz_file_whose_points_make_no_grid_is_named_so_not_as_damage(tmp_path, plugin, layout):
    """A line scan written as x, y, z (y the same on every line) or a map listing each point twice
    gives SurfaceTopography's reader a grid step of zero, and numpy's "'list' argument must have
    no negative elements": it was 'a damaged ... file', to be copied again from the instrument.
    One point alone (numpy's "zero-size array to reduction operation") was damage too."""
    rows = [f"{0.1 * i:.6g} {0.1 * j:.6g} {np.sin(i / 3) + np.cos(j / 4):.6g}"
            for j in range(1 if layout == "one row" else 16) for i in range(16)]  # fmt: skip
    rows = {"one row": rows, "each point twice": rows + rows, "one point": rows[:1]}[layout]
    (tmp_path / "scan.xyz").write_text("\n".join(rows) + "\n")
    with pytest.raises(ValueError, match=r"file make no grid: there is one, two share a position, or all lie on one "
                                         r"row or one column \(a line scan written as x, y, z\); export a line as its x "
                                         r"and z") as said:
        plugin(path=str(tmp_path / "scan.xyz"), unit="um").generate(None)
    assert "damaged" not in str(said.value) and "copy it again" not in str(said.value)


def test_a_damaged_files_message_carries_its_readers_reason_on_one_short_line():
    from SurfaceTopography.Exceptions import CorruptFile

    from frictionlab_spectra.reader_failures import describe_failure

    class Reader:  # what describe_failure asks of a SurfaceTopography reader
        name = staticmethod(lambda: "Gwyddion")
        format = staticmethod(lambda: "gwy")

    said = str(describe_failure(Reader(), CorruptFile("Expected 'GwyContainer'\n" + "x" * 5000 + " at byte 12"), "w"))
    assert said.startswith("w: a damaged Gwyddion file (CorruptFile: Expected 'GwyContainer' xxx")
    assert "at byte 12); the reader of its format cannot read it" in said
    assert "\n" not in said and len(said) < 400

def netcdf(path, heights_unit: str, length_unit: str):
    z = rough_um(16)
    with netcdf_file(str(path), "w") as nc:
        nc.createDimension("x", 16)
        nc.createDimension("y", 16)
        for axis in ("x", "y"):
            var = nc.createVariable(axis, "d", (axis,))
            var[:] = np.arange(16) * 0.125
            var.length, var.unit = 2.0, length_unit
        heights = nc.createVariable("heights", "d", ("x", "y"))
        heights[:] = z
        heights.unit = heights_unit


def test_units_that_are_not_lengths_are_refused_and_a_unit_mismatch_is_named(tmp_path):
    netcdf(tmp_path / "kg.nc", "kg", "kg")
    with pytest.raises(ValueError, match="the file's length unit 'kg' is not a length unit"):
        SurfaceFile(path=str(tmp_path / "kg.nc")).generate(None)
    netcdf(tmp_path / "mixed.nc", "nm", "um")
    with pytest.raises(ValueError, match="heights and its lateral sizes are in different units"):
        SurfaceFile(path=str(tmp_path / "mixed.nc")).generate(None)


def test_sizes_along_x_and_y_in_different_units_are_named_as_such_not_as_the_heights(tmp_path):
    """A NetCDF whose x is in um and y in nm (heights in um) was told its heights and its lateral
    sizes were in different units, and to convert its heights."""
    z = np.random.default_rng(3).normal(size=(12, 10))
    with netcdf_file(str(tmp_path / "xy.nc"), "w") as nc:
        for name, size, length, unit in (("x", 12, 6.0, "um"), ("y", 10, 5000.0, "nm")):
            nc.createDimension(name, size)
            var = nc.createVariable(name, "d", (name,))
            var.length, var.unit = length, unit
        heights = nc.createVariable("heights", "d", ("x", "y"))
        heights[:] = z
        heights.unit = "um"
    with pytest.raises(ValueError, match="sizes along x and along y are in different length units") as refused:
        SurfaceFile(path=str(tmp_path / "xy.nc")).generate(None)
    assert "convert its heights" not in str(refused.value)



def write_bcr(path, counts: np.ndarray, *, xunit="nm", yunit="nm", zunit="nm", bit2nm=0.1):
    """A BCR-STM file by hand: a 2048-byte text header, then int16 heights (little endian), rows along x."""
    ny, nx = counts.shape
    header = (f"fileformat = bcrstm\nheadersize = 2048\nxpixels = {nx}\nypixels = {ny}\nxlength = {nx * 100}\n"
              f"ylength = {ny * 100}\nxunit = {xunit}\nyunit = {yunit}\nzunit = {zunit}\nbit2nm = {bit2nm}\n")
    path.write_bytes(header.encode("latin-1").ljust(2048, b"\0") + counts.astype("<i2").tobytes())


@pytest.mark.parametrize("units, said", [
    ({"yunit": "um"}, "sizes along x and along y are in different length units"),  # was 'a damaged BCR-STM file'
    ({"zunit": "V"}, "the file's heights are in 'V', a voltage, not a length: it holds no heights"),
])  # fmt: skip
def test_a_bcr_file_of_units_its_reader_refuses_is_named_not_damaged(tmp_path, units, said):
    counts = np.round(rough_um(16) * 1e4)  # heights of 0.1 nm steps
    write_bcr(tmp_path / "sound.bcr", counts)
    read = SurfaceFile(path=str(tmp_path / "sound.bcr"), unit="nm", detrend="none").generate(None)
    np.testing.assert_allclose(read.heights, 0.1 * counts, rtol=1e-12)  # bit2nm: 0.1 nm a count
    assert read.spacing == pytest.approx(100.0)
    write_bcr(tmp_path / "units.bcr", counts, **units)
    with pytest.raises(ValueError, match=said) as refused:
        SurfaceFile(path=str(tmp_path / "units.bcr")).generate(None)
    assert "damaged" not in str(refused.value)

def test_a_unit_of_any_length_is_quoted_cut_in_the_middle(tmp_path):
    """A file's unit is the file's text: one of 10,000 characters was quoted whole in the
    refusal that it is not a length unit."""
    netcdf(tmp_path / "long.nc", "u" * 10_000, "u" * 10_000)
    with pytest.raises(ValueError, match="the file's length unit 'u{30}'...'u{30}' is not a length unit") as refused:
        SurfaceFile(path=str(tmp_path / "long.nc")).generate(None)
    assert len(str(refused.value)) < 400


def test_an_escape_code_in_a_files_unit_or_channel_is_printed_escaped(tmp_path, capsys):
    netcdf(tmp_path / "evil.nc", "\x1b]2;owned\x07\x1b[2J", "\x1b]2;owned\x07\x1b[2J")
    (tmp_path / "p.yaml").write_text(yaml.safe_dump({
        "name": "evil", "seed": 1, "realizations": 1, "spectrum": {"name": "surface-file",
        "params": {"path": str(tmp_path / "evil.nc")}}, "solver": {"name": "mdr"},
        "loading": {"start": 0.01, "stop": 0.1, "steps": 3}}))  # fmt: skip
    main(["validate", str(tmp_path / "p.yaml")])
    captured = capsys.readouterr()
    assert "\x1b" not in captured.out + captured.err and "\x07" not in captured.out + captured.err


def test_a_profilometer_csv_export_goes_to_surfacetopography_when_asked(tmp_path):
    """A Dektak-style export: a Latin-1 header ("\\xb5m"), then x, z: refused as a table with
    the remedy, read as an instrument's export with format: instrument, levelled by its line."""
    from frictionlab_spectra import ProfileFile

    x = np.arange(200) * 0.05
    z = 0.1 * np.sin(3 * x) + 0.02 * x
    header = "Meta Data\nScan Length,10 \xb5m\n\nScan Data\nLateral(\xb5m),Total Profile(\xb5m)\n".encode("latin-1")
    (tmp_path / "dektak.csv").write_bytes(header + "".join(f"{a:.4f},{b:.6f}\n" for a, b in zip(x, z)).encode())
    with pytest.raises(ValueError, match="not UTF-8 at line 2.*read with format: instrument"):
        ProfileFile(path=str(tmp_path / "dektak.csv"), spacing=0.05).generate(None)
    line = ProfileFile(path=str(tmp_path / "dektak.csv"), format="instrument", unit="um")
    made = line.generate(None)
    assert made.heights.size == 200 and made.spacing == pytest.approx(0.05, rel=1e-9)
    t = x - x.mean()
    expected = z - z.mean() - (t @ (z - z.mean()) / (t @ t)) * t
    np.testing.assert_allclose(made.heights, expected, atol=1e-6)
    assert line.input_summary()["detrend"] == "tilt" and line.input_summary()["detrend_from"] == "default"


def test_a_tilt_left_in_is_a_caveat_of_the_run_and_of_its_summary(tmp_path):
    import frictionlab

    tilted_x3p(tmp_path / "t.x3p")
    surface = SurfaceFile(path=str(tmp_path / "t.x3p"), unit="um", detrend="mean")
    result = frictionlab.run(law_preset(tmp_path / "t.x3p", "mdr", surface, unit="um", detrend="mean"),
                             out=tmp_path / "run", workers=1, progress=False, plot=False)  # fmt: skip
    assert any(caveat.startswith("a tilt carries") for caveat in result.caveats)
    stored = json.loads((tmp_path / "run" / "summary.json").read_text())
    assert stored["caveats"] == result.caveats and stored["input"]["caveats"][0] in result.caveats
    levelled = frictionlab.run(law_preset(tmp_path / "t.x3p", "mdr", SurfaceFile(path=str(tmp_path / "t.x3p"), unit="um"),
                                          unit="um"), out=tmp_path / "level", workers=1, progress=False, plot=False)  # fmt: skip
    assert not any("tilt" in caveat for caveat in levelled.caveats)


def test_realizations_of_one_measured_line_are_said_to_be_one_surface(tmp_path):
    """Ten realizations of a profile read from a file press the same line ten times: the
    bootstrap interval over them was a point ([a, a]) beside a std.err of the fit, without a
    word. The run says the ensemble is one surface; a random spectrum's run says nothing of it."""
    import frictionlab

    z = np.cumsum(np.random.default_rng(2).standard_normal(2000))
    np.save(tmp_path / "line.npy", z)
    preset = {"name": "one", "realizations": 4, "spectrum": {"name": "profile-file",
              "params": {"path": str(tmp_path / "line.npy"), "spacing": 1.0, "detrend": "tilt"}},
              "solver": {"name": "mdr"}, "loading": {"start": 0.01, "stop": 0.5, "steps": 8, "spacing": "log", "unit": "f"},
              "fit": {"bootstrap": 100}}  # fmt: skip
    result = frictionlab.run(preset, out=tmp_path / "run", workers=1, progress=False, plot=False)
    said = [caveat for caveat in result.caveats if caveat.startswith("all 4 realizations gave the same curve")]
    assert len(said) == 1 and result.fit.a_ci[0] == result.fit.a_ci[1]  # the point the caveat explains
    assert said[0] in json.loads((tmp_path / "run" / "summary.json").read_text())["caveats"]
    random_lines = frictionlab.run("quickstart", out=tmp_path / "random", workers=1, progress=False, plot=False,
                                   realizations=4)  # fmt: skip
    assert not any("same curve" in caveat for caveat in random_lines.caveats)


def test_a_crop_that_leaves_out_the_undefined_points_is_read(tmp_path):
    """Undefined points (an X3P's) or NaN (a table's) outside region were refused as if the
    whole file were pressed, though the tutorial's advice is to crop to the measured part."""
    z = rough_um(24)
    holes = z.copy()
    holes[5, 3] = holes[20, 4] = np.nan
    np.save(tmp_path / "holes.npy", holes)
    np.save(tmp_path / "clean.npy", z)
    x3pio.write(tmp_path / "holes.x3p", holes * 1e-6, x_scale=1e-7, y_scale=1e-7, revision=x3pio.Revision.ISO5436_2000)
    x3pio.write(tmp_path / "clean.x3p", z * 1e-6, x_scale=1e-7, y_scale=1e-7, revision=x3pio.Revision.ISO5436_2000)
    region = {"x": [8, 24]}
    for name, extra in (("x3p", {"unit": "um"}), ("npy", {"spacing": 0.1})):
        kept = SurfaceFile(path=str(tmp_path / f"holes.{name}"), region=region, **extra)
        clean = SurfaceFile(path=str(tmp_path / f"clean.{name}"), region=region, **extra)
        np.testing.assert_allclose(kept.generate(None).heights, clean.generate(None).heights, rtol=1e-12, atol=1e-15)
    summary = SurfaceFile(path=str(tmp_path / "holes.x3p"), region=region, unit="um").input_summary()
    assert summary["undefined_points"] == 0 and summary["undefined_outside_region"] == 2
    assert summary["filled_by"] is None
    with pytest.raises(ValueError, match=r"1 of 96 points of the region are undefined .* undefined: harmonic"):
        SurfaceFile(path=str(tmp_path / "holes.x3p"), region={"y": [2, 6]}, unit="um").rms_height()
    with pytest.raises(ValueError, match=r"1 value\(s\) in the region's heights .* the first at row 3, column 3"):
        SurfaceFile(path=str(tmp_path / "holes.npy"), region={"y": [2, 6]}, spacing=0.1).rms_height()


def test_pixels_equal_but_for_rounding_are_not_said_to_be_taken_as_square(tmp_path):
    """An x, y, z text file's steps, 0.1 and 0.1 + 2e-17, were said to be 'taken as square
    (1.39e-14 % apart)': a note about pixels that are square."""
    z = rough_um(16)[:12]  # 16 x 12 points: x steps of 0.1, y steps of 0.1 + 2e-17 as read
    rows = [f"{0.1 * i:.6g} {0.1 * j:.6g} {z[j, i]:.9g}" for j in range(12) for i in range(16)]
    (tmp_path / "scan.xyz").write_text("\n".join(rows) + "\n")
    surface = SurfaceFile(path=str(tmp_path / "scan.xyz"), unit="um")
    assert "pixels" not in surface.input_summary()
    assert surface.generate(None).spacing == pytest.approx(0.1, rel=1e-12)


def test_a_filled_hole_is_counted_in_the_region_pressed_not_in_the_file(tmp_path):
    """With undefined: harmonic and a crop that leaves out a large hole, the summary said the
    file's 400 points were filled and the caveat asked to crop to the measured part: as done."""
    z = rough_um(64)
    z[10:30, 10:30] = np.nan  # 9.8 % of the file
    x3pio.write(tmp_path / "hole.x3p", z * 1e-6, x_scale=1e-7, y_scale=1e-7, revision=x3pio.Revision.ISO5436_2000)
    params = {"path": str(tmp_path / "hole.x3p"), "unit": "um", "undefined": "harmonic"}
    whole = SurfaceFile(**params).input_summary()
    assert whole["undefined_points"] == 400 and "9.77 % of the file's points" in whole["caveats"][0]
    measured = SurfaceFile(**params, region={"x": [30, 64]}).input_summary()
    assert measured["undefined_points"] == 0 and measured["undefined_outside_region"] == 400
    assert measured["filled_by"] is None and not any("harmonic" in c for c in measured.get("caveats", []))
    partly = SurfaceFile(**params, region={"x": [20, 64]}).input_summary()
    assert partly["undefined_points"] == 200 and partly["filled_by"] == "harmonic"
    assert any(c.startswith("7.1 % of the region's points were undefined") for c in partly["caveats"])


def test_a_text_export_too_large_for_the_memory_left_is_refused_before_it_is_parsed(tmp_path, monkeypatch):
    """SurfaceTopography's text readers parse the whole file as it is opened (1.2 to 1.9 times its
    bytes): a large .xyz under a memory limit ended as 'the Plain text file declares more points
    than this process can hold', or read past the room. It is refused by its size, unparsed."""
    import frictionlab_spectra.instrument_reader as readers

    z = rough_um(16)
    rows = [f"{0.1 * i:.6g} {0.1 * j:.6g} {z[j, i]:.9g}" for j in range(16) for i in range(16)]
    (tmp_path / "scan.xyz").write_text("\n".join(rows) + "\n")
    size = (tmp_path / "scan.xyz").stat().st_size
    monkeypatch.setattr(readers, "room_to_read", lambda: (2 * size - 1, "the room in this test"))
    with pytest.raises(ValueError, match=rf"scan.xyz': a text export \(.*\) of {size:,} bytes; SurfaceTopography's "
                                         r"reader takes about .* GiB to read it, more than the .* GiB this process may "
                                         r"use \(the room in this test\); crop the scan"):
        SurfaceFile(path=str(tmp_path / "scan.xyz"), unit="um").rms_height()
    monkeypatch.setattr(readers, "room_to_read", lambda: (2 * size, "the room in this test"))
    assert SurfaceFile(path=str(tmp_path / "scan.xyz"), unit="um").rms_height() > 0


def test_undefined_points_under_a_gwyddion_mask_are_said_to_be_its_mask(tmp_path):
    """SurfaceTopography reads a Gwyddion mask as points not measured, and the refusal said only
    that: a mask that selects grains over measured heights was then filled (undefined: harmonic)
    as its message advised, those heights replaced."""
    from SurfaceTopography.IO.GWY import _gwy_write_object

    from .test_scan_edge_cases import rough

    z = rough(16, 24, 3) * 1e-8  # on pixels of 0.1 um, a mask over its first 3 rows
    field = {"xres": ("i", 24), "yres": ("i", 16), "xreal": ("d", 2.4e-6), "yreal": ("d", 1.6e-6),
             "si_unit_xy": ("o", ("GwySIUnit", {"unitstr": ("s", "m")})),
             "si_unit_z": ("o", ("GwySIUnit", {"unitstr": ("s", "")}))}  # fmt: skip
    mask = np.zeros_like(z)
    mask[:3] = 1.0
    container = {"/0/data/title": ("s", "Height"),
                 "/0/data": ("o", ("GwyDataField", {**field, "si_unit_z": ("o", ("GwySIUnit", {"unitstr": ("s", "m")})),
                                                    "data": ("D", z.ravel())})),
                 "/0/mask": ("o", ("GwyDataField", {**field, "data": ("D", mask.ravel())}))}  # fmt: skip
    with open(tmp_path / "masked.gwy", "wb") as fh:
        fh.write(b"GWYP")
        _gwy_write_object(fh, "GwyContainer", container)
    with pytest.raises(ValueError, match=r"72 of 384 points are undefined in the file: under its Gwyddion mask.*a "
                       r"selection \(grains, a marked area\) over measured heights would have them replaced"):
        SurfaceFile(path=str(tmp_path / "masked.gwy"), unit="um").generate(None)
