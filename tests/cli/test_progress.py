"""The CLI's progress reporter, driven by a real run."""

import io

from frictionlab.compute import engine
from frictionlab.progress import ProgressReporter
from frictionlab.options import RunOptions


class FakeTerminal(io.StringIO):
    def isatty(self):
        return True


def test_terminal_gets_a_rich_bar_that_ends_full(make_scene):
    stream = FakeTerminal()
    engine.run(make_scene({"realizations": 30}), RunOptions(workers=1), listeners=[ProgressReporter(stream, after=0)])
    text = stream.getvalue()
    assert text.startswith("small: 30 realizations of power-law lines, 16 force steps, 1 worker(s)\n")
    last = text.split("\r")[-1]
    assert "realizations" in last and "30/30" in last and "━" in last  # rich's bar, drawn in place
    assert text.removesuffix("\x1b[?25h").endswith("\n")  # the cursor shown again after the last line


def test_a_run_shorter_than_two_seconds_shows_its_first_line_and_in_a_log_its_last(make_scene):
    for interactive, lines in ((True, 1), (False, 2)):
        stream = FakeTerminal()
        reporter = ProgressReporter(stream, interactive=interactive)  # 2 s before anything more is shown
        engine.run(make_scene({"realizations": 4}), RunOptions(workers=1), listeners=[reporter])
        text = stream.getvalue()
        assert text.startswith("small: 4 realizations") and text.count("\n") == lines
        assert interactive or text.splitlines()[1].startswith("4/4 realizations")


def test_log_file_gets_one_plain_line_per_tenth(make_scene):
    stream = io.StringIO()
    reporter = ProgressReporter(stream, after=0)
    engine.run(make_scene({"realizations": 20}), RunOptions(workers=1), listeners=[reporter])
    lines = stream.getvalue().split("\n")[:-1]
    assert [line.split(" ")[0] for line in lines[1:]] == [f"{2 * i}/20" for i in range(1, 11)]
    assert "\r" not in stream.getvalue()


def test_rate_counts_only_realizations_computed_by_this_process_on_a_resume(make_scene):
    import time

    from frictionlab.compute.engine import RunInfo

    stream = io.StringIO()
    reporter = ProgressReporter(stream)
    reporter.run_started(run=RunInfo(scene=make_scene({}), total=10, workers=1, resumed=8))
    assert "(8 restored from the run folder)" in stream.getvalue()
    reporter.started = time.perf_counter() - 2.0  # 2 s for the 2 realizations left: 1 per second
    line = reporter._line(10, 10)
    assert ", 1.0/s," in line, line


def in_a_notebook(monkeypatch, widgets: bool):
    """As in a Jupyter kernel, with or without ipywidgets installed."""
    import importlib.machinery
    import sys
    import types

    ipython = types.ModuleType("IPython")

    class ZMQInteractiveShell:  # Jupyter's kernel shell, by its class name as IPython reports it
        pass

    ipython.get_ipython = ZMQInteractiveShell
    monkeypatch.setitem(sys.modules, "IPython", ipython)
    fake = types.ModuleType("ipywidgets")
    fake.__spec__ = importlib.machinery.ModuleSpec("ipywidgets", None)
    monkeypatch.setitem(sys.modules, "ipywidgets", fake if widgets else None)  # None: not installed
    return ipython


def test_a_notebook_with_ipywidgets_gets_a_bar_even_without_a_terminal(monkeypatch):
    from frictionlab.progress import wants_bar

    assert not wants_bar(io.StringIO())
    ipython = in_a_notebook(monkeypatch, widgets=True)
    assert wants_bar(io.StringIO())
    ipython.get_ipython = lambda: None  # IPython imported, but a plain terminal shell or none
    assert not wants_bar(io.StringIO())


def test_a_notebook_without_ipywidgets_gets_plain_lines_and_no_warning(monkeypatch, make_scene, recwarn):
    in_a_notebook(monkeypatch, widgets=False)
    stream = io.StringIO()
    reporter = ProgressReporter(stream, after=0)
    assert not reporter.interactive
    engine.run(make_scene({"realizations": 10}), RunOptions(workers=1), listeners=[reporter])
    lines = stream.getvalue().splitlines()
    assert lines[0].startswith("small: 10 realizations") and lines[-1].startswith("10/10 realizations")
    assert "\r" not in stream.getvalue() and "\x1b" not in stream.getvalue()
    assert not [w for w in recwarn if "ipywidgets" in str(w.message)]


def test_the_first_line_counts_the_workers_that_run_not_those_asked_for(make_scene):
    stream = FakeTerminal()
    engine.run(make_scene({"realizations": 6}), RunOptions(workers=4, executor="serial"), listeners=[ProgressReporter(stream, after=0)])
    assert stream.getvalue().startswith("small: 6 realizations of power-law lines, 16 force steps, 1 worker(s)\n")


def test_more_workers_than_cores_are_said_to_take_turns(make_scene, monkeypatch):
    monkeypatch.setattr(engine, "default_workers", lambda: 1)  # a machine of one core
    stream = FakeTerminal()
    engine.run(make_scene({"realizations": 4}), RunOptions(workers=2, executor="processes"),
               listeners=[ProgressReporter(stream, after=0)])  # fmt: skip
    first = stream.getvalue().splitlines()[0]
    assert first.endswith(", 2 worker(s) on 1 core(s): they take turns, no faster than 1")
    stream = FakeTerminal()  # as many as the cores: nothing to say
    engine.run(make_scene({"realizations": 4}), RunOptions(workers=1, executor="processes"),
               listeners=[ProgressReporter(stream, after=0)])  # fmt: skip
    assert stream.getvalue().splitlines()[0].endswith(", 1 worker(s)")


def test_a_pool_the_run_may_still_go_without_is_said_as_the_most_workers_it_takes(make_scene):
    """`run --workers 8` began "8 worker(s) on 2 core(s)" and ended "(1 worker)": the default pool
    gives way to this process where the work would not repay its start (the first realization
    tells). The first line says "up to"; an executor asked for by name runs as asked."""
    outcomes = []
    for executor, said in ((None, ", up to 2 worker(s)"), ("processes", ", 2 worker(s)")):
        stream = FakeTerminal()
        outcomes.append(engine.run(make_scene({"realizations": 4}), RunOptions(workers=2, executor=executor),
                                   listeners=[ProgressReporter(stream, after=0)]))  # fmt: skip
        assert stream.getvalue().splitlines()[0].split(" on ")[0].endswith(said), stream.getvalue()
    assert outcomes[0].workers == 1  # four small realizations: not worth a pool


def test_a_run_replayed_from_its_log_does_not_guess_the_cores_it_ran_on(make_scene):
    """A run followed from its progress log (``frictionlab follow``, maybe copied from another
    machine) says its workers, never this machine's cores beside them."""
    from frictionlab.compute.engine import RunInfo

    stream = FakeTerminal()
    ProgressReporter(stream, after=0).run_started(RunInfo(scene=make_scene({}), total=4, workers=64, executor="processes"))
    assert stream.getvalue().splitlines()[0].endswith(", 64 worker(s)")


def test_the_first_line_of_a_run_of_one_realization_says_realization(make_scene):
    """A measured scan runs one realization: "1 realization of", as validate says it, not
    "1 realizations of"."""
    stream = FakeTerminal()
    engine.run(make_scene({"realizations": 1}), RunOptions(workers=1), listeners=[ProgressReporter(stream, after=0)])
    assert stream.getvalue().startswith("small: 1 realization of power-law lines, 16 force steps")


def notebook_display(monkeypatch):
    """As in a Jupyter kernel with ipywidgets: what rich displays is collected in the list returned."""
    import builtins
    import sys
    import types

    ipython = in_a_notebook(monkeypatch, widgets=True)
    monkeypatch.setattr(builtins, "get_ipython", ipython.get_ipython, raising=False)  # as IPython's kernel sets it
    shown = []
    display = types.ModuleType("IPython.display")
    display.display = lambda *objects, **_: shown.extend(objects)
    monkeypatch.setitem(sys.modules, "IPython.display", display)

    class Output:  # ipywidgets' output area: what is displayed within it goes to the bar's own place
        def __enter__(self):
            return self

        def __exit__(self, *exc):
            return False

        def clear_output(self, wait=False):
            pass

    sys.modules["ipywidgets"].Output = Output
    return shown


def test_a_notebook_bar_leaves_no_empty_output_under_it(monkeypatch, make_scene):
    """rich, stopping its bar in a notebook, showed its console's empty buffer: an empty output
    (a blank line) under every bar, one a point in a sweep."""
    shown = notebook_display(monkeypatch)
    reporter = ProgressReporter(io.StringIO(), after=0)
    assert reporter.interactive
    engine.run(make_scene({"realizations": 10}), RunOptions(workers=1), listeners=[reporter])
    texts = [getattr(item, "text", None) for item in shown if type(item).__name__ != "Output"]
    assert texts and "10/10" in texts[-1]  # the bar drawn full at its end
    assert all(text.strip() for text in texts), texts


def test_a_notebook_bar_is_redrawn_once_a_second_not_ten_times(monkeypatch):
    """In a notebook each redraw of rich's bar is an output cleared and sent again, changed or
    not: ten a second flooded the kernel's channel (817 outputs over a solve of two minutes,
    all alike but the second)."""
    from frictionlab.progress import _Bar

    terminal = _Bar(FakeTerminal(), "realizations", 10)
    terminal.stop()
    assert terminal.progress.live.refresh_per_second == 10
    notebook_display(monkeypatch)
    bar = _Bar(io.StringIO(), "realizations", 10)
    bar.stop()
    assert bar.progress.console.is_jupyter and bar.progress.live.refresh_per_second == 1


def test_what_was_printed_before_a_run_goes_out_before_its_progress(monkeypatch, make_scene):
    """In a notebook, ``print("start"); frictionlab.run(...)`` showed the run's first progress
    line above "start": stdout waits in a buffer, stderr is flushed at once."""
    import sys

    sent = []

    class Buffered(io.StringIO):  # stdout as a kernel's or a pipe's: sent when flushed
        def flush(self):
            if self.getvalue():
                sent.append(("stdout", self.getvalue()))
                self.seek(0)
                self.truncate()

    class Progress(io.StringIO):
        def write(self, text):
            sent.append(("stderr", text))
            return len(text)

    monkeypatch.setattr(sys, "stdout", Buffered())
    print("start")
    engine.run(make_scene({"realizations": 2}), RunOptions(workers=1), listeners=[ProgressReporter(Progress(), after=0)])
    assert sent[0] == ("stdout", "start\n") and sent[1][0] == "stderr", sent
