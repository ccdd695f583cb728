"""The plugin registry: built-ins, entry-point discovery, environment switches.

Built-in physics registers through the same hooks as any third-party plugin.
Environment switches (read when a registry is built):

``FRICTIONLAB_DISABLE_DISCOVERY=1``  load built-ins only, no entry points
``FRICTIONLAB_PLUGINS=a,b``          load only these entry points
``FRICTIONLAB_BLOCK_PLUGINS=a,b``    never load these entry points
``FRICTIONLAB_TRACE_HOOKS=1``        trace every hook call on stderr
"""

from __future__ import annotations

import contextlib
import functools
import importlib
import importlib.metadata as md
import os
import re
import sys
import traceback
from dataclasses import dataclass

import pluggy

from ..errors import FrictionlabError, PluginError, did_you_mean, short_repr, warn_user
from .base import Plugin
from .classcheck import params_problem, validate_plugin_class
from .hookspecs import PROJECT_NAME, RegistrationSpecs
from .kinds import KINDS
from .listeners import LIFECYCLE_HOOKS, GuardedListener, RunListener, fault_site
from .solve_progress import SolveFailed

ENTRY_POINT_GROUP = PROJECT_NAME
BUILTIN_MODULES = ("frictionlab_spectra", "frictionlab_solvers", "frictionlab_slopes")


def normalize_name(name: str) -> str:
    """Preset keys are case- and separator-insensitive: ``Power_Law`` -> ``power-law``."""
    return name.strip().lower().replace("_", "-").replace(" ", "-")


def _env_list(env, key: str) -> list[str]:
    return [item.strip() for item in env.get(key, "").split(",") if item.strip()]


_ON, _OFF = ("1", "true", "yes", "on"), ("", "0", "false", "no", "off")


def _env_flag(env, key: str) -> bool:
    """A yes/no variable; another value (a typo: ``ture``, ``2``) is said, and read as no."""
    value = env.get(key, "").strip().lower()
    if value not in _ON + _OFF:
        warn_user(f"{key}={env[key]!r} is not one of {', '.join(_ON)} (on) or {', '.join(_OFF[1:])} (off); "
                  "read as off", RuntimeWarning)  # fmt: skip
    return value in _ON


@dataclass(frozen=True)
class PluginInfo:
    kind: str
    name: str
    cls: type[Plugin]

    @property
    def summary(self) -> str:
        return self.cls.summary

    @property
    def provider(self) -> str:
        """The distribution that ships the plugin (looked up when asked: the lookup
        reads every installed distribution's metadata, too slow for each start)."""
        return provider_of(self.cls)[0]

    @property
    def version(self) -> str:
        return provider_of(self.cls)[1]


@dataclass(frozen=True)
class LoadFailure:
    entry_point: str
    distribution: str
    error: str
    claims: tuple[tuple[str, str], ...] = ()  # (kind, name) of the classes it registered before failing


@functools.cache
def _module_distributions() -> dict[str, list[str]]:
    return md.packages_distributions()


def plugin_label(cls: type) -> str:
    """``solver 'mdr' (module.Class from distribution)``: a plugin class as every message names it."""
    return f"{cls.kind} {cls.name!r} ({cls.__module__}.{cls.__qualname__} from {provider_of(cls)[0]})"


@functools.cache
def provider_of(cls: type) -> tuple[str, str]:
    """The distribution (and version) that ships ``cls``, from its module."""
    return _provider(cls.__module__)


def _provider(module: str) -> tuple[str, str]:
    top = module.split(".")[0]
    dists = _module_distributions().get(top)
    if dists:
        dist = dists[0]
        try:
            return dist, md.version(dist)
        except md.PackageNotFoundError:  # pragma: no cover - broken metadata
            return dist, "unknown"
    return module, "unversioned"


def _registers_nothing(plugin) -> str:
    """Why an entry point that implements no hook is refused (skipped without a word, its plugins
    were looked for in vain): a hook without its mark, or the class named instead of the module."""
    hooks = [base.register_hook for base in KINDS.values()] + list(LIFECYCLE_HOOKS)
    if unmarked := [name for name in hooks if callable(getattr(plugin, name, None))]:
        return f"it implements no hook: {', '.join(unmarked)} lacks the @frictionlab.hookimpl mark"
    said = "it implements no hook: the entry point's value must be the module holding its @frictionlab.hookimpl functions"
    if isinstance(plugin, type):  # the class itself, as the kit's register_plugin takes it
        said += f" ({plugin.__module__}), not the class {plugin.__qualname__}"
    return said


def _warn_of_unknown_names(only: list[str], installed: list[str]) -> None:
    """A name in FRICTIONLAB_PLUGINS that no installed plugin has (a typo) is said: the plugin
    meant would otherwise be left out without a word. (A blocked name that is not installed
    is blocked all the same.)"""
    for name in (name for name in only if name not in installed):
        warn_user(
            f"FRICTIONLAB_PLUGINS names {name!r}, which is no installed plugin's entry point (installed: "
            f"{', '.join(installed) or 'none'}; the built-ins load without being named)", RuntimeWarning,
        )  # fmt: skip


class Registry:
    """Every installed plugin class, by kind and name."""

    def __init__(self, *, discover: bool = True, builtins: bool = True, env=None):
        env = os.environ if env is None else env
        self.pm = pluggy.PluginManager(PROJECT_NAME)
        self.pm.add_hookspecs(RegistrationSpecs)
        self.pm.add_hookspecs(RunListener)  # an installed plugin may listen to every run
        self.failures: list[LoadFailure] = []
        self._distributions: dict[str, str] = {}  # entry point -> its distribution, of those loaded
        self._claims: dict[tuple[str, str], list[str]] = {}  # (kind, name) -> the entry points registering it
        self._plugins: dict[str, dict[str, PluginInfo]] = {kind: {} for kind in KINDS}
        self._clashes: dict[str, dict[str, str]] = {kind: {} for kind in KINDS}
        if _env_flag(env, "FRICTIONLAB_TRACE_HOOKS"):
            self.pm.trace.root.setwriter(sys.stderr.write)
            self.pm.enable_tracing()
        self._builtins: dict[str, dict[str, type]] = {kind: {} for kind in KINDS}  # the names no installed plugin may take
        if builtins:
            for module_name in BUILTIN_MODULES:
                self.pm.register(module := importlib.import_module(module_name), name=module_name)
                self._note_builtins(module)
        if discover and not _env_flag(env, "FRICTIONLAB_DISABLE_DISCOVERY"):
            self._load_entry_points(
                only=_env_list(env, "FRICTIONLAB_PLUGINS"),
                blocked=_env_list(env, "FRICTIONLAB_BLOCK_PLUGINS"),
            )
        self.pm.check_pending()
        self._collect()
        for message in self.clashes:
            warn_user(f"frictionlab plugins: {message}", RuntimeWarning)

    # ------------------------------------------------------------- loading

    def _load_entry_points(self, only: list[str], blocked: list[str]) -> None:
        for name in blocked:
            self.pm.set_blocked(name)
        found = md.entry_points(group=ENTRY_POINT_GROUP)
        _warn_of_unknown_names(only, sorted({ep.name for ep in found}))
        for ep in found:
            if (only and ep.name not in only) or self.pm.is_blocked(ep.name):
                continue
            if self.pm.get_plugin(ep.name) is not None:
                continue
            dist = ep.dist.name if ep.dist else "unknown distribution"
            value = ep.pattern.match(ep.value)  # None: ep.load() and ep.module would raise AttributeError
            claims: list[tuple[str, str]] = []
            try:  # what it prints goes to stderr: stdout may be JSON (--json, frictionlab schema)
                with contextlib.redirect_stdout(sys.stderr):
                    if value is None:
                        raise PluginError(f"the entry point's value {ep.value!r} names no module: it must be module "
                                          "or module:attribute, of letters, digits, _ and dots")  # fmt: skip
                    plugin = ep.load()
                    self.pm.register(plugin, name=ep.name)
                    self._try_registration(plugin, claims)
                    if not claims and not self.pm.get_hookcallers(plugin):
                        raise PluginError(_registers_nothing(plugin))
                self._distributions[ep.name] = dist
                for claim in claims:
                    self._claims.setdefault(claim, []).append(ep.name)
            except (Exception, SystemExit) as exc:  # a broken plugin must not break (nor end) the tool
                if self.pm.get_plugin(ep.name) is not None:
                    self.pm.unregister(name=ep.name)
                message = self._failure_message(exc, value.group("module").partition(".")[0] if value else "")
                self.failures.append(LoadFailure(ep.name, dist, message, tuple(claims)))
                warn_user(f"frictionlab plugin {ep.name!r} from {dist} failed to load ({message}); skipped", RuntimeWarning)

    def _note_builtins(self, module) -> None:
        """The classes a built-in module registers, by kind and name: names no installed plugin may take."""
        for kind, base in KINDS.items():
            if hook := getattr(module, base.register_hook, None):
                hook(register=lambda cls, kind=kind: self._builtins[kind].setdefault(normalize_name(cls.name), cls))

    def _failure_message(self, exc: BaseException, package: str) -> str:
        """Why an entry point failed to load, on one line, with where in its ``package`` it raised."""
        if isinstance(exc, SystemExit):  # argparse or sys.exit() at import, reading frictionlab's arguments
            return f"SystemExit({exc.code!r}): it exits as it loads (parsing arguments at import?)"
        if isinstance(exc, SyntaxError):  # its str names the file without its folder
            return f"SyntaxError: {exc.msg} ({exc.filename}, line {exc.lineno})"
        if isinstance(exc, pluggy.PluginValidationError):
            return self._hook_arguments_message(exc)
        message = f"{type(exc).__name__}: {exc}"
        frame, where, _ = fault_site(exc, package)
        if frame is None or isinstance(exc, PluginError):  # a broken contract is said by what, not where
            return message
        function, _, line = where.partition(" at ")
        return f"{message} ({'as it imports, ' + line if function == '<module>()' else 'in ' + where})"

    def _try_registration(self, plugin, claims: list[tuple[str, str]]) -> None:
        """Run ``plugin``'s registration hooks alone, checking every class it registers: a
        misspelled hook, a hook that raises or a class breaking the contract is then this
        plugin's failure, not every command's."""
        if problem := self._unknown_hook(plugin):
            raise PluginError(problem)
        self.pm.check_pending()  # a hook's arguments; the built-ins passed it: only this plugin can fail it
        for kind, base in KINDS.items():
            for impl in getattr(self.pm.hook, base.register_hook).get_hookimpls():
                if impl.plugin is plugin:
                    def register(cls, _kind=kind):  # a preset naming a refused class is told why
                        claims.append((_kind, normalize_name(str(getattr(cls, "name", "")))))
                        validate_plugin_class(_kind, cls)
                        if problem := params_problem(cls) or self._builtin_name_problem(_kind, cls):
                            raise PluginError(f"{cls.__qualname__}: {problem}")

                    impl.function(**{arg: {"register": register}[arg] for arg in impl.argnames})

    def _builtin_name_problem(self, kind: str, cls) -> str | None:
        """A class of an installed plugin may not take a built-in's name: the built-in keeps it."""
        key = normalize_name(cls.name)
        if (taken := self._builtins[kind].get(key)) is None or taken is cls:
            return None
        return (f"name {key!r} is taken by the built-in {kind} {taken.__module__}.{taken.__qualname__}, which keeps "
                "it; choose another name")  # fmt: skip

    def _hook_arguments_message(self, exc: pluggy.PluginValidationError) -> str:
        """pluggy's refusal of a hook's arguments, on one line, with the arguments the hook passes."""
        message = f"PluginValidationError: {' '.join(str(exc).split())}"
        hook = re.search(r"for hook '(\w+)'", str(exc))
        caller = getattr(self.pm.hook, hook.group(1), None) if hook else None
        if caller is not None and caller.spec is not None:
            message += (f"; {hook.group(1)} passes ({', '.join(caller.spec.argnames)}): take any of them, "
                        "by these names")  # fmt: skip
        return message

    def _unknown_hook(self, plugin) -> str:
        """A hook ``plugin`` implements that frictionlab has none of (a misspelling), said with
        the hook meant; "" if none."""
        hooks = [base.register_hook for base in KINDS.values()] + list(LIFECYCLE_HOOKS)
        for caller in self.pm.get_hookcallers(plugin) or ():
            if caller.name not in hooks:
                hint = did_you_mean(caller.name, hooks, cutoff=0.85) or f"; the hooks are {', '.join(hooks)}"
                return f"unknown hook {caller.name!r}{hint}"
        return ""

    def register_plugin(self, plugin, name: str | None = None) -> None:
        """Register a plugin object (module or class with hookimpls) and re-collect.

        If the plugin is rejected (a misspelled hook: ``pluggy.PluginValidationError``;
        a class breaking the contract, taking a built-in's name or clashing with another:
        ``PluginError``, in the words an installed plugin's failure to load says it), it is
        unregistered again before the error propagates, so the registry is left as it was.
        """
        was_registered = self.pm.is_registered(plugin)
        clashes = set(self.clashes)
        try:
            self.pm.register(plugin, name=name)
            if problem := self._unknown_hook(plugin):  # as a run's discovery says it: with the hook meant
                raise pluggy.PluginValidationError(plugin, f"{problem} (in {plugin!r})")
            self._try_registration(plugin, [])
            self._collect()
            for message in self.clashes:
                if message not in clashes:
                    raise PluginError(message)
        except BaseException:
            if not was_registered and self.pm.is_registered(plugin):
                self.pm.unregister(plugin)
                self._collect()
            raise

    def unregister_plugin(self, plugin) -> None:
        self.pm.unregister(plugin)
        self._collect()

    def _collect(self) -> None:
        """Every registered class by kind and name. A name two classes claim is neither's (an installed
        plugin claiming a built-in's fails to load instead: ``_try_registration``):
        asking for it is an error naming both (``_clashes``); every other name works."""
        tables: dict[str, dict[str, PluginInfo]] = {kind: {} for kind in KINDS}
        clashes: dict[str, dict[str, str]] = {kind: {} for kind in KINDS}
        for kind, base in KINDS.items():

            # each class was checked as its plugin registered (``_try_registration``), a built-in's by
            # the conformance kit's tests: not again at every start
            def register(cls, _kind=kind):
                key = normalize_name(cls.name)
                previous = tables[_kind].get(key)
                if previous is None or previous.cls is cls:
                    tables[_kind][key] = PluginInfo(_kind, key, cls)
                elif key not in clashes[_kind]:
                    clashes[_kind][key] = (
                        f"two {_kind} plugins are named {key!r}: "
                        f"{previous.cls.__module__}.{previous.cls.__qualname__} from {previous.provider} "
                        f"and {cls.__module__}.{cls.__qualname__} from {provider_of(cls)[0]}; "
                        + self._clash_advice(_kind, key)
                    )

            getattr(self.pm.hook, base.register_hook)(register=register)
            for key in clashes[kind]:
                del tables[kind][key]
        self._plugins, self._clashes = tables, clashes

    def _clash_advice(self, kind: str, key: str) -> str:
        """How to be rid of a claim to a taken name: the entry points to block (never a built-in's)."""
        if claims := self._claims.get((kind, key)):
            return f"block one with FRICTIONLAB_BLOCK_PLUGINS={' or '.join(claims)}, or uninstall its distribution"
        return "uninstall or block one of them (FRICTIONLAB_BLOCK_PLUGINS)"

    @property
    def clashes(self) -> list[str]:
        """What is wrong with each name that two plugins of one kind claim."""
        return [message for kind in KINDS for message in self._clashes[kind].values()]

    # ------------------------------------------------------------- queries

    def run_listeners(self) -> list[object]:
        """The registered plugins that implement a lifecycle hook: ``engine.run`` tells them
        of every run, besides the listeners it is given."""
        found: dict[int, list] = {}
        for name in LIFECYCLE_HOOKS:
            for impl in getattr(self.pm.hook, name).get_hookimpls():
                found.setdefault(id(impl.plugin), []).append((name, impl))
        return [self._guarded(impls) for impls in found.values()]

    def _guarded(self, impls) -> GuardedListener:
        """A listening plugin whose hook raises is told by its entry point and distribution."""
        name = self.pm.get_name(impls[0][1].plugin)
        if name in self._distributions:
            label = f"frictionlab plugin {name!r} from {self._distributions[name]}"
            advice = f"tell its authors, or block it (FRICTIONLAB_BLOCK_PLUGINS={name})"
        else:
            module = impls[0][1].function.__module__
            label, advice = f"run listener {module} from {_provider(module)[0]}", "tell its authors"
        return GuardedListener(impls, label, advice)

    def names(self, kind: str) -> list[str]:
        return sorted(self._plugins[kind])

    def infos(self, kind: str | None = None) -> list[PluginInfo]:
        kinds = [kind] if kind else list(KINDS)
        return [self._plugins[k][n] for k in kinds for n in sorted(self._plugins[k])]

    def get(self, kind: str, name: str) -> type[Plugin]:
        return self.info(kind, name).cls

    def info(self, kind: str, name: str) -> PluginInfo:
        if kind not in self._plugins:
            raise PluginError(f"unknown plugin kind {kind!r}; kinds are {', '.join(KINDS)}")
        key = normalize_name(name)
        if key in self._clashes[kind]:
            raise PluginError(self._clashes[kind][key])
        try:
            return self._plugins[kind][key]
        except KeyError:
            raise PluginError(self.not_found_message(kind, name)) from None

    def at_fault(self, exc: BaseException) -> PluginError | None:
        """``exc`` told as the fault of the installed plugin whose code raised it, or None."""
        return plugin_fault(exc, [info.cls for info in self.infos()])

    def not_found_message(self, kind: str, name: str) -> str:
        installed = self.names(kind)
        key = normalize_name(name)
        failed = [f for f in self.failures if (kind, key) in f.claims or (not f.claims and f.entry_point == key)]
        if failed:  # installed, but refused: why, not a guess at another name
            why = "; ".join(f"{f.entry_point} ({f.distribution}): {f.error.rstrip('.')}" for f in failed)
            return (f"{kind} plugin {short_repr(name)} is installed but failed to load: {why}. Fix the plugin "
                    f"(frictionlab plugins then lists it), or choose another: installed {kind} plugins: "
                    f"{', '.join(installed) or 'none'}.")  # fmt: skip
        message = f"no {kind} plugin named {short_repr(name)}{did_you_mean(normalize_name(name), installed) or '.'}"
        message += f" Installed {kind} plugins: {', '.join(installed) or 'none'}."
        if self.failures:
            broken = "; ".join(f"{f.entry_point} ({f.distribution}): {f.error}" for f in self.failures)
            message += f" Plugins that failed to load: {broken}."
        return message


def plugin_fault(exc: BaseException, classes) -> PluginError | None:
    """``exc`` told as the fault of the plugin among ``classes`` whose code raised it (the innermost
    frame of its traceback in a third party's plugin package), or None: the built-ins are
    frictionlab's own, and a fault anywhere else is not a plugin's."""
    place = fault_place(exc, classes)
    if place is None:
        return None
    plugin, where = place
    said = f": {short_repr(str(exc), 300)[1:-1]}" if str(exc) else ""  # MemoryError(), sys.exit(): no message
    return PluginError(f"{plugin} raised {type(exc).__name__}{said} in {where}; the plugin is at fault: "
                       "tell its authors, or choose another plugin")  # fmt: skip


def fault_place(exc: BaseException, classes) -> tuple[str, str] | None:
    """The third party's plugin among ``classes`` whose code raised ``exc``, and where, as messages
    name them: ``("solver 'x' (module.Class from dist)", "solve() at module.py:12")``; None if none."""
    packages: dict[str, type] = {}
    for cls in classes:
        if (top := cls.__module__.partition(".")[0]) not in BUILTIN_MODULES:
            packages.setdefault(top, cls)
    for package, cls in packages.items():
        frame, where, owner = fault_site(exc, package)
        if frame is not None:
            if owner is not None:  # a Params class: the plugin it is of (another class of the package may be first)
                cls = owner if issubclass(owner, Plugin) else next((c for c in classes if c.Params is owner), cls)
            return plugin_label(cls), where
    return None


def solve_failed(exc: BaseException) -> FrictionlabError | None:
    """A ``SolveFailed`` raised outside a realization (the load of full contact, taken while a
    preset is validated or before a run) told as a realization's failure tells it: the plugin's
    own word, naming the plugin whose method raised it, never as its fault nor as a bug; None
    for any other exception."""
    if not isinstance(exc, SolveFailed):
        return None
    frames = [frame for frame, _ in traceback.walk_tb(exc.__traceback__)][::-1]  # innermost first
    owner = next((frame.f_locals["self"] for frame in frames if isinstance(frame.f_locals.get("self"), Plugin)), None)
    return FrictionlabError((f"{plugin_label(type(owner))} raised " if owner is not None else "") + f"SolveFailed: {exc}")


def installed_plugin_fault(exc: BaseException) -> PluginError | None:
    """``exc`` told as the fault of the installed plugin whose code raised it, or None (also when
    no plugin was loaded in this process: none ran)."""
    if default_registry.cache_info().currsize == 0:
        return None
    return default_registry().at_fault(exc)


def installed_plugin_place(exc: BaseException) -> tuple[str, str] | None:
    """Where in an installed plugin ``exc`` was raised (``fault_place``), or None (also when no
    plugin was loaded in this process)."""
    if default_registry.cache_info().currsize == 0:
        return None
    return fault_place(exc, [info.cls for info in default_registry().infos()])


@functools.cache
def default_registry() -> Registry:
    """The process-wide registry, built on first use."""
    return Registry()
