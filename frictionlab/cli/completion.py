"""``frictionlab completion bash|zsh|fish``: a shell completion script, made from the
argument parser itself (commands, their options, the built-in presets' names), so it
never falls behind the commands."""

from __future__ import annotations

import argparse
import shlex

from ..errors import ExitCode

SHELLS = ("bash", "zsh", "fish")
PRESET_ARGUMENTS = {"preset", "presets"}  # positionals that take a preset file or a built-in's name

EXAMPLES = """examples:
  source <(frictionlab completion bash)                                  bash, this shell
  frictionlab completion bash > ~/.local/share/bash-completion/completions/frictionlab
  frictionlab completion zsh > "${fpath[1]}/_frictionlab"                 zsh
  frictionlab completion fish > ~/.config/fish/completions/frictionlab.fish
"""


def add_parser(sub) -> None:
    p = sub.add_parser(
        "completion",
        help="print a shell completion script (bash, zsh, fish)",
        description="Print a completion script for your shell: commands, options and built-in preset names "
        "complete with TAB. Load it as the examples show.",
        epilog=EXAMPLES,
    )
    p.add_argument("shell", choices=SHELLS, help="the shell to complete in")
    p.set_defaults(handler=run)


def run(args) -> ExitCode:
    print(completion_script(args.shell, args.parser), end="")
    return ExitCode.OK


def _commands(parser: argparse.ArgumentParser) -> dict[str, dict]:
    """Per command: its help line, its options, the words its positionals take, and
    whether one of them is a preset."""
    from ..preset.builtin import builtin_presets

    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    helps = {c.dest: c.help or "" for c in sub._choices_actions}
    presets = [p.name for p in builtin_presets()]
    commands = {}
    for name, command in sub.choices.items():
        options, words, takes_preset = [], [], False
        for action in command._actions:
            if action.option_strings:
                options += [o for o in action.option_strings if o.startswith("--")] or action.option_strings
            elif isinstance(action, argparse._SubParsersAction):
                words += list(action.choices)
            elif action.choices:
                words += [str(c) for c in action.choices]
            elif action.dest in PRESET_ARGUMENTS:
                takes_preset = True
        if name == "presets":  # `presets copy NAME`: a built-in's name
            words += presets
        if takes_preset:
            words += presets
        commands[name] = {"help": helps.get(name, ""), "options": options, "words": words, "files": takes_preset}
    return commands


def completion_script(shell: str, parser: argparse.ArgumentParser) -> str:
    commands = _commands(parser)
    if shell == "fish":
        return _fish(commands)
    script = _bash(commands)
    if shell == "zsh":  # zsh runs the bash function through its bash compatibility layer
        return "#compdef frictionlab\nautoload -U +X bashcompinit && bashcompinit\n" + script
    return script


def _bash(commands: dict[str, dict]) -> str:
    cases = "\n".join(
        f"        {name}) opts={shlex.quote(' '.join(c['options']))}; words={shlex.quote(' '.join(c['words']))}; "
        f"files={1 if c['files'] else 0} ;;"
        for name, c in commands.items()
    )
    return f"""# frictionlab completion for bash (frictionlab completion bash)
_frictionlab() {{
    local cur="${{COMP_WORDS[COMP_CWORD]}}" command="" opts="" words="" files=1 i
    for ((i = 1; i < COMP_CWORD; i++)); do
        case "${{COMP_WORDS[i]}}" in
            -*) ;;
            *) command="${{COMP_WORDS[i]}}"; break ;;
        esac
    done
    if [[ -z "$command" ]]; then
        COMPREPLY=($(compgen -W {shlex.quote(' '.join(commands) + ' -h --help -V --version')} -- "$cur"))
        return
    fi
    case "$command" in
{cases}
    esac
    if [[ "$cur" == -* ]]; then
        COMPREPLY=($(compgen -W "$opts -h --help" -- "$cur"))
        return
    fi
    COMPREPLY=($(compgen -W "$words" -- "$cur"))
    if [[ "$files" == 1 ]]; then
        COMPREPLY+=($(compgen -f -- "$cur"))
    fi
}}
complete -o filenames -F _frictionlab frictionlab
"""


def _fish(commands: dict[str, dict]) -> str:
    def q(text: str) -> str:
        return "'" + text.replace("\\", "\\\\").replace("'", "\\'") + "'"

    lines = ["# frictionlab completion for fish (frictionlab completion fish)", "complete -c frictionlab -f"]
    lines += ["complete -c frictionlab -n __fish_use_subcommand -s V -l version -d 'print the version and exit'"]
    for name, c in commands.items():
        lines.append(f"complete -c frictionlab -n __fish_use_subcommand -a {name} -d {q(c['help'])}")
        seen = f"-n '__fish_seen_subcommand_from {name}'"
        for option in c["options"]:
            flag = f"-l {option[2:]}" if option.startswith("--") else f"-s {option[1:]}"
            lines.append(f"complete -c frictionlab {seen} {flag}")
        if c["words"]:
            lines.append(f"complete -c frictionlab {seen} -a {q(' '.join(c['words']))}")
        if c["files"]:
            lines.append(f"complete -c frictionlab {seen} -F")
    return "\n".join(lines) + "\n"
