"""A channel of an instrument file whose values are no heights is refused in any reader, by
name: SurfaceTopography's IBW and MI readers list an AFM's current, voltage and phase channels
beside its heights (each with a kind), and such a channel, picked with ``channel:`` or the
file's default, was read as heights of 1 m per ampere or volt. (Gwyddion's A, the ampere its
reader takes for the angstrom, was refused alone.)"""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("SurfaceTopography")

from SurfaceTopography.IO.Reader import ChannelInfo, DataKind, data_kind_from_unit  # noqa: E402

from frictionlab_spectra import SurfaceFile  # noqa: E402
from frictionlab_spectra.instrument_reader import check_channel_of_heights  # noqa: E402

from .test_scan_edge_cases import rough, write_gwy  # noqa: E402


class Listing:
    """A reader (IBW's, an Asylum file) that lists heights, a current in A, a bias in V and a
    phase in deg, each with the kind SurfaceTopography gives it."""

    def __init__(self, real=None, units=(("Height", "m"), ("Current", "A"), ("Bias", "V"), ("Phase", "deg"))):
        self.real = real
        self.channels = [
            ChannelInfo(self, i, name=name, dim=2, nb_grid_pts=(16, 16), unit="m", data_unit=unit,
                        data_kind=data_kind_from_unit(unit, name, ascii_angstrom=False))
            for i, (name, unit) in enumerate(units)
        ]  # fmt: skip
        self.default_channel = self.channels[0]

    @classmethod
    def format(cls):
        return "ibw"

    @classmethod
    def name(cls):
        return "Igor binary wave (IBW)"

    def close(self):
        if self.real is not None:
            self.real.close()


@pytest.mark.parametrize(("index", "said"), [
    (1, "channel 1 ('Current') holds current values in 'A', not heights"),
    (2, "channel 2 ('Bias') holds voltage values in 'V', not heights"),
    (3, "channel 3 ('Phase') holds phase values in 'deg', not heights"),
])  # fmt: skip
def test_a_channel_of_another_kind_is_refused_naming_the_channels_of_heights(index, said):
    reader = Listing()
    assert [c.data_kind for c in reader.channels][1] == DataKind.CURRENT  # IBW's A is the ampere
    with pytest.raises(ValueError, match="^scan: " + said.replace("(", r"\(").replace(")", r"\)")) as refused:
        check_channel_of_heights(reader, reader.channels[index], "scan")
    assert "choose a channel of heights with channel (0: 'Height')" in str(refused.value)
    check_channel_of_heights(reader, reader.channels[0], "scan")  # heights pass


def test_a_reader_without_kinds_is_judged_by_the_unit_of_its_values():
    """A reader that gives no kind (or an older SurfaceTopography): a unit that is no length refuses."""
    reader = Listing(units=(("Z", "V"),))
    for channel in reader.channels:
        channel._data_kind = None
    with pytest.raises(ValueError, match=r"channel 0 \('Z'\) holds values in 'V', not heights: the file holds no "):
        check_channel_of_heights(reader, reader.channels[0], "scan")
    for unit in ("nm", "um", "\u00b5m", "\u00c5", None):
        check_channel_of_heights(Listing(units=(("Z", unit),)), Listing(units=(("Z", unit),)).channels[0], "scan")


@pytest.mark.parametrize("channel", [1, "Bias"])
def test_a_surface_file_refuses_a_current_or_voltage_channel_its_reader_lists(tmp_path, monkeypatch, channel):
    """The refusal reaches the spectrum's message, by index or by name."""
    path = write_gwy(tmp_path / "afm.gwy", rough(16, 16, 4) * 1e-9, 1e-9, 1e-9)
    monkeypatch.setattr("frictionlab_spectra.instrument_file._open_reader", lambda fh, path, where: Listing())
    with pytest.raises(ValueError, match=r"afm.gwy': channel \d \('(Current|Bias)'\) holds (current|voltage) values"):
        SurfaceFile(path=str(path), unit="nm", channel=channel).rms_height()


def test_an_index_past_the_channels_listed_says_they_are_not_the_instruments_numbering(tmp_path, capsys):
    """Gwyddion numbers a file's channels 0 to 3 (Height, Amplitude in V, Phase in deg, Z Sensor);
    its reader lists the two of heights, 0 and 1. 'channel: 3', Gwyddion's Z Sensor, was refused
    as 'does not exist' with the two listed and no word of why the numbers differ."""
    from .test_scan_edge_cases import validate

    z = rough(16, 16) * 1e-9
    path = write_gwy(tmp_path / "afm.gwy", z, 1e-7, 1e-7,
                     more=[("Amplitude", rough(16, 16), "V"), ("Phase", rough(16, 16), "deg"), ("Z Sensor", z, "m")])  # fmt: skip
    code, text = validate(tmp_path, capsys, path, channel=3)
    assert code == 2 and "Traceback" not in text
    assert ("channel 3 does not exist; the file has 2 (0 to 1): 0: 'Height', 1: 'Z Sensor' (most readers list "
            "channels of heights only: one in degrees, volts or no unit may be left out); indices count the channels "
            "listed here, not the instrument's own numbering: name the channel to be sure") in text


@pytest.mark.parametrize("signal", ["Amplitude", "Deflection Error", "Phase"])
def test_a_signal_in_metres_first_in_the_file_is_passed_over_for_the_height_channel(tmp_path, capsys, signal):
    """An AFM file whose first channel is an amplitude or a deflection error, in metres as its
    heights are, had it read as the heights by default: an rms height 100 times too small and
    slopes of the error signal, with only its name in the listing. The channel named Height is
    taken, and the listing says why and how to take the other; asked for by index, the signal is read."""
    from .test_scan_edge_cases import validate

    z = rough(16, 16) * 1e-9
    path = write_gwy(tmp_path / "afm.gwy", z * 0.01, 1e-7, 1e-7, more=[("Height", z, "m")], title=signal)
    summary = SurfaceFile(path=str(path), unit="nm", detrend="mean").input_summary()
    assert summary["channel"] == "Height" and summary["channel_index"] == 1
    assert abs(summary["rms_height"] - float(np.std(z * 1e9))) < 1e-9 * summary["rms_height"]
    code, text = validate(tmp_path, capsys, path, unit="nm")
    assert code == 0 and (f"the file's default channel, 0 '{signal}', names a signal, not heights: channel 1 'Height' "
                          "was taken (channel: 0 takes the other)") in text
    asked = SurfaceFile(path=str(path), unit="nm", detrend="mean", channel=0).input_summary()
    assert asked["channel"] == signal and "channel_note" not in asked


def test_the_channels_of_heights_offered_leave_out_a_signal_named_so():
    """An amplitude in m is in a length unit, yet no heights (the default channel's note says so):
    the refusal offered it beside the heights. Where only such channels are in lengths, they are offered."""
    reader = Listing(units=(("Amplitude", "m"), ("Height", "m"), ("Current", "A")))
    with pytest.raises(ValueError, match=r"choose a channel of heights with channel \(1: 'Height'\), or export"):
        check_channel_of_heights(reader, reader.channels[2], "scan")
    only = Listing(units=(("Amplitude", "m"), ("Current", "A")))
    with pytest.raises(ValueError, match=r"choose a channel of heights with channel \(0: 'Amplitude'\), or export"):
        check_channel_of_heights(only, only.channels[1], "scan")
