"""What every plugin is: a kebab-case name, a summary, references and validated
``Params``; the bounds on the numbers frictionlab reads."""

from __future__ import annotations

import re
from typing import ClassVar, Literal

from pydantic import BaseModel, ConfigDict, ValidationError


NAME_PATTERN = re.compile(r"^[a-z][a-z0-9]*(-[a-z0-9]+)*$")

Control = Literal["force", "indentation"]
"""What a sweep's loads are: total loads (see ``LoadMeaning``) or indentations."""


MAX_MAGNITUDE = 1e100  # numbers frictionlab reads: 0, or 1e-100 <= |x| <= 1e100 (products of a few stay finite)


class PluginParams(BaseModel):
    """Base for every plugin's ``Params``: unknown keys are errors, values are
    validated on assignment too (the TUI edits them in place). Each validator is built
    when its plugin is first used, not when its module is imported (``defer_build``):
    a run pays for its own plugins only."""

    model_config = ConfigDict(extra="forbid", validate_assignment=True, defer_build=True)

    def __setattr__(self, name, value):
        # pydantic keeps a value that fails a model-level check on assignment;
        # put the old one back so a rejected edit leaves the params valid.
        previous = dict(self.__dict__)
        try:
            super().__setattr__(name, value)
        except ValidationError:
            self.__dict__.update(previous)
            raise


class Plugin:
    """Common base: stores parameters, nothing else.

    ``Plugin(params)`` takes a ready ``Params`` instance; ``Plugin(**kwargs)``
    validates keyword arguments through ``Params``.
    """

    name: ClassVar[str] = ""  # kebab-case, the plugin's key in a preset
    summary: ClassVar[str] = ""  # one line
    references: ClassVar[tuple[str, ...]] = ()  # DOIs
    Params: ClassVar[type[PluginParams]] = PluginParams
    kind: ClassVar[str] = ""  # set by the kind's base class, never by a plugin
    params: PluginParams  # the validated parameters, the only state the constructor keeps

    def __init__(self, params: PluginParams | None = None, **kwargs):
        if params is not None and kwargs:
            raise TypeError("give either a Params instance or keyword arguments, not both")
        if params is None:
            params = self.Params(**kwargs)
        elif not isinstance(params, self.Params):
            raise TypeError(
                f"params must be an instance of {type(self).__name__}.Params. "
                f"Got {type(params).__name__} instead."
            )
        self.params = params

    def __repr__(self) -> str:
        args = ", ".join(f"{k}={v!r}" for k, v in self.params.model_dump().items())
        return f"{type(self).__name__}({args})"
