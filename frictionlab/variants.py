"""Variants of one preset: its data with a few dotted-path changes, validated by
``preset.build_scene`` like any preset, so every variant is a scene a user could
run. The studies build their scenes here (a grid refined, another solver of the
same elastic body, fewer realizations). Nothing here knows physics: solvers are
swapped by copying the parameters of the elastic body both declare
(``ContactSolver.body_params``), and the f range is kept through the contract's
own normalisation (``force_unit``).
"""

from __future__ import annotations

import copy
import math
from collections.abc import Callable
from typing import Any

from .errors import FrictionlabError
from .preset import Scene, build_scene, set_path
from .plugin.registry import Registry


def force_scale(scene: Scene) -> float:
    """The load at f = 1 (``force_unit``) for realization 0's profile (``Scene.load_scales``)."""
    return scene.load_scales.force_unit


class SceneFactory:
    """Builds validated variants of one preset's data."""

    def __init__(self, data: dict, registry: Registry, source: str,
                 before_reading: Callable[[Scene], None] | None = None):  # fmt: skip
        """``before_reading``: the base scene's memory check (``build_scene``), before a
        measured map is read or an MDR-equivalent line made."""
        self.data = copy.deepcopy(data)
        self.registry = registry
        self.source = source
        self.base = build_scene(self.data, registry=registry, source=source, before_reading=before_reading)
        self._base_scale = force_scale(self.base)

    def make(self, changes: dict[str, Any], *, keep_f_range: bool = True,
             before_reading: Callable[[Scene], None] | None = None) -> Scene:  # fmt: skip
        """The preset with ``changes`` (dotted path -> value). With ``keep_f_range``
        the force grid is rescaled so the variant sweeps the base scene's f range
        (a shorter line or another stiffness would otherwise shift it).
        ``before_reading``: as ``build_scene``'s (a memory check)."""
        data = copy.deepcopy(self.data)
        for path, value in changes.items():
            set_path(data, path, value)
        where = f"{self.source} with " + ", ".join(f"{k}={v}" for k, v in changes.items())
        scene = build_scene(data, registry=self.registry, source=where, before_reading=before_reading)
        if keep_f_range and scene.preset.loading.unit == "force":  # loads in f keep their f range themselves
            ratio = force_scale(scene) / self._base_scale
            if not math.isclose(ratio, 1.0, rel_tol=1e-12):
                loading = self.base.preset.loading
                set_path(data, "loading.start", loading.start * ratio)
                set_path(data, "loading.stop", loading.stop * ratio)
                scene = build_scene(data, registry=self.registry, source=where)
        return scene

    def solver_choice(self, name: str, tolerance: float | None = None) -> dict:
        """``{"name", "params"}`` for solver ``name`` with the base solver's elastic body
        (the ``body_params`` both solvers declare) and, for an iterative solver, the
        ``tolerance``. Raises FrictionlabError naming the option when the solver is
        not installed."""
        try:
            cls = self.registry.get("solver", name)
        except FrictionlabError as exc:
            raise FrictionlabError(f"--reference: {exc}") from None
        base = self.base.solver.params.model_dump()
        params = {k: base[k] for k in cls.body_params if k in self.base.solver.body_params}
        if tolerance is not None and cls.tolerance_param is not None:
            params[cls.tolerance_param] = tolerance
        return {"name": cls.name, "params": params}
