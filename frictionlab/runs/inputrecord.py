"""What a run folder records of its input files, and what a resume checks against it: each
file's SHA-256, and what was read from it (shape, pixel size, unit, channel, levelling, rms
height: the spectrum's ``input_summary``). The hash catches a file that changed; what was
read catches a file read otherwise, by another version of frictionlab (another channel
taken, another levelling), whose realizations a resume would mix with the stored ones."""

from __future__ import annotations

import math

from ..errors import FrictionlabError, RunFolderError, short_repr, shown, shown_name
from ..io.inputs import InputFileProblem, sha256_of
from ..plugin.outputs import input_summary_problem, refuse
from ..preset import Scene

PROSE = frozenset({"caveats", "channel_note", "file"})  # how it is said, and where it lay: not what was read


def file_hashes(scene: Scene) -> dict:
    """``{field: {"path", "sha256"}}`` of each input file ``scene`` reads."""
    hashes = {}
    for field, path in scene.input_files().items():
        try:
            hashes[field] = {"path": path, "sha256": sha256_of(path)}
        except (InputFileProblem, OSError) as exc:
            reason = exc if isinstance(exc, InputFileProblem) else exc.strerror
            raise FrictionlabError(f"{field}: cannot read {shown_name(path)}: {reason}") from None
    return hashes


def what_was_read(scene: Scene) -> dict | None:
    """The spectrum's ``input_summary`` less its prose; None for a spectrum that reads no file. Read
    as the run starts: one summary.json could not hold is refused by the plugin's name then."""
    summary = scene.spectrum.input_summary()
    refuse(scene.spectrum, input_summary_problem(summary))
    return None if summary is None else {key: value for key, value in summary.items() if key not in PROSE}


def input_changes(state: dict, hashes: dict, read: dict | None) -> list[str]:
    """How the inputs now (``hashes``, ``read``) differ from those ``state`` (a manifest)
    recorded, a line each. What was read is not checked where the file changed (it is read
    otherwise, of course), nor where the manifest recorded none (an older version's)."""
    recorded = state.get("inputs") if isinstance(state.get("inputs"), dict) else {}
    changes = []
    for field, now in hashes.items():
        then = recorded.get(field)
        if isinstance(then, dict) and then.get("sha256") != now["sha256"]:
            changes.append(f"the input file {field} ({now['path']}) changed since the run started (SHA-256 "
                           f"{str(then.get('sha256'))[:12]}... then, {now['sha256'][:12]}... now); restore it")  # fmt: skip
    then_read = state.get("read")
    if not changes and isinstance(then_read, dict) and read is not None:
        changes += [f"the input file is read otherwise than when the run started (another version of frictionlab): {line}"
                    for line in _differences(then_read, read)]  # fmt: skip
    return changes


def refuse_changed_inputs(folder, state: dict, hashes: dict, read: dict | None) -> None:
    """RunFolderError saying how the inputs changed, if they did: a resume would mix the two."""
    changes = input_changes(state, hashes, read)
    if changes:
        raise RunFolderError(f"cannot resume {shown_name(folder)}: " + "; ".join(changes)
                             + "; or start a new run in another folder")  # fmt: skip


def _differences(then: dict, now: dict) -> list[str]:
    return [f"{shown(str(key))}: {short_repr(then.get(key), 60)} then, {short_repr(now.get(key), 60)} now"
            for key in sorted(set(then) | set(now)) if not _same(then.get(key), now.get(key))]  # fmt: skip


def _same(a, b) -> bool:
    """Equal, floats to 1e-9 relative (another numpy's last bits are no other reading)."""
    if isinstance(a, float) and isinstance(b, float):
        return a == b or math.isclose(a, b, rel_tol=1e-9)
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(map(_same, a, b))
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(_same(a[k], b[k]) for k in a)
    return a == b
