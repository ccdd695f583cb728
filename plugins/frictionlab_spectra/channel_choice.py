"""Which channel of an instrument file is read: the one a preset names (an index among the
channels the reader lists, or a name), or the reader's default unless its name says it is an
AFM's signal other than heights; refusals list the channels to choose from."""

from __future__ import annotations

from .instrument_reader import HEIGHT_WORDS, SIGNAL_WORDS, names_a_signal, quoted, says


LEFT_OUT = " (most readers list channels of heights only: one in degrees, volts or no unit may be left out)"


def pick_channel(reader, wanted: str | int | None, where: str):
    """The channel ``wanted`` (an index, or a name: the first of that name), or the reader's
    default (``_default_channel``); and a note when other channels share its name, or the
    default was passed over (None otherwise)."""
    channels = list(reader.channels)
    if not channels:  # a reader keeps only channels of heights (a length over lengths): here, none
        raise ValueError(f"{where}: the {reader.name()} file holds no channel of heights that SurfaceTopography reads "
                         "(heights are lengths: m, um, nm...; a channel in degrees, volts, newtons or no unit is "
                         "not read as heights); export the height channel with its length unit")  # fmt: skip
    if wanted is None:
        channel, note = _default_channel(reader.default_channel, channels)
    elif isinstance(wanted, int):
        if not 0 <= wanted < len(channels):
            raise ValueError(f"{where}: channel {wanted} does not exist; the file has {len(channels)} "
                             f"(0 to {len(channels) - 1}): {_named(channels)}{LEFT_OUT}; indices count the channels "
                             "listed here, not the instrument's own numbering: name the channel to be sure")  # fmt: skip
        channel = channels[wanted]
    else:
        named = [c for c in channels if str(c.name) == wanted]
        if not named:
            raise ValueError(f"{where}: no channel named {quoted(wanted)}; the file has {_named(channels)}"
                             f"{_near_names(channels, wanted)}{LEFT_OUT}")  # fmt: skip
        channel = named[0]
    same = [int(c.index) for c in channels if str(c.name) == str(channel.name)]
    note = note if wanted is None else None
    if len(same) > 1:
        note = ("" if note is None else f"{note}; ") + (f"{len(same)} channels are named {quoted(channel.name)} (indices {', '.join(map(str, same))}); "
                f"index {int(channel.index)} was taken (channel: INDEX chooses another)")  # fmt: skip
    return channel, note


def _default_channel(default, channels):
    """The reader's default channel, unless its name is an AFM's signal other than heights (an
    amplitude or a deflection error, in m like heights) and another's names heights: then the
    first of those, and a note saying so."""
    if not names_a_signal(default):
        return default, None
    heights = [c for c in channels if says(c, HEIGHT_WORDS) and not says(c, SIGNAL_WORDS)]
    if not heights:
        return default, None
    return heights[0], (f"the file's default channel, {int(default.index)} {quoted(default.name)}, names a signal, not "
                        f"heights: channel {int(heights[0].index)} {quoted(heights[0].name)} was taken "
                        f"(channel: {int(default.index)} takes the other)")  # fmt: skip


def _near_names(channels, wanted: str) -> str:
    """A hint when a name differs from one of the file's only in case or surrounding spaces:
    names are matched exactly, as the file writes them."""
    key = wanted.strip().casefold()
    near = [quoted(c.name) for c in channels if str(c.name).strip().casefold() == key]
    return f" (names are matched exactly: did you mean {near[0]}?)" if near else ""


def _named(channels) -> str:
    return ", ".join(f"{int(c.index)}: {quoted(c.name)}" for c in channels)
