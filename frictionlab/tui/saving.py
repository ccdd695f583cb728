"""Saving the open preset (``FrictionlabApp``'s, a mixin): Ctrl+S, Ctrl+O, and the file of a
duplicate; a built-in preset is saved as a copy, a file that cannot be written is said, and
one that another program (an editor, another TUI) wrote since it was opened is replaced only
once the user says so."""

from __future__ import annotations

import asyncio
import copy
from pathlib import Path

from ..errors import shown, shown_name
from ..preset.builtin import listed_preset_folders, user_presets_dir
from .folders import (
    copy_name,
    copy_target,
    file_stamp,
    is_builtin,
    made_when_saved,
    names_taken,
    new_preset_path,
    save_preset,
)
from .running import NO_PRESET
from .screens import ConfirmScreen, PathScreen
from .widgets.presets import PresetsPane


class PresetSaving:
    """Ctrl+S and Ctrl+O on the draft, and writing a preset file (``FrictionlabApp``'s)."""

    def action_save(self) -> None:
        if self.draft_path is None or self._draft() is None:
            self.say(NO_PRESET, "warning")
            return
        if is_builtin(self.draft_path):  # shipped with frictionlab: saved as a copy, where the user says
            self.say(f"{shown_name(self.draft_path.name)} is a built-in preset: save your version as a new file.", "warning", until_open=True)
            self.push_screen(
                PathScreen("Save the built-in preset's changes as", new_preset_path(self.draft_path.stem, self.save_folder), self.save_folder),
                lambda path: path is not None and self._save_checked(path),
            )
            return
        if self.draft_source != self.draft_path and self.draft_path.exists():
            # a new preset whose file appeared since the New dialog: replaced only if the user says so
            self.push_screen(
                PathScreen(f"{shown_name(self.draft_path)} exists now: save the new preset as", self.draft_path, self.save_folder),
                lambda path: path is not None and self._save_checked(path),
            )
            return
        if self._changed_on_disk():
            self.push_screen(ConfirmScreen(changed_question(self.draft_path)),
                             lambda yes: yes and self._save_checked(self.draft_path))  # fmt: skip
            return
        self._save_checked(self.draft_path)

    async def unsaved(self) -> bool:
        """Whether the draft has unsaved changes, counting an edit still on its way: keys typed
        together (z, Esc, q: SSH sends them joined) are in the form's fields' queues when q is
        answered, and the app heard of the change only after it had quit without asking."""
        if self.modified or self._saved is None or self._mounted("EditPane") is None:
            return self.modified
        form = await self.form_settled()
        return form.data is not None and form.data != self._saved

    async def form_settled(self):
        """The form, once the keys already handed to its fields are in its draft and its problems:
        a value typed, then Esc and Ctrl+S together, was saved as it was before the value, unasked."""
        form = self.query_one("#form")
        pumps = [form, *form.query("*")]
        for _ in range(1000):  # each turn lets the fields' and the form's queues move on
            if not any(pump.message_queue_size for pump in pumps):
                break
            await asyncio.sleep(0)
        return form

    def _changed_on_disk(self) -> bool:
        """Whether the open preset's file is there and not as it was read or last saved here."""
        if self.disk_stamp is None or self.draft_source != self.draft_path:
            return False
        return file_stamp(self.draft_path) not in (None, self.disk_stamp)

    def _watch_preset_file(self) -> None:
        """Say once, as it happens, that the open preset's file was changed or removed on disk."""
        if self.disk_stamp is None or self.draft_source != self.draft_path:
            return
        now = file_stamp(self.draft_path)
        if now in (self.disk_stamp, self.said_stamp):
            return
        self.said_stamp = now
        if now is None:
            self.say(f"{shown(self.draft_path)} was removed from disk: Ctrl+S writes the form's preset there again.",
                     "warning", until_open=True)  # fmt: skip
        else:
            self.say(f"{shown(self.draft_path)} was changed on disk (by another program or TUI): Ctrl+S asks "
                     "before replacing it; Enter on it in Presets (F2) opens it as it is now.", "warning",
                     until_open=True)  # fmt: skip

    def action_save_as(self) -> None:
        """A copy of the draft in another file (by default ``<file>-copy.yaml`` beside it), under a
        name no listed preset has; the form goes on with the copy, the preset's own file is kept."""
        if self.draft_path is None or self._draft() is None:
            self.say(NO_PRESET, "warning")
            return
        folder = self.save_folder if is_builtin(self.draft_path) else self.draft_path.parent
        name = str(self._draft().get("name") or self.draft_path.stem)
        copied, default = copy_target(name, self.draft_path.stem, folder, self.names_listed())
        self.push_screen(
            PathScreen("Save a copy of the preset as", default, self.save_folder),
            lambda path: path is not None and self._save_copy(path, copied, default),
        )

    def _save_copy(self, path: Path, copied: str, default: Path) -> None:
        """Ctrl+O's file chosen: the draft saved there, renamed unless it is the preset's own
        file or its name is no other listed preset's (two rows of the list shared one)."""
        data, name = self._draft(), self._draft().get("name")
        if path != self.draft_path and (not isinstance(name, str) or name in self.names_listed(replaced=path)):
            data = {**data, "name": copy_name(copied, path, default, self.names_listed(replaced=path))}
        self._save_checked(path, data)

    def names_listed(self, replaced: Path | None = None) -> set[str]:
        """The names the presets list shows, but that of the file a copy replaces (``replaced``)."""
        return names_taken(self.query_one(PresetsPane).presets, replaced)

    def _save_checked(self, path: Path, data: dict | None = None) -> None:
        """Write the draft (or ``data``, Ctrl+O's renamed copy of it) to ``path``, asking first when it has problems."""
        data = self._draft() if data is None else data
        problems = self.query_one("#form").problems  # the form's now: its message to the app may be on its way
        if not problems:
            self._write(path, data, template=self.draft_source)
            return
        count = len(problems)
        question = (
            f"This preset has {count} problem{'s' if count != 1 else ''}; frictionlab run will refuse it:\n"
            + "\n".join(problems[:6])
            + (f"\n(and {count - 6} more, listed under the form)" if count > 6 else "")  # 7 said as 6, nothing more
            + "\n\nSave it anyway?"
        )
        self.push_screen(
            ConfirmScreen(question), lambda yes: yes and self._write(path, data, template=self.draft_source)
        )

    def _write(self, path: Path, data: dict, then_open: bool = False, template: Path | None = None) -> None:
        try:
            if not path.parent.exists() and made_when_saved(path.parent, self.save_folder):
                path.parent.mkdir(parents=True)  # a presets folder, made when first saved into
            save_preset(path, data, template=template)
        except OSError as exc:  # a read-only folder, not the user's, a file in the way
            self._ask_elsewhere(path, exc, lambda there: self._write(there, data, then_open, template))
            return
        self.reload_presets()
        listed = self.query_one(PresetsPane).highlight(path)  # a listed folder: the preset is there
        # else said: a bare name typed is saved in the working folder, which the list does not show
        shows = ", ".join(shown_name(folder) for folder in listed_preset_folders(self.presets_dir))
        where = "" if listed else f" (not listed: the Presets list shows the presets in {shows})"
        self.say(f"Saved {shown_name(path)}{where}", until_open=not then_open)  # of the open preset: not of the next one opened
        if then_open:
            self.run_worker(self._open_after_confirm(path), group="open")  # the copy is saved either way
        else:
            if data.get("name") != self._draft().get("name"):  # Ctrl+O's copy: the form shows its name
                self.query_one("#form").rename(data["name"])
            self.draft_path = self.draft_source = path
            self.disk_stamp = file_stamp(path)
            self.modified = False
            self._saved = copy.deepcopy(data)
            self._show_edit_state()

    def _ask_elsewhere(self, path: Path, exc: OSError, write_there) -> None:
        """Say why ``path`` cannot be written and ask at once for another file, in the user folder
        by default (made when first saved into); ``write_there`` writes the one given. (Ctrl+O,
        once advised, saved the open preset, never a duplicate's copy, and offered ``path`` again.)"""
        reason = exc.strerror or str(exc)
        elsewhere = user_presets_dir() / path.name
        self.say(f"{shown(path)} cannot be written ({reason}): give another file, e.g. in your own presets "
                 f"folder, {shown(elsewhere.parent)}; Esc leaves it unsaved", "error", title="Not saved")  # fmt: skip
        title = f"{shown_name(path.name)} cannot be written there ({reason}): save it as"

        def answered(there: Path | None) -> None:
            if there is None:  # Esc: the advice to give another file no longer applies, and nothing was written
                self.say(f"{shown(path)} cannot be written ({reason}); nothing was written", "warning", title="Not saved")
                return
            write_there(there)

        self.push_screen(PathScreen(title, elsewhere, self.save_folder), answered)


def changed_question(path: Path) -> str:
    return (f"{shown(path)} was changed on disk since it was opened here (by another program or TUI).\n"
            "Replace it with the form's preset? What the other wrote is lost.\n\n"
            "n keeps the file: Ctrl+O saves the form elsewhere; Enter on it in Presets opens it as it is now.")  # fmt: skip
