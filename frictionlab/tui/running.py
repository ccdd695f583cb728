"""The app's runs: starting one (or a sweep) as a process of its own, resuming one,
following one another process started, and showing how each ended on the Run tab.

``RunControl`` is a part of ``FrictionlabApp`` (a mixin): it uses the app's status line
(``say``), its panes and its draft preset.
"""

from __future__ import annotations

import os

from contextlib import suppress
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING

from textual.css.query import NoMatches
from textual.widgets import TabbedContent

from ..io.files import real_path
from ..errors import FrictionlabError, PresetError, RunFolderError, command_word, counted, shown, shown_name
from ..options import RunOptions
from ..preset import build_scene, resolve_input_paths
from .folders import read_run, read_sweep
from .messages import RunCrashed, RunFinished
from .screens import QuitDuringRunScreen, QuitRunEndedScreen, QuitUnsavedScreen
from .text import failure_message

if TYPE_CHECKING:
    from .following import FollowedRun

NO_RESUME_HELPS = ("A resume computes nothing new and fails the same way: change the preset as that says, then run it "
                   "again (Ctrl+R).")  # fmt: skip

# A run's modules (its process, its folder, its log, the Run tab) are imported where a run is
# started or followed: the first screen needs none of them, and it is drawn before they load.

NO_PRESET = "No preset open: F2 lists them (Enter opens one, n makes a new one)."


class RunControl:
    """Starting, resuming, following and cancelling runs (``FrictionlabApp``'s)."""

    def action_start_run(self) -> None:
        from ..io.files import output_path_problem
        from ..runs.rundir import new_run_folder
        from ..runs.sweep import plan_sweep

        if self.running:
            self.say("A run is going; c on the Run tab cancels it.", "warning")
            return
        data = self._draft()
        if data is None:
            self.say(NO_PRESET, "warning")
            return
        try:
            if self.draft_path is not None:  # relative input files are the preset file's neighbours
                data = resolve_input_paths(data, self.draft_path.parent, self.registry)
            scene = build_scene(data, registry=self.registry)
            sweep = None
            if scene.preset.sweep is not None:  # every point is checked before any runs
                source = str(self.draft_path) if self.draft_path else None
                sweep = plan_sweep(data, registry=self.registry, source=source)
        except PresetError as exc:
            count = len(exc.problems)
            self.say(exc.problems[0], "error", title=f"Cannot run: {count} problem{'s' if count != 1 else ''}")
            self.blocked_by = exc.problems[0]
            self.query_one("#tabs", TabbedContent).active = "edit"
            form = self.query_one("#form")
            form.revalidate(changed=False)  # a file may have gone since the last keystroke: mark it now
            form.focus_problem(exc.problems)
            return
        try:
            out_dir = new_run_folder(scene.preset.name, self.runs_dir)  # made now: it claims the name
        except FrictionlabError as exc:  # the runs folder is a file
            self.say(output_path_problem(self.runs_dir) or str(exc), "error", title="Run failed")
            return
        except OSError as exc:  # it cannot be made: read-only, not the user's
            self.say(f"no run folder can be made in {shown(self.runs_dir)} ({exc.strerror or exc}): quit and start "
                     "the TUI in a folder you can write in, or give one: frictionlab tui --runs DIR", "error",
                     title="Cannot run")  # fmt: skip
            return
        self._start(scene, sweep, out_dir, self.run_options)

    def _refuse_damaged(self, folder: Path, reason: str) -> None:
        self.say(f"{shown_name(folder.name)} is damaged: {reason}. Nothing of it was changed; move it aside "
                 "or repair that file to go on.", "error", title="Cannot resume", about=folder)  # fmt: skip

    def resume_run(self, folder: Path | None) -> None:
        """Continue a cancelled or interrupted run in ``folder`` with the preset stored
        there (``frictionlab resume``): only the missing realizations are computed."""
        if self.running:
            self.say("A run is going; c on the Run tab cancels it.", "warning")
            return
        if folder is None:
            self.say("No run to resume: F5 lists the runs (u there resumes the highlighted one).", "warning")
            return
        if not os.path.lexists(folder):  # removed since it ended (it was said to be 'not a run folder, or a link')
            self.last_resumable = self.last_resumable and folder != self.last_out_dir
            self.refresh_bindings()  # u leaves the Run tab's footer
            self.say(f"{shown(folder)} was removed from disk: nothing is left to resume; Ctrl+R runs the preset "
                     "again.", "warning", about=folder)  # fmt: skip
            return
        from ..runs.detached import run_state

        try:
            state = run_state(folder)
            if state.status == "running":
                if self.followed is None:
                    self._follow_the_winner(folder, state.pid)
                else:
                    self.show_running(folder)
                return
            if state.kind == "sweep" and state.status == "completed":
                self.say(f"{shown_name(folder.name)} is complete: nothing to resume.", "warning", about=folder)
                return
            if state.kind == "sweep" and state.status == "failed" and (points := read_sweep(folder).failed_for_good.splitlines()):
                self.say(f"{shown_name(folder.name)}: every point ended, and at {counted(len(points), 'point')} all the "
                         f"realizations finished but the fit failed: {'; '.join(points)}. {NO_RESUME_HELPS}",
                         "error", title="Cannot resume", about=folder)  # fmt: skip
                return
            if state.status == "damaged":  # a resume would rewrite the damaged file: the user did not ask that
                self._refuse_damaged(folder, state.reason)
                return
        except FrictionlabError as exc:
            from ..runs.detached import damage_reason
            from ..runs.rundir import STATE_FILE

            if os.path.lexists(folder / STATE_FILE):  # its manifest cannot be read: never resumed over
                self._refuse_damaged(folder, damage_reason(folder, exc))
                return
            # not a run folder (yet): said below
        try:
            entry = read_run(folder)
        except (OSError, RunFolderError):
            entry = None  # no summary yet (a run killed early): the stored preset says whether it can go on
        if entry is not None and entry.status == "completed":
            self.say(f"{shown_name(folder.name)} is complete: nothing to resume.", "warning", about=folder)
            return
        if entry is not None and entry.failed_for_good:  # no process started: it would compute nothing
            self.say(f"{shown_name(folder.name)} failed with all its {entry.done} realizations finished: "
                     f"{entry.failed_for_good}. {NO_RESUME_HELPS}", "error", title="Cannot resume", about=folder)  # fmt: skip
            return
        stored = self._stored_or_say(folder, "resume")
        if stored is not None:
            self._start(*stored, folder, replace(self.run_options, resume=True))

    def _follow_the_winner(self, folder: Path, pid: int | None = None) -> None:
        """A resume that another process (a TUI, the CLI) began first: follow that one, and say so."""
        self.follow_run(folder)
        if self.followed is None:
            return  # the status line says why it cannot be followed
        self.action_show_tab("run")
        from ..runs.detached import lock_holder

        pid = pid or lock_holder(folder)
        self.say(f"{shown(folder.name)} was resumed by another process first (pid {pid or 'unknown'}): "
                 "this TUI follows that run; c cancels it", "warning")  # fmt: skip

    def _stored(self, folder: Path):
        """(scene, sweep) of the run stored in ``folder`` (sweep None), or of the sweep (scene
        its first point's); RunFolderError or PresetError if it holds none that can run."""
        from ..preset.paths import as_now
        from ..runs.detached import run_state
        from ..runs.rundir import RunDirectory
        from ..runs.sweep import plan_sweep
        from ..runs.sweepfiles import stored_sweep

        if run_state(folder).kind == "sweep":
            sweep = plan_sweep(stored_sweep(folder), registry=self.registry, source=str(folder / "sweep.json"))
            return sweep.points[0].scene, sweep
        stored = as_now(RunDirectory(folder).stored_preset())[0]  # a value since retired: the resume says so
        return build_scene(stored, registry=self.registry), None

    def _stored_or_say(self, folder: Path, verb: str):
        """``_stored(folder)``, or None once the status line has said why it cannot ``verb`` it."""
        try:
            return self._stored(folder)
        except RunFolderError as exc:
            self.say(str(exc), "error", title=f"Cannot {verb}", about=folder)
        except PresetError as exc:
            self.say(exc.problems[0], "error", title=f"Cannot {verb} {shown_name(folder.name)}", about=folder)
        return None

    def _start(self, scene, sweep, out_dir: Path, options: RunOptions) -> None:
        from ..runs.detached import check_startable, check_sweep_startable, lock_held, start_detached

        self.last_outcome = None
        self.last_resumable = False
        self.refresh_bindings()
        try:  # refused here, at once, what the run would refuse as it begins
            if sweep is None:
                check_startable(scene, out_dir, options)
            else:
                check_sweep_startable(sweep, out_dir, options)
        except FrictionlabError as exc:
            if options.resume and lock_held(out_dir):  # another TUI (or the CLI) resumed it first
                self._follow_the_winner(out_dir)
                return
            self.say(str(exc), "error", title="Cannot resume" if options.resume else "Cannot run",
                     about=out_dir if options.resume else None)
            self.taken_back_on = "" if options.resume else "edit"  # memory, say: an edit may change it
            self._unclaim(out_dir, options)
            return
        try:
            preset = scene.resolved() if sweep is None else sweep.preset_data
            process = start_detached(preset, out_dir, options, source=sweep.source if sweep is not None else None)
        except OSError as exc:  # no process can be started (out of processes, memory)
            self.say(f"cannot start the run: {exc.strerror or exc}", "error", title="Run failed")
            self._unclaim(out_dir, options)
            return
        except FrictionlabError as exc:  # its folder changed since the check above
            self.say(str(exc), "error", title="Cannot resume" if options.resume else "Cannot run")
            self._unclaim(out_dir, options)
            return
        self.followed = self._follower(out_dir, scene, sweep, process)
        self.refresh_bindings()  # the Run tab's keys: cancel now, not run nor resume
        self.query_one("RunPane").start(scene, sweep, out_dir)
        if options.resume and sweep is None:  # what it restores, at once: not 0 % until its process has begun
            self._show_stored(out_dir)
        elif options.resume:
            self._show_stored_sweep(out_dir, sweep)
        self.action_show_tab("run")
        verb = "Resuming" if options.resume else "Running"
        name = scene.preset.name if sweep is None else f"the sweep {sweep.name}"
        self.say(f"{verb} {name} into {shown_name(out_dir)} as a process of its own "
                 f"(pid {self.followed.pid}): it goes on if you quit")  # fmt: skip

    @staticmethod
    def _unclaim(out_dir: Path, options: RunOptions) -> None:
        """A fresh run's folder, made to claim its name, given back when the run is refused
        before it began: empty, it is removed (each refused Ctrl+R left one in runs/)."""
        if not options.resume:
            with suppress(OSError):  # not empty, or gone: left as it is
                out_dir.rmdir()

    def _follower(self, folder: Path, scene, sweep, process=None) -> FollowedRun:
        from .following import FollowedRun, FollowedSweep

        if sweep is None:
            return FollowedRun(folder, scene, self._show_snapshot, process=process)
        show_point = lambda kind, point, result: self._show_point(sweep, kind, point, result)  # noqa: E731
        return FollowedSweep(folder, sweep, self._show_snapshot, show_point, process=process)

    def show_running(self, folder: Path) -> None:
        """The Run tab, following the run going on in ``folder`` (if it is not the one shown)."""
        if self.followed is None or real_path(self.followed.folder) != real_path(folder):
            if self.running:
                self.say("A run is shown: it goes on when you quit; follow this one after it (or from another TUI).",
                         "warning", about=folder)
                return
            self.follow_run(folder)
        self.action_show_tab("run")

    def follow_run(self, folder: Path) -> None:
        """Show the run (or sweep) going on in ``folder`` (another process's) live on the Run tab."""
        stored = self._stored_or_say(folder, "follow")
        if stored is None:
            return
        scene, sweep = stored
        self.last_outcome = None
        self.last_resumable = False
        self.query_one("RunPane").start(scene, sweep, folder)  # before the first poll: that fills its table
        self.followed = self._follower(folder, scene, sweep)
        self.refresh_bindings()
        name = scene.preset.name if sweep is None else f"The sweep {sweep.name}"
        self.say(f"{name} is running in {shown_name(folder)} (a process of its own): F4 shows it, c cancels it")
        self._follow_tick()

    def _show_point(self, sweep, kind: str, point, result) -> None:
        if (pane := self._mounted("RunPane")) is not None:
            with suppress(NoMatches):  # the app is closing: the pane's widgets go one by one
                pane.show_point(sweep, kind, point, result)

    def _show_snapshot(self, snapshot) -> None:
        self.last_snapshot = snapshot
        if (pane := self._mounted("RunPane")) is not None:
            with suppress(NoMatches):  # as above: a follow tick late in the close found #run-stats gone
                pane.show_progress(snapshot, self.followed is not None and self.followed.cancelling)

    def _follow_tick(self) -> None:
        followed = self.followed
        if followed is None:
            return
        from ..runs.detached import lock_held
        from .following import FollowedSweep, read_finished, read_finished_sweep

        if followed.count_from_chunks():
            self._count_from_chunks(followed)
        ended = followed.ended
        over = followed.poll()
        for message in followed.follower.warnings.take():  # its process's: its stderr is no one's
            self.say(message, "warning", about=followed.folder)
        if followed.ended != ended:  # its last event: c leaves the footer now, not once its process has closed
            self.refresh_bindings()
        if not over:
            return
        self.followed = None
        self.last_out_dir = followed.folder
        self.last_resumable = _resumable(followed.folder)  # however it ended: u offered when it can go on
        self.refresh_bindings()
        if followed.process is not None and lock_held(followed.folder):  # ours ended, the folder is another's:
            self._follow_the_winner(followed.folder)  # its resume won the race (its word may be lost: the winner
            return  # rewrote the progress file), never the old summary read as how ours ended
        if isinstance(self.screen, QuitDuringRunScreen):
            self._ask_quit_again(followed)
        if followed.error:
            self.on_run_crashed(RunCrashed(followed.error))
            self.reload_runs()
            return
        try:
            read = read_finished_sweep if isinstance(followed, FollowedSweep) else read_finished
            finished = read(followed.folder)
        except (FrictionlabError, OSError, ValueError, TypeError, KeyError):
            resume = "u resumes it" if self.last_resumable else "it cannot be resumed"
            error = f"the run's process ended without writing its results ({resume}: {shown_name(followed.folder)})"
            if self.last_resumable:  # killed (kill -9, a reboot): interrupted, as Results and runs say
                self._show_stored(followed.folder, resuming=False)
            self.on_run_crashed(RunCrashed(error, interrupted=self.last_resumable))
            self.reload_runs()
            return
        self.on_run_finished(RunFinished(finished, followed.folder))

    def _ask_quit_again(self, followed) -> None:
        """The run ended while the quit question was up: that question, which said it was going,
        is asked again as things are now (y quits, n or Esc stays)."""
        from .following import FollowedSweep

        what = "sweep" if isinstance(followed, FollowedSweep) else "run"
        self.screen.dismiss(None)
        question = (f"The {what} in {shown_name(followed.folder)} has ended meanwhile: nothing is left to leave "
                    "running or to cancel. Quit now?")  # fmt: skip
        self.push_screen(QuitRunEndedScreen(question), lambda yes: yes and self.exit())

    def _show_stored(self, folder: Path, resuming: bool = True) -> None:
        from ..runs.detached import stored_count

        try:
            done, total = stored_count(folder)
        except (OSError, FrictionlabError):
            return
        if done is not None and total:
            self.query_one("RunPane").show_stored_count(done, total, resuming=resuming)

    def _show_stored_sweep(self, folder: Path, sweep, resuming: bool = True) -> None:
        """A sweep's resume: the points its sweep.json holds as done, and the first point it
        goes on with, with the realizations that point's chunks hold."""
        from ..runs.detached import stored_count
        from ..runs.sweep import UNFINISHED, point_folder
        from .folders import read_sweep

        try:
            rows = read_sweep(folder).points
        except (OSError, FrictionlabError):
            return
        done = {row["point"] for row in rows if row["status"] not in UNFINISHED}
        going_on = next((point for point in sweep.points if point.number not in done), None)
        if going_on is None:
            return
        try:
            stored, total = stored_count(point_folder(folder, going_on))
        except (OSError, FrictionlabError):  # a point never reached: nothing stored
            stored, total = None, None
        total = total or going_on.scene.preset.realizations
        self.query_one("RunPane").show_stored_sweep(sweep, [row for row in rows if row["point"] in done],
                                                    going_on, min(stored or 0, total), total, resuming)  # fmt: skip

    def _count_from_chunks(self, followed: FollowedRun) -> None:
        """A run whose progress file cannot be read, or that writes none: said once; its count read from its chunks."""
        if not followed.said_progress_problem:
            followed.said_progress_problem = True
            self.say(f"{followed.count_from_chunks()}: the count comes from the run's chunks, without a live plot", "warning")
        from .following import FollowedSweep

        if isinstance(followed, FollowedSweep):  # its points done, and the chunks of the one going on
            self._show_stored_sweep(followed.folder, followed.sweep, resuming=False)
            return
        done, total = followed.stored_count()
        if total and (pane := self._mounted("RunPane")) is not None:
            pane.show_stored_count(done or 0, total)

    def action_cancel_run(self) -> None:
        if not self.running:  # Ctrl+R answers "no preset open" where none is: say what starts a run here
            self.say("No run is going: Ctrl+R starts one." if self._draft() is not None else
                     "No run is going, and no preset is open: F2 lists them (Enter opens one), then Ctrl+R runs it.",
                     "warning")  # fmt: skip
            return
        if self.followed.ended:
            self.say("The run has ended: its files are being written; nothing is left to cancel.", "warning")
            return
        if self.followed.cancelling:  # signalled again, it would stop before writing what finished
            self.say("Cancelling already: what finished is being written (u resumes the run once it has ended).",
                     "warning")  # fmt: skip
            return
        if not self.followed.cancel():  # its process is gone (the next tick shows how it ended), or not verified
            return self.followed.refusal and self.say(self.followed.refusal, "error", title="Not cancelled")
        self.query_one("RunPane").show_cancelling()
        self.refresh_bindings()  # c leaves the footer: pressed again it would stop the writing of what finished
        self.say("Cancelling: the solves running stop; what finished is kept (u resumes it).")  # in place of what was said

    def on_run_finished(self, message: RunFinished) -> None:
        outcome = message.outcome
        self.last_outcome, self.last_out_dir = outcome, message.out_dir
        self.refresh_bindings()  # resume, if it ended before it completed
        pane = self.query_one("RunPane")
        from .following import FinishedSweep

        if isinstance(outcome, FinishedSweep):
            self.say(pane.show_sweep_outcome(outcome))
        else:
            line = pane.show_outcome(outcome)
            if outcome.done == 0 and outcome.failures:  # nothing to show: say why, as the user can fix it
                self.say(failure_message(outcome.failures[0][1]), "error", title="Run failed: no realization finished")
            elif outcome.failures:
                self.say(f"{line}; {outcome.failed} failed: {failure_message(outcome.failures[0][1])}", "warning")
            else:
                self.say(line)
        self.reload_runs()

    def on_run_crashed(self, message: RunCrashed) -> None:
        self.query_one("RunPane").show_crash(message.error, interrupted=message.interrupted)
        self.say(message.error, "warning" if message.interrupted else "error",
                 title="Run interrupted" if message.interrupted else "Run failed")  # fmt: skip

    async def action_quit(self) -> None:
        """Quit at once; with unsaved changes, ask first whether to drop them; then, while a run
        goes on, whether to leave it running or cancel it (nothing is cancelled by a quit that
        does not happen)."""
        if isinstance(self.screen, (QuitUnsavedScreen, QuitDuringRunScreen, QuitRunEndedScreen)):
            return  # Ctrl+Q again: the question is up; stacked, one n left the same question there
        if await self.unsaved():
            self.push_screen(QuitUnsavedScreen(), lambda yes: yes and self._quit_leaving_or_cancelling_the_run())
            return
        self._quit_leaving_or_cancelling_the_run()

    def _quit_leaving_or_cancelling_the_run(self) -> None:
        followed = self.followed
        if followed is None or followed.ended:  # nothing left to leave running or cancel
            self.exit()
            return
        from .following import FollowedSweep

        what = "sweep" if isinstance(followed, FollowedSweep) else "run"

        def answered(choice: str | None) -> None:
            if choice is None:
                return
            if choice == "cancel":
                followed.cancel()  # SIGTERM: it keeps what finished; no need to wait for it
            self.farewell = quit_farewell(what, followed.folder, followed.pid, cancelled=choice == "cancel")
            self.exit()

        question = (f"A {what} is going in {shown_name(followed.folder)} (pid {followed.pid}), a process of its own.\n"
                    "Leave it running (a TUI opened later shows it, u resumes it if it stops), or cancel it "
                    "(what finished is kept)?")  # fmt: skip
        self.push_screen(QuitDuringRunScreen(question), answered)


def quit_farewell(what: str, folder: Path, pid: int | None, cancelled: bool) -> str:
    """The line the shell shows once the TUI has quit during a run: the screen that said where
    the run went is gone, and the prompt alone said nothing of a process still going."""
    word = command_word(folder)
    if cancelled:
        return (f"The {what} in {shown_name(folder)} (pid {pid}) was told to stop: it keeps what finished "
                f"(`frictionlab resume {word}` goes on with it).")  # fmt: skip
    return (f"The {what} in {shown_name(folder)} (pid {pid}) goes on: `frictionlab follow {word}` shows it, "
            "`frictionlab runs` lists it.")  # fmt: skip


def _resumable(folder: Path) -> bool:
    """Whether the run (or sweep) in ``folder`` ended before it completed and can go on (a run that
    failed with every realization finished cannot, nor a sweep of such points: ``runs.settled``)."""
    from ..runs.detached import run_state
    from ..runs.settled import why_no_resume_helps

    try:
        if not run_state(folder).resumable:
            return False
    except (OSError, FrictionlabError):
        return False
    return not why_no_resume_helps(folder)[0]  # a resume would fail the same way
