"""Saving the open preset (``FrictionlabApp``'s, a mixin): Ctrl+S, Ctrl+O, and the file of a
duplicate; a built-in preset is saved as a copy, a file that cannot be written is said."""

from __future__ import annotations

import copy
from pathlib import Path

from ..errors import shown
from .folders import is_builtin, new_preset_path, save_preset, user_presets_dir
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
            self.say(f"{self.draft_path.name} is a built-in preset: save your version as a new file.", "warning", until_open=True)
            self.push_screen(
                PathScreen("Save the built-in preset's changes as", self._save_as_default(), self.save_folder),
                lambda path: path is not None and self._save_checked(path),
            )
            return
        if self.draft_source != self.draft_path and self.draft_path.exists():
            # a new preset whose file appeared since the New dialog: replaced only if the user says so
            self.push_screen(
                PathScreen(f"{self.draft_path} exists now: save the new preset as", self.draft_path, self.save_folder),
                lambda path: path is not None and self._save_checked(path),
            )
            return
        self._save_checked(self.draft_path)

    def action_save_as(self) -> None:
        if self.draft_path is None or self._draft() is None:
            self.say(NO_PRESET, "warning")
            return
        self.push_screen(
            PathScreen("Save preset as", self._save_as_default(), self.save_folder),
            lambda path: path is not None and self._save_checked(path),
        )

    def _save_as_default(self) -> Path:
        """The file Save as offers: the preset's own, or for a built-in one (never written) its copy's."""
        if is_builtin(self.draft_path):
            return new_preset_path(self.draft_path.stem, self.save_folder)
        return self.draft_path

    def _save_checked(self, path: Path) -> None:
        data = self._draft()
        if not self.problems:
            self._write(path, data, template=self.draft_source)
            return
        count = len(self.problems)
        question = (
            f"This preset has {count} problem{'s' if count != 1 else ''}; frictionlab run will refuse it:\n"
            + "\n".join(self.problems[:6])
            + "\n\nSave it anyway?"
        )
        self.push_screen(
            ConfirmScreen(question), lambda yes: yes and self._write(path, data, template=self.draft_source)
        )

    def _write(self, path: Path, data: dict, then_open: bool = False, template: Path | None = None) -> None:
        try:
            if not path.parent.exists() and path.parent.resolve() == self.save_folder.resolve():
                path.parent.mkdir(parents=True)  # the presets folder, made when first saved into
            save_preset(path, data, template=template)
        except OSError as exc:  # a read-only folder, not the user's, a file in the way
            elsewhere = user_presets_dir() / path.name
            self.say(f"{shown(path)} cannot be written ({exc.strerror or exc}): Ctrl+O saves it elsewhere, "
                     f"e.g. {shown(elsewhere)}", "error", title="Not saved")  # fmt: skip
            return
        self.say(f"Saved {path}")
        self.reload_presets()
        self.query_one(PresetsPane).highlight(path)  # a listed folder: the preset is there
        if then_open:
            self.run_worker(self._open_after_confirm(path), group="open")  # the copy is saved either way
        else:
            self.draft_path = self.draft_source = path
            self.modified = False
            self._saved = copy.deepcopy(data)
            self._show_edit_state()
