"""The chunk file of a run folder: one ``.npz`` of the realizations it holds, its
name their index range; written by ``chunk_bytes``, read back by ``read_chunk``,
which trusts nothing it has not checked (the SHA-256 the manifest lists, every
array's name and shape, the indices against the run's)."""

from __future__ import annotations

import hashlib
import io
import math
import os
import re
import zipfile
from pathlib import Path

import numpy as np

from ..compute.ensemble import OWN_H_TOLERANCE
from ..compute.realization import RealizationResult
from ..errors import OutputRefused, RunFolderError, first_names, shown
from ..io.files import npy_header, npz_unpacked_problem, output_path_problem
from ..io.inputs import InputFileProblem
from ..preset import Scene
from .runfolder import MAX_WALL_SECONDS, open_member, read_member

CHUNK_DIR = "chunks"
MAX_CHUNK_DIRECTORY_BYTES = 256 * 1024  # a chunk's ~30 arrays list in under 8 kB of its zip's central directory
MAX_CHUNK_BYTES = 16 * 1024**3  # a chunk holds curves of many realizations; larger is no run's
# of a failed realization's error, as text (4 bytes a character): a bound on an array's size; an error is
# recorded cut to compute.realization.MAX_ERROR_CHARACTERS (16,000 bytes), an older chunk's may be longer
ERROR_BYTES = 1 << 18
CHUNK_NAME = re.compile(r"(\d{8})-(\d{8})(?:\.(\d+))?\.npz")
OK_ARRAYS = ("index", "seconds", "slope_rms_line", "points", "force_unit")
FAILED_ARRAYS = ("failed_index", "failed_seconds", "failed_error")
CURVE_ARRAYS = ("xi", "contact_count", "indentation")
OPTIONAL_CURVE_ARRAYS = ("force", "real_area_corrected", "real_gradient_rms", "contact_spots")
ADDED_OPTIONAL_ARRAYS = frozenset({"real_gradient_rms", "contact_spots"})  # of those, absent from older chunks: NaN
ADDED_CURVE_ARRAYS = ("half_load_points",)  # kept by every run, absent from the chunks of older versions: NaN
HEIGHT_ARRAYS = ("measured_rms_height", "own_rms_height", "peak_rms")  # absent from the chunks of older versions: NaN
ENTRY_BYTES = 1024  # of an array in a chunk besides its values: its zip entry's two headers and its .npy header, ~300 bytes


class ChunkDamage(ValueError):
    """A chunk file whose content is not what a chunk of this run can hold."""


def check_chunk_folder(folder: Path) -> None:
    """Refuse, before any realization runs, a chunks/ the run cannot keep its realizations in: a
    link or no folder (never written or read through), or a folder no file can be created in (a
    resume computed a chunk, lost it when it could not be written, and said to resume again)."""
    if os.path.islink(folder) or (os.path.lexists(folder) and not folder.is_dir()):
        raise RunFolderError(
            f"{shown(folder)} is not a folder (a link, a file, ...): chunks are never written or read through it "
            "(remove it, or give another folder)"
        )
    if folder.is_dir() and (problem := output_path_problem(folder)):
        raise OutputRefused(f"{problem}: the run keeps its realizations there; make it writable, then run again")


def chunk_bytes(results: list[RealizationResult]) -> bytes:
    """One chunk file's bytes: the arrays of ``results`` (finished and failed), saved by numpy."""
    ok = [r for r in results if r.ok]
    failed = [r for r in results if not r.ok]
    arrays: dict[str, np.ndarray] = {
        "index": np.array([r.index for r in ok], dtype=np.int64),
        "seconds": np.array([r.seconds for r in ok], dtype=np.float64),
        "slope_rms_line": np.array([r.slope_rms_line for r in ok], dtype=np.float64),
        "points": np.array([r.points for r in ok], dtype=np.int64),
        "force_unit": np.array([r.force_unit for r in ok], dtype=np.float64),
        "measured_rms_height": np.array([r.measured_rms_height for r in ok], dtype=np.float64),
        "own_rms_height": np.array([r.own_rms_height for r in ok], dtype=np.float64),
        "peak_rms": np.array([r.peak_rms for r in ok], dtype=np.float64),
        "failed_index": np.array([r.index for r in failed], dtype=np.int64),
        "failed_seconds": np.array([r.seconds for r in failed], dtype=np.float64),
        "failed_error": np.array([r.error for r in failed], dtype=str),
    }
    for name in (*CURVE_ARRAYS, *OPTIONAL_CURVE_ARRAYS, *ADDED_CURVE_ARRAYS):
        rows = [getattr(r, name) for r in ok]
        if ok and rows[0] is not None:
            arrays[name] = np.vstack(rows)
    buffer = io.BytesIO()
    np.savez(buffer, **arrays)  # not compressed: deflate costs 10x the write, and the chunks are a working store
    data = buffer.getvalue()
    return data


def most_chunk_bytes(held: int, steps: int) -> int:
    """The largest file ``chunk_bytes`` writes for ``held`` realizations of ``steps`` load steps,
    each finished (8 bytes in each per-realization array, 8 a step in each curve any solver keeps)
    or failed (8 bytes in its index and its time, its error at most ERROR_BYTES): a larger file is
    refused before it is read (a chunk of 877 realizations, 1 MB, grown to 3 GB was read whole and
    a resume ran out of memory, again at each resume)."""
    curves = CURVE_ARRAYS + OPTIONAL_CURVE_ARRAYS + ADDED_CURVE_ARRAYS
    finished = 8 * (len(OK_ARRAYS + HEIGHT_ARRAYS) + steps * len(curves))
    failed = 8 * 2 + ERROR_BYTES
    arrays = len(OK_ARRAYS + HEIGHT_ARRAYS + FAILED_ARRAYS + curves)
    return min(MAX_CHUNK_BYTES, held * max(finished, failed) + arrays * ENTRY_BYTES)


def damage_report(chunk_dir: Path, listed: set[str], damaged: dict[str, str], kept: set[int], total: int) -> str:
    """What a resume found wrong in ``chunk_dir``: the ``damaged`` chunks (name: why) and the
    files the manifest does not ``list``, with how many of the ``total`` realizations they held
    are not ``kept`` elsewhere and so are recomputed; empty when nothing is wrong."""
    unlisted = sorted(
        p.name for p in chunk_dir.glob("*.npz") if p.name not in listed and p.name not in damaged
    ) if chunk_dir.is_dir() else []  # fmt: skip
    if not damaged and not unlisted:
        return ""
    lost = set()
    for name in [*damaged, *unlisted]:
        match = CHUNK_NAME.fullmatch(name)
        if match:
            lost.update(range(int(match[1]), min(int(match[2]), total - 1) + 1))
    lost -= kept
    reasons: dict[str, list[str]] = {}
    for name, why in damaged.items():
        reasons.setdefault(why, []).append(name)
    parts = []
    if damaged:  # each reason with the files it was found in
        detail = "; ".join(f"{first_names(names)}: {why}" for why, names in reasons.items())
        parts.append(f"{len(damaged)} chunk file(s) failed verification ({detail})")
    if unlisted:
        parts.append(f"{len(unlisted)} file(s) in {CHUNK_DIR}/ are not in the manifest and are ignored")
    return "; ".join(parts) + f"; {len(lost)} realization(s) they held are recomputed"


def read_chunk(folder: Path, name: str, digest, scene: Scene) -> list[RealizationResult]:
    """The results in chunk ``name`` of the run folder ``folder``, verified against its
    listed SHA-256 ``digest`` and against ``scene``; ChunkDamage when anything is off."""
    match = CHUNK_NAME.fullmatch(name) if isinstance(name, str) else None
    if match is None or not isinstance(digest, str):
        raise ChunkDamage("not a chunk name")
    first, last = int(match[1]), int(match[2])
    held = max(1, min(last - first + 1, scene.preset.realizations))  # realizations it can hold
    try:
        raw = read_member(folder, f"{CHUNK_DIR}/{name}", most_chunk_bytes(held, scene.loads.size), what="file")
    except InputFileProblem as exc:
        raise ChunkDamage("missing" if str(exc).startswith("no such") else str(exc)) from None
    if hashlib.sha256(raw).hexdigest() != digest:
        raise ChunkDamage("checksum mismatch")
    try:
        with _check_archive(io.BytesIO(raw)) as archive:  # its directory parsed once, for the sizes it declares
            problem = npz_unpacked_problem(archive, held * (scene.loads.size * 8 + ERROR_BYTES) + 4096)
        if problem is None:
            with np.load(io.BytesIO(raw), allow_pickle=False) as data:
                arrays = {key: data[key] for key in data.files}
    except Exception as exc:  # a damaged zip or array header
        raise ChunkDamage(f"unreadable ({type(exc).__name__})") from None
    if problem is not None:
        raise ChunkDamage(problem)
    return chunk_results(arrays, first, last, scene)


def chunk_indices(folder: Path, name: str) -> set[int]:
    """The realizations chunk ``name`` of the run folder ``folder`` holds (finished and
    failed), read from its two index arrays alone: what a resume restores of it, counted
    without reading its curves (its name's range may have gaps: realizations finish out of
    order). Its checksum is not verified here, a resume does; a file that cannot be read as
    a chunk, or whose indices lie outside its name's range, holds none."""
    match = CHUNK_NAME.fullmatch(name) if isinstance(name, str) else None
    if match is None:
        return set()
    first, last = int(match[1]), int(match[2])
    held = []
    try:
        with open_member(folder, f"{CHUNK_DIR}/{name}", "chunk") as fh, _check_archive(fh) as archive:
            size = os.fstat(fh.fileno()).st_size  # no array in it is larger
            for array in ("index", "failed_index"):
                with archive.open(f"{array}.npy") as member:
                    held.append(_index_array(member, last - first + 1, size))
    except (InputFileProblem, KeyError, ValueError, OSError, EOFError, MemoryError, zipfile.BadZipFile):
        return set()
    indices = np.concatenate(held)
    if indices.size and (indices.min() < first or indices.max() > last):
        return set()
    return set(indices.tolist())


def _check_archive(fh) -> zipfile.ZipFile:
    """The zip archive ``fh`` once its central directory is known to be a chunk's size: zipfile
    parses all of it at once, some 600 bytes of memory for each 90-byte entry (a forged chunk of a
    few hundred MB would take gigabytes). ``zipfile._EndRecData`` reads the end record alone."""
    end = zipfile._EndRecData(fh)
    if end is None:
        raise zipfile.BadZipFile("not a zip archive")
    if end[zipfile._ECD_SIZE] > MAX_CHUNK_DIRECTORY_BYTES:
        raise ValueError("a central directory larger than any chunk's")
    return zipfile.ZipFile(fh)


def _index_array(member, most: int, file_size: int) -> np.ndarray:
    """A 1-D integer .npy array of at most ``most`` values read from ``member`` of a file of
    ``file_size`` bytes, its header checked before anything is allocated (a forged shape
    must not size a buffer)."""
    shape, dtype = npy_header(member)
    if len(shape) != 1 or dtype.kind not in "iu" or shape[0] > most or shape[0] * dtype.itemsize > file_size:
        raise ValueError("not an index array")
    raw = member.read(min(shape[0] * dtype.itemsize, file_size))
    if len(raw) != shape[0] * dtype.itemsize:
        raise ValueError("a short index array")
    return np.frombuffer(raw, dtype).astype(np.int64)


# An rms over some of n values is at most sqrt(n) times their rms (its largest square is at most
# their sum): xi, the rms slope in contact over the profile's, is at most sqrt(points); twice
# that leaves room for a plugin's own weighting. A forged xi of 1e308 overflowed the fit.
XI_BOUND = 2.0
# A per-realization value past this is no run's: the ensemble means add up to 10^7 of them (a
# preset's most realizations) and stay finite (a forged indentation of 1e308 overflowed its mean).
VALUE_BOUND = 1e300
# what a realization can give in each column besides xi and the counts: (least, most, NaN allowed)
VALUE_RANGES = {
    "indentation": (-VALUE_BOUND, VALUE_BOUND, False),  # finite, as a solver's curve must be
    "force": (-VALUE_BOUND, VALUE_BOUND, False),
    "real_area_corrected": (0.0, VALUE_BOUND, False),
    "real_gradient_rms": (0.0, VALUE_BOUND, True),  # NaN: a chunk of a version before it, as below
    "slope_rms_line": (0.0, VALUE_BOUND, False),
    "measured_rms_height": (0.0, VALUE_BOUND, True),
    "own_rms_height": (0.0, VALUE_BOUND, True),
    "peak_rms": (0.0, VALUE_BOUND, True),  # a forged peak of inf was a caveat of the run
    "seconds": (0.0, MAX_WALL_SECONDS, True),
    "failed_seconds": (0.0, MAX_WALL_SECONDS, True),
}


def _check_values(arrays: dict, numeric: tuple[str, ...]) -> None:
    """ChunkDamage unless each of ``numeric`` holds real numbers (a forged chunk's text or
    complex arrays reached the statistics), ``failed_error`` is text, and the values are what a
    realization can give: each column within its ``VALUE_RANGES`` (the message names the
    column, the value and the range), xi none infinite, below 0 or above ``XI_BOUND`` sqrt(points), each
    profile of 1 point or more, its rms slope finite and > 0 and its force unit > 0 (NaN there
    failed the run as a preset's magnitudes), its contact counts and the points carrying half the
    load (NaN: not said) from 0 to its points (a chunk that broke these was restored, and its run
    folder written as its load refuses)."""
    for name in numeric:
        if arrays[name].dtype.kind not in "iuf":
            raise ChunkDamage(f"array {name} of type {arrays[name].dtype}, not real numbers")
    if arrays["failed_error"].dtype.kind != "U":
        raise ChunkDamage(f"array failed_error of type {arrays['failed_error'].dtype}, not text")
    for name in (name for name in VALUE_RANGES if name in numeric):
        _check_range(name, arrays[name], *VALUE_RANGES[name])
    if "xi" not in numeric:  # no finished realization
        return
    if bool((np.isinf(arrays["xi"]) | (arrays["xi"] < 0)).any()):
        raise ChunkDamage("xi infinite or below 0")
    points = arrays["points"][:, None]
    if not bool((np.isfinite(points) & (points >= 1) & (points == np.floor(points))).all()):  # NaN failed int()
        raise ChunkDamage("a profile's points not a whole number >= 1")
    if bool((arrays["xi"] > XI_BOUND * np.sqrt(points)).any()):  # NaN compares false: allowed
        raise ChunkDamage("xi above what an rms over some of a profile's slopes can be")
    if not bool((arrays["slope_rms_line"] > 0).all()):
        raise ChunkDamage("a line's rms slope not a finite number > 0")  # a realization with one is a failure
    if not bool((arrays["force_unit"] > 0).all()):  # NaN compares false: refused (inf: the run's own check says it)
        raise ChunkDamage("a force unit k h X not > 0")
    for name in (name for name in ("contact_count", "half_load_points", "contact_spots") if name in numeric):
        if bool(((arrays[name] < 0) | (arrays[name] > points)).any()):  # NaN compares false: allowed
            raise ChunkDamage(f"{name} below 0 or above the profile's points")


def _check_range(name: str, values: np.ndarray, least: float, most: float, nan: bool, digits: int = 6) -> None:
    bad = ~((values >= least) & (values <= most))  # NaN too
    if nan:
        bad &= ~np.isnan(values)
    if bool(bad.any()):
        value = float(values.flat[int(np.argmax(bad))])
        raise ChunkDamage(f"{name} {value:.{digits}g}, not from {least:.{digits}g} to {most:.{digits}g}{' (or NaN)' if nan else ''}")


def _check_force_unit(values: np.ndarray, scene: Scene) -> None:
    """ChunkDamage unless each realization's force unit k h X is the run's (realization 0's profile
    gives it, and every profile shares it: the ensemble forms f with the first one's). A forged
    chunk's other unit moved f, and so the fitted law."""
    unit, spread = scene.load_scales.force_unit, OWN_H_TOLERANCE  # the spread the profiles' own h may have
    _check_range("force_unit", values, unit * (1 - spread), unit * (1 + spread), False, digits=12)


def _optional_kept(scene: Scene) -> tuple[bool, ...]:
    """Whether a realization of ``scene`` keeps each of ``OPTIONAL_CURVE_ARRAYS``."""
    solver = scene.solver
    return scene.forces_vary, solver.corrected_area, solver.real_gradient, solver.counts_spots


def chunk_results(arrays: dict, first: int, last: int, scene: Scene) -> list[RealizationResult]:
    """The RealizationResults of one chunk's arrays; ChunkDamage if anything is
    missing, misshapen, or indexes a realization the chunk cannot hold."""
    needed = (*OK_ARRAYS, *FAILED_ARRAYS)
    missing = [name for name in needed if name not in arrays]
    if missing:
        raise ChunkDamage(f"no array {missing[0]}")
    n, k, steps = arrays["index"].shape[0], arrays["failed_index"].shape[0], scene.loads.size
    curves = (*CURVE_ARRAYS, *(name for name, kept in zip(OPTIONAL_CURVE_ARRAYS, _optional_kept(scene)) if kept))
    for name in ADDED_OPTIONAL_ARRAYS.intersection(curves):
        if n and name not in arrays:  # a chunk of a version before it: the values are unknown
            arrays = {**arrays, name: np.full((n, steps), math.nan)}
    for name in OK_ARRAYS + (curves if n else ()):
        if name not in arrays:
            raise ChunkDamage(f"no array {name}")
        shape = (n, steps) if name in curves else (n,)
        if arrays[name].shape != shape:
            raise ChunkDamage(f"array {name} of shape {arrays[name].shape}, expected {shape}")
    for name in FAILED_ARRAYS:
        if arrays[name].shape != (k,):
            raise ChunkDamage(f"array {name} of shape {arrays[name].shape}, expected {(k,)}")
    indices = np.concatenate([arrays["index"], arrays["failed_index"]])
    if indices.dtype.kind not in "iu":
        raise ChunkDamage("indices are not integers")
    low, high = max(first, 0), min(last, scene.preset.realizations - 1)
    repeated = indices.size > 1 and bool((np.diff(np.sort(indices)) == 0).any())  # not np.unique: it imports numpy.ma
    if indices.size == 0 or indices.min() < low or indices.max() > high or repeated:
        raise ChunkDamage(f"indices outside {first}..{last} of this run, or repeated")
    heights = {}  # absent from the chunks of older versions: NaN
    for name in HEIGHT_ARRAYS:
        heights[name] = arrays.get(name, np.full(n, math.nan))
        if heights[name].shape != (n,):
            raise ChunkDamage(f"array {name} of shape {heights[name].shape}, expected {(n,)}")
    for name in ADDED_CURVE_ARRAYS:
        heights[name] = arrays.get(name, np.full((n, steps), math.nan))
        if heights[name].shape != (n, steps):
            raise ChunkDamage(f"array {name} of shape {heights[name].shape}, expected {(n, steps)}")
    _check_values({**arrays, **heights}, (*OK_ARRAYS, *(curves if n else ()), *heights, "failed_seconds"))
    if n:
        _check_force_unit(arrays["force_unit"], scene)
    out = []
    for row, index in enumerate(arrays["index"].tolist()):
        out.append(RealizationResult(
            index=index,
            seconds=float(arrays["seconds"][row]),
            xi=arrays["xi"][row],
            contact_count=arrays["contact_count"][row],
            indentation=arrays["indentation"][row],
            force=arrays["force"][row] if "force" in curves else None,
            real_area_corrected=arrays["real_area_corrected"][row] if "real_area_corrected" in curves else None,
            real_gradient_rms=arrays["real_gradient_rms"][row] if "real_gradient_rms" in curves else None,
            contact_spots=arrays["contact_spots"][row] if "contact_spots" in curves else None,
            slope_rms_line=float(arrays["slope_rms_line"][row]),
            points=int(arrays["points"][row]),
            force_unit=float(arrays["force_unit"][row]),
            measured_rms_height=float(heights["measured_rms_height"][row]),
            own_rms_height=float(heights["own_rms_height"][row]),
            peak_rms=float(heights["peak_rms"][row]),
            half_load_points=np.asarray(heights["half_load_points"][row], dtype=float),
        ))  # fmt: skip
    for row, index in enumerate(arrays["failed_index"].tolist()):
        out.append(RealizationResult(
            index=index, seconds=float(arrays["failed_seconds"][row]), error=str(arrays["failed_error"][row])
        ))  # fmt: skip
    return out
