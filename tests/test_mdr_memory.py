"""The memory of a surface pressed as its MDR-equivalent line: the line is short
(2 sqrt(A / pi) / dx points), but the main process makes it from the whole surface
(its synthesis, or its map read and transformed). The check counts that making and runs
before it, and worker processes are sent the line, not what the surface derived."""

from __future__ import annotations

import pickle
import tracemalloc

import numpy as np
import pytest

from frictionlab.compute import engine, memory
from frictionlab.errors import RunError
from frictionlab.options import RunOptions
from frictionlab.preset import Scene, build_scene
from frictionlab.runs.runner import memory_check_before_reading

from .conftest import SMALL_PRESET, merge
from .test_executors import same_numbers

MiB = 2**20


def mdr_surface(points: int, **changes) -> dict:
    """A power-law surface with every mode of its grid in the band (short_cutoff 2 pixels:
    the largest synthesis per point), pressed by MDR."""
    return merge(SMALL_PRESET, {
        "realizations": 2, "fit": {"bootstrap": 20},
        "spectrum": {"name": "power-law-2d", "params": {"hurst": 0.8, "points": points, "spacing": 1.0,
                                                         "short_cutoff": 2.0, "rms_height": 1.0}},
        **changes,
    })  # fmt: skip


def mdr_map(path, **params) -> dict:
    data = merge(SMALL_PRESET, {"realizations": 1, "fit": {"bootstrap": 20}})
    data["spectrum"] = {"name": "surface-file", "params": {"path": str(path), "spacing": 1.0, **params}}
    return data


def before_its_line(scene: Scene) -> Scene:
    """The scene ``build_scene`` checks: the same, its line not made yet."""
    return Scene(preset=scene.preset, spectrum=scene.spectrum, solver=scene.solver, slope=scene.slope)


def traced_peak(make) -> int:
    """Bytes numpy and Python allocate at the peak of ``make()`` above what was in use before."""
    tracemalloc.start()
    try:
        floor = tracemalloc.get_traced_memory()[0]
        make()
        return tracemalloc.get_traced_memory()[1] - floor
    finally:
        tracemalloc.stop()


def test_a_surface_too_large_for_its_line_to_be_made_is_refused_before_it_is_made(registry, monkeypatch):
    """The check ran on the line alone (2,312 points here) once the whole surface had been
    synthesised to make it: a surface too large to synthesise died of MemoryError, a request
    the check passed. It is refused first, naming the making, with a side that fits."""
    data = mdr_surface(2048)
    monkeypatch.setattr(memory, "available_memory", lambda: (256 * MiB, "a test limit"))
    checked = []

    def check(scene):
        checked.append(scene)
        memory_check_before_reading(RunOptions(workers=1))(scene)

    with pytest.raises(RunError) as caught:
        build_scene(data, registry=registry, before_reading=check)
    message = str(caught.value)
    assert "making the MDR-equivalent line of a surface of 4,194,304 points" in message, message
    assert "but 0.25 GiB is available (a test limit)" in message
    # refused before anything in proportion to the surface (8 bytes a point is one array of it)
    peak = traced_peak(lambda: pytest.raises(RunError, build_scene, data, registry=registry, before_reading=check))
    assert peak < 2048**2
    side = int(message.split("spectrum.params.points <= ")[1].split(".")[0].replace(",", ""))
    provisional = checked[0]
    assert provisional.equivalent_line is None and provisional.spectrum.params.points == 2048
    fits = memory.estimate(provisional, workers=1, executor="serial", points=side**2).total
    too_many = memory.estimate(provisional, workers=1, executor="serial", points=(side + 1) ** 2).total
    assert fits <= 0.98 * 256 * MiB < too_many  # 2 % to spare
    monkeypatch.setattr(memory, "available_memory", lambda: (fits, "a test limit"))
    scene = build_scene(mdr_surface(side), registry=registry, before_reading=check)  # the side offered is made
    assert scene.equivalent_line.grid_shape() == (memory.line_points(side**2),)


def test_a_map_too_large_for_its_line_to_be_made_is_refused_before_it_is_read(registry, tmp_path, monkeypatch):
    """A map pressed by MDR was read whole, then reflected and transformed, before the check,
    which counted its line alone: it is refused from its .npy header, unread, naming a
    smaller map (it has no points to offer)."""
    heights = np.random.default_rng(np.random.SeedSequence(5)).normal(size=(1024, 1024))
    np.save(tmp_path / "map.npy", heights)
    data = mdr_map(tmp_path / "map.npy")
    monkeypatch.setattr(memory, "available_memory", lambda: (192 * MiB, "a test limit"))
    check = memory_check_before_reading(RunOptions(workers=1))
    with pytest.raises(RunError) as caught:
        build_scene(data, registry=registry, before_reading=check)
    message = str(caught.value)
    assert "making the MDR-equivalent line of a surface of 1,048,576 points" in message, message
    assert "It would fit with fewer points: making the MDR-equivalent line" in message
    peak = traced_peak(lambda: pytest.raises(RunError, build_scene, data, registry=registry, before_reading=check))
    assert peak < heights.nbytes / 4


@pytest.mark.parametrize(
    "spectrum", ["power-law-2d", "periodic map", "non-periodic map"],
)
def test_the_estimate_of_making_the_line_bounds_its_measured_peak(registry, tmp_path, spectrum):
    """tracemalloc sees numpy's buffers: building the scene (the map read, its FFT, the modes
    given to the line) peaks under the estimate of making the line, and not far under it."""
    if spectrum == "power-law-2d":
        data, points = mdr_surface(1024), 1024**2
    else:
        heights = np.random.default_rng(np.random.SeedSequence(11)).normal(size=(512, 768))
        np.save(tmp_path / "map.npy", heights)
        data, points = mdr_map(tmp_path / "map.npy", periodic=spectrum == "periodic map"), heights.size
    built = []
    peak = traced_peak(lambda: built.append(build_scene(data, registry=registry)))
    guess = memory.estimate(before_its_line(built[0]), workers=1, executor="serial")
    assert guess.grid == points and guess.points == built[0].equivalent_line.grid_shape()[0]
    assert peak <= guess.making
    assert guess.making < 2.5 * peak
    # once the line is made, its making is past: the run's estimate is the line's
    assert memory.estimate(built[0], workers=1, executor="serial").making == 0


def test_workers_are_sent_the_line_not_what_the_surface_derived_to_make_it(registry):
    """Each worker process was sent the whole scene, the surface's synthesis with it (16 bytes
    a mode, as large as the surface), which no worker pressing the line uses, and which the
    estimate of a worker does not count. It is sent the line, with the same numbers."""
    scene = build_scene(mdr_surface(512, realizations=6), registry=registry)
    assert len(pickle.dumps(scene)) > 8 * 512**2  # the surface's synthesis, here
    sent = scene.for_pressing()
    assert len(pickle.dumps(sent)) < 512**2 / 8
    assert sent.equivalent_line is scene.equivalent_line and sent.spectrum.params == scene.spectrum.params
    serial = engine.run(scene, RunOptions(workers=1, executor="serial"))
    pooled = engine.run(scene, RunOptions(workers=2, executor="processes"))
    assert pooled.extra["executor"] == "processes" and pooled.done == 6
    same_numbers(serial, pooled)


def test_a_sweep_of_mdr_surfaces_checks_each_point_before_its_line_and_keeps_no_surface(registry, monkeypatch):
    """A sweep planned every point (each surface synthesised to make its line) before any
    check, and kept every point's synthesis: four 6000^2 surfaces, each of which runs alone
    under ulimit -v 2 GiB, died of MemoryError while the sweep was planned. Each point is
    checked before its line is made, and keeps its line, not its surface."""
    from frictionlab.runs.sweep import plan_sweep

    data = {**mdr_surface(1024), "sweep": {"parameters": {"spectrum.params.hurst": {"values": [0.6, 0.7, 0.8, 0.9]}}}}
    held = []

    def plan():
        held.append(plan_sweep(data, registry=registry, before_reading=lambda scene: lines.append(scene.equivalent_line)))

    lines = []  # each point's line when it was checked
    tracemalloc.start()
    try:
        floor = tracemalloc.get_traced_memory()[0]
        plan()
        kept = tracemalloc.get_traced_memory()[0] - floor
    finally:
        tracemalloc.stop()
    assert lines == [None] * 4  # each checked before its line was made
    assert [point.scene.equivalent_line is not None for point in held[0].points] == [True] * 4
    assert kept < 4 * MiB  # one surface's synthesis is 8 MiB; all four were kept (35 MB)
    monkeypatch.setattr(memory, "available_memory", lambda: (200 * MiB, "a test limit"))
    with pytest.raises(RunError, match="making the MDR-equivalent line of a surface of 4,194,304 points"):
        plan_sweep({**data, "sweep": {"parameters": {"spectrum.params.points": {"values": [256, 2048]}}}},
                   registry=registry, before_reading=memory_check_before_reading(RunOptions(workers=1)))


def test_validate_checks_each_point_of_an_mdr_sweep_before_its_line_is_made(registry, tmp_path, monkeypatch, capsys):
    """``validate`` checked a sweep's base, then made every point's line unchecked: a point
    too large passed (or died of MemoryError). It is refused, naming the making."""
    import yaml

    from frictionlab.cli import main
    from frictionlab.errors import ExitCode

    data = {**mdr_surface(256), "sweep": {"parameters": {"spectrum.params.points": {"values": [256, 2048]}}}}
    (tmp_path / "sweep.yaml").write_text(yaml.safe_dump(data))
    monkeypatch.setattr(memory, "available_memory", lambda: (256 * MiB, "a test limit"))
    assert main(["validate", str(tmp_path / "sweep.yaml")]) == ExitCode.RUNTIME_FAILURE
    assert "making the MDR-equivalent line of a surface of 4,194,304 points" in capsys.readouterr().err
