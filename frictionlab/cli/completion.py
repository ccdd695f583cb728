"""``frictionlab completion bash|zsh|fish``: a shell completion script made from the
argument parser itself, so it never falls behind the commands.

The parser is walked once (``command_specs``) into what each word may be: a command,
an option, an option's value (its choices, a file, a folder, a ``--set`` path from the
preset schema), or a positional (a preset: a built-in's name or a YAML file). Each
shell's script is that table written in the shell's own terms."""

from __future__ import annotations

import argparse
import shlex
from dataclasses import dataclass, field

from ..errors import ExitCode
from .options import PATH_METAVARS

SHELLS = ("bash", "zsh", "fish")

EXAMPLES = """examples:
  source <(frictionlab completion bash)                                  bash, this shell
  frictionlab completion bash > ~/.local/share/bash-completion/completions/frictionlab
  frictionlab completion zsh > "${fpath[1]}/_frictionlab"                 zsh
  frictionlab completion fish > ~/.config/fish/completions/frictionlab.fish
"""

# What a value is, from its argument's metavar or (for a positional) its dest. A value
# with none of these (a number, an address) is not completed.
FILES, DIRS, PRESETS, BUILTINS, SETTINGS, WORDS, NOTHING = "files", "dirs", "presets", "builtins", "settings", "words", ""
KIND_OF_METAVAR = {**{metavar: DIRS if what == "folder" else FILES for metavar, what in PATH_METAVARS.items()},
                   "NAME": BUILTINS, "PATH=VALUE": SETTINGS}
KIND_OF_DEST = {"preset": PRESETS, "presets": PRESETS}


def add_parser(sub) -> None:
    p = sub.add_parser(
        "completion",
        help="print a shell completion script (bash, zsh, fish)",
        description="Print a completion script for your shell: commands, options, their choices, built-in and "
        "local presets, files and --set paths complete with TAB. Load it as the examples show.",
        epilog=EXAMPLES,
    )
    p.add_argument("shell", choices=SHELLS, help="the shell to complete in")
    p.set_defaults(handler=run)


def run(args) -> ExitCode:
    print(completion_script(args.shell, args.parser), end="")
    return ExitCode.OK


@dataclass
class Value:
    """What the words of one argument may be: ``kind`` (one of the kinds above) and,
    for ``WORDS``, the words; ``count`` words follow an option (0 for a flag)."""

    kind: str = NOTHING
    words: tuple[str, ...] = ()
    count: int = 1
    repeats: bool = False  # a positional that takes every further word (nargs "+" or "*")


@dataclass
class Command:
    """One command (``run``) or nested command (``presets copy``) of the parser."""

    path: str  # "" for frictionlab itself
    help: str = ""
    options: dict[str, Value] = field(default_factory=dict)  # every flag, -h and --help once each
    positionals: list[Value] = field(default_factory=list)
    commands: list[str] = field(default_factory=list)  # the nested commands' names


def _value(action: argparse.Action) -> Value:
    count = action.nargs if isinstance(action.nargs, int) else 1
    repeats = action.nargs in ("+", "*")
    if action.choices:
        return Value(WORDS, tuple(map(str, action.choices)), count, repeats)
    kind = KIND_OF_METAVAR.get(action.metavar) if isinstance(action.metavar, str) else None
    if kind is None and not action.option_strings:
        kind = KIND_OF_DEST.get(action.dest)
    return Value(kind or NOTHING, (), count, repeats)


def command_specs(parser: argparse.ArgumentParser) -> list[Command]:
    """Every command of ``parser``, frictionlab itself first, each with what its words may be."""
    found = []

    def walk(parser: argparse.ArgumentParser, path: str, help: str) -> None:
        command = Command(path, help)
        found.append(command)
        for action in parser._actions:
            if isinstance(action, argparse._SubParsersAction):
                helps = {c.dest: c.help or "" for c in action._choices_actions}
                command.commands = list(action.choices)
                for name, sub in action.choices.items():
                    walk(sub, f"{path} {name}".strip(), helps.get(name, ""))
            elif action.option_strings:
                for option in action.option_strings:
                    command.options[option] = _value(action)
            else:
                command.positionals.append(_value(action))

    walk(parser, "", "")
    return found


def settable_paths(schema: dict) -> list[str]:
    """Every dotted path ``--set`` can give a value to, read from the preset's JSON Schema
    (``frictionlab schema``): a plugin's parameters under every installed plugin of its kind."""
    definitions = schema.get("$defs", {})
    paths: set[str] = set()

    def walk(node: dict, path: str) -> None:
        if "$ref" in node:
            node = definitions.get(node["$ref"].rsplit("/", 1)[-1], {})
        variants = node.get("oneOf") or node.get("anyOf")
        if variants:
            for variant in variants:
                walk(variant, path)
            return
        properties = node.get("properties")
        if not properties:
            if path and node.get("type") not in ("null", "object"):  # an object without fields takes no value
                paths.add(path)
            return
        for name, child in properties.items():
            walk(child, f"{path}.{name}" if path else name)

    walk(schema, "")
    return sorted(paths)


def _dynamic_words() -> dict[str, list[str]]:
    from ..preset import preset_json_schema
    from ..preset.builtin import builtin_presets

    return {BUILTINS: [p.name for p in builtin_presets()], SETTINGS: [f"{p}=" for p in settable_paths(preset_json_schema())]}


def completion_script(shell: str, parser: argparse.ArgumentParser) -> str:
    commands, words = command_specs(parser), _dynamic_words()
    if shell == "fish":
        return _fish(commands, words)
    script = _bash(commands, words)
    if shell == "zsh":  # zsh runs the bash function through its bash compatibility layer
        return "#compdef frictionlab\nautoload -U +X bashcompinit && bashcompinit\n" + script
    return script


# ------------------------------------------------------------------ bash (and zsh)


def _bash_values(value: Value) -> str:
    """The bash lines that fill COMPREPLY for one value."""
    if value.kind == WORDS:
        return f"COMPREPLY=($(compgen -W {shlex.quote(' '.join(value.words))} -- \"$cur\"))"
    if value.kind == FILES:
        return 'compopt -o filenames 2>/dev/null; COMPREPLY=($(compgen -f -- "$cur"))'
    if value.kind == DIRS:
        return 'compopt -o filenames 2>/dev/null; COMPREPLY=($(compgen -d -- "$cur"))'
    if value.kind == BUILTINS:
        return 'COMPREPLY=($(compgen -W "$_frictionlab_builtins" -- "$cur"))'
    if value.kind == PRESETS:  # a built-in's name, a YAML file, or a folder on the way to one
        return ('compopt -o filenames 2>/dev/null; COMPREPLY=($(compgen -W "$_frictionlab_builtins" -- "$cur") '
                '$(compgen -f -X \'!*.yaml\' -- "$cur") $(compgen -f -X \'!*.yml\' -- "$cur") $(compgen -d -- "$cur"))')  # fmt: skip
    if value.kind == SETTINGS:
        return 'compopt -o nospace 2>/dev/null; COMPREPLY=($(compgen -W "$_frictionlab_settings" -- "$cur"))'
    return "COMPREPLY=()"


def _bash(commands: list[Command], words: dict[str, list[str]]) -> str:
    specs, values = [], []
    for command in commands:
        takes = " ".join(f"{o}:{v.count}" for o, v in command.options.items() if v.count)
        specs.append(
            f"        {shlex.quote(command.path)}) commands={shlex.quote(' '.join(command.commands))}; "
            f"options={shlex.quote(' '.join(command.options))}; takes={shlex.quote(takes)} ;;"
        )
        for option, value in command.options.items():
            if value.count:
                values.append(f"        {shlex.quote(command.path + ' ' + option)}) {_bash_values(value)} ;;")
        for number, value in enumerate(command.positionals, 1):
            values.append(f"        {shlex.quote(f'{command.path} #{number}')}) {_bash_values(value)} ;;")
        if command.positionals and command.positionals[-1].repeats:  # nargs="+": every further word
            values.append(f"        {shlex.quote(command.path + ' #*')}) {_bash_values(command.positionals[-1])} ;;")
    builtins, settings = " ".join(words[BUILTINS]), " ".join(words[SETTINGS])
    spec_cases, value_cases = "\n".join(specs), "\n".join(values)
    return f"""# frictionlab completion for bash (frictionlab completion bash), made from its parser
_frictionlab_builtins={shlex.quote(builtins)}
_frictionlab_settings={shlex.quote(settings)}

_frictionlab_spec() {{  # the nested commands, options and valued options (OPTION:COUNT) of command "$1"
    commands="" options="" takes=""
    case "$1" in
{spec_cases}
    esac
}}

_frictionlab_values() {{  # COMPREPLY for "$1": "COMMAND OPTION" (its value) or "COMMAND #N" (its N-th word)
    COMPREPLY=()
    case "$1" in
{value_cases}
        *'#'[0-9]*) _frictionlab_values "${{1% #*}} #*" ;;
    esac
}}

_frictionlab() {{
    local cur="${{COMP_WORDS[COMP_CWORD]}}" path="" commands options takes word pending="" skip=0 position=0 i
    _frictionlab_spec ""
    for ((i = 1; i < COMP_CWORD; i++)); do
        word="${{COMP_WORDS[i]}}"
        if [[ "$word" == "=" ]]; then  # bash splits --out=DIR and --set a.b=1 at "=": a value follows
            if ((i + 1 < COMP_CWORD)); then
                ((i++))
                skip=0
            fi
            continue
        fi
        if ((skip > 0)); then
            ((skip--))
            continue
        fi
        if [[ "$word" == -* ]]; then
            pending="$word" skip=0
            for spec in $takes; do
                [[ "${{spec%:*}}" == "$word" ]] && skip="${{spec##*:}}"
            done
        elif [[ " $commands " == *" $word "* ]]; then
            path="${{path:+$path }}$word" position=0
            _frictionlab_spec "$path"
        else
            ((position++))
        fi
    done
    if ((skip > 0)); then
        _frictionlab_values "$path $pending"
    elif [[ "${{COMP_WORDS[COMP_CWORD - 1]}}" == "=" ]]; then  # the value of a --set path: yours to type
        COMPREPLY=()
    elif [[ "$cur" == -* ]]; then
        COMPREPLY=($(compgen -W "$options" -- "$cur"))
    elif [[ -n "$commands" && $position == 0 ]]; then
        COMPREPLY=($(compgen -W "$commands" -- "$cur"))
    else
        _frictionlab_values "$path #$((position + 1))"
    fi
}}
complete -F _frictionlab frictionlab
"""


# ------------------------------------------------------------------ fish


def _fish_quote(text: str) -> str:
    return "'" + text.replace("\\", "\\\\").replace("'", "\\'") + "'"


def _fish_values(value: Value, words: dict[str, list[str]]) -> str:
    """The fish flags that complete one value (-r: it takes one; -F files; -x no files)."""
    if value.kind == WORDS:
        return f"-x -a {_fish_quote(' '.join(value.words))}"
    if value.kind == FILES:
        return "-F"
    if value.kind == PRESETS:  # a built-in's name, a YAML file, or a folder on the way to one
        files = "(string match -r -- '.*\\.ya?ml$' (__fish_complete_suffix .yaml)) (__fish_complete_directories)"
        return f"-x -a {_fish_quote(' '.join(words[BUILTINS]) + ' ' + files)}"
    if value.kind == DIRS:
        return "-x -a '(__fish_complete_directories)'"
    if value.kind in (BUILTINS, SETTINGS):
        return f"-x -a {_fish_quote(' '.join(words[value.kind]))}"
    return "-x"


def _fish(commands: list[Command], words: dict[str, list[str]]) -> str:
    top = commands[0]
    names = " ".join(top.commands)
    lines = [
        "# frictionlab completion for fish (frictionlab completion fish), made from its parser",
        "complete -c frictionlab -f",
    ]
    for command in commands:
        depth = command.path.split()
        if not depth:
            condition = "__fish_use_subcommand"
        elif len(depth) == 1:
            nested = " ".join(c.path.split()[-1] for c in commands if c.path.startswith(command.path + " "))
            condition = f"'__fish_seen_subcommand_from {depth[0]}" + (f"; and not __fish_seen_subcommand_from {nested}'" if nested else "'")
        else:
            condition = f"'__fish_seen_subcommand_from {depth[0]}; and __fish_seen_subcommand_from {depth[-1]}'"
        for name in command.commands:
            sub = next(c for c in commands if c.path == f"{command.path} {name}".strip())
            lines.append(f"complete -c frictionlab -n {condition} -a {name} -d {_fish_quote(sub.help)}")
        for option, value in command.options.items():
            if option in ("-h", "--help") and command.path:
                continue
            flag = f"-l {option[2:]}" if option.startswith("--") else f"-s {option[1:]}"
            completes = f" -r {_fish_values(value, words)}" if value.count else ""
            lines.append(f"complete -c frictionlab -n {condition} {flag}{completes}")
        if command.path and command.positionals:
            lines.append(f"complete -c frictionlab -n {condition} {_fish_values(command.positionals[0], words)}")
    lines.append(f"complete -c frictionlab -n 'not __fish_use_subcommand; and __fish_seen_subcommand_from {names}' -s h -l help")
    return "\n".join(lines) + "\n"
