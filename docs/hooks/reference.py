"""mkdocs hooks: the reference pages generated from the code at build time.

- reference/cli.md: every command and flag, walked from ``frictionlab.cli.main``'s
  argument parser (what ``frictionlab COMMAND --help`` prints, as tables);
- reference/presets.md: every section of a preset and every built-in plugin's
  parameters, from their pydantic models' JSON Schema;
- reference/json.md: the shapes of ``--json`` output, from ``frictionlab.cli.jsonout``;
- explanation/reproduction.md: REPRODUCTION.md as ``frictionlab report`` wrote it,
  its figure paths made relative to the page;
- architecture.md: ARCHITECTURE.md, the layers of the code.

Nothing here is written to the source tree: the pages exist in the built site only.
"""

from __future__ import annotations

import argparse
import json
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def on_files(files, config):
    from mkdocs.structure.files import File

    pages = {
        "reference/cli.md": cli_reference(),
        "reference/presets.md": preset_reference(),
        "reference/json.md": json_reference(),
        "explanation/reproduction.md": reproduction_page(),
        "architecture.md": (ROOT / "ARCHITECTURE.md").read_text(encoding="utf-8"),
    }
    for src_uri, content in pages.items():
        files.append(File.generated(config, src_uri, content=content))
    return files


# --------------------------------------------------------------------------- CLI


def _cell(text) -> str:
    """A Markdown table cell: one line, pipes escaped, and ``<name>`` shown as written (not
    taken for an HTML tag, which the page would drop)."""
    text = " ".join(str(text).split()).replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")
    return text.replace("|", "\\|")


def _flag(action: argparse.Action) -> str:
    names = ", ".join(f"`{name}`" for name in action.option_strings) or f"`{action.metavar or action.dest}`"
    if action.nargs == 0:
        return names
    metavar = action.metavar or (("{" + ",".join(map(str, action.choices)) + "}") if action.choices else action.dest.upper())
    if isinstance(metavar, tuple):
        metavar = " ".join(metavar)
    if isinstance(action.nargs, int) and action.nargs > 1 and " " not in metavar:
        metavar = " ".join([metavar] * action.nargs)
    return f"{names} `{metavar}`" if action.option_strings else names


def _actions_table(parser: argparse.ArgumentParser) -> list[str]:
    rows = ["| argument | what it does |", "|---|---|"]
    for action in parser._actions:
        if isinstance(action, (argparse._HelpAction, argparse._SubParsersAction)):
            continue
        help_text = "" if action.help == argparse.SUPPRESS else (action.help or "")
        if action.required and action.option_strings:
            help_text += " (required)"
        if action.choices and not action.option_strings and not help_text:
            help_text = "one of " + ", ".join(map(str, action.choices))
        rows.append(f"| {_flag(action)} | {_cell(help_text)} |")
    return rows if len(rows) > 2 else []


def subcommands(parser: argparse.ArgumentParser) -> dict[str, tuple[argparse.ArgumentParser, str]]:
    """``{name: (subparser, one-line help)}`` of ``parser``'s commands, in the parser's order."""
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            helps = {choice.dest: choice.help or "" for choice in action._choices_actions}
            return {name: (sub, helps.get(name, "")) for name, sub in action.choices.items()}
    return {}


def cli_reference() -> str:
    from frictionlab.cli.main import build_parser

    parser = build_parser()
    parser.prog = "frictionlab"
    commands = subcommands(parser)
    out = [
        "# Command-line reference",
        "",
        "Generated from the argument parser when the site is built: it is what",
        "`frictionlab COMMAND --help` prints, command by command.",
        "",
        "```text",
        parser.format_usage().strip(),
        "```",
        "",
        _cell(parser.description or ""),
        "",
        *_actions_table(parser),
        "",
        "| command | what it does |",
        "|---|---|",
        *(f"| [`{name}`](#{name}) | {_cell(help_text)} |" for name, (_, help_text) in commands.items()),
        "",
        "Exit codes, for every command: see [what frictionlab promises about your data](../data-safety.md).",
        "",
    ]
    for name, (sub, help_text) in commands.items():
        out += [f"## {name}", "", _cell(sub.description or help_text), ""]
        out += ["```text", sub.format_usage().strip(), "```", ""]
        out += _actions_table(sub) + [""]
        if sub.epilog:
            out += ["```text", sub.epilog.strip(), "```", ""]
        for nested, (nested_parser, nested_help) in subcommands(sub).items():
            out += [f"### {name} {nested}", "", _cell(nested_parser.description or nested_help), ""]
            out += ["```text", nested_parser.format_usage().strip(), "```", ""]
            out += _actions_table(nested_parser) + [""]
    return "\n".join(out)


def json_reference() -> str:
    from frictionlab.cli.jsonout import SHAPES, VERSION, shape

    out = [
        "# JSON output",
        "",
        "With `--json`, a command prints one JSON object on stdout and nothing else there (progress and",
        "messages go to stderr). Its first key names its shape and version, for example",
        f'`{{"schema": "{shape("run")}", ...}}`; the version (now {VERSION}) goes up when a key is removed or',
        "changes meaning, and keys may be added within a version. A command refused or failed under",
        "`--json` prints the `error` shape, with the process's exit code in it",
        "(exit codes: [your data and exit codes](../data-safety.md)). `frictionlab schema` prints a JSON",
        "Schema document for editors, not one of these.",
        "",
        "| schema | printed by | holds |",
        "|---|---|---|",
        *(f"| `{shape(name)}` | {_cell(commands)} | {holds} |" for name, (commands, holds) in SHAPES.items()),
        "",
        "For example, the fit's slope of a run, in a script:",
        "",
        "```bash",
        "frictionlab run quickstart --quiet --json | python -c 'import json, sys; print(json.load(sys.stdin)[\"fit\"][\"b\"])'",
        "```",
        "",
    ]
    return "\n".join(out)


# ------------------------------------------------------------------- presets


# a nested model of the preset -> how its type reads in a table
_SECTIONS = {
    "PluginChoice": "`{name, params}`",
    "Loading": "[section](#loading)",
    "FitSettings": "[section](#fit)",
    "OutputSettings": "[section](#output)",
    "SweepSettings": "[section](#sweep)",
    "SweepParameter": "[values or range](#sweepparameterspath)",
}


def _reference(ref: str) -> str:
    """A DOI as doi:10...; a citation without one (Love 1929) as it is written."""
    return f"doi:{ref}" if ref.startswith("10.") else ref


def _schema_type(prop: dict, defs: dict) -> str:
    if "$ref" in prop:
        title = defs.get(prop["$ref"].rsplit("/", 1)[-1], {}).get("title", "object")
        return _SECTIONS.get(title, title)
    if prop.get("type") == "object" and "additionalProperties" in prop:
        return "mapping of dotted path to " + _schema_type(prop["additionalProperties"], defs)
    if "enum" in prop:
        return " \\| ".join(f"`{v}`" for v in prop["enum"])
    if "const" in prop:
        return f"`{prop['const']}`"
    if "anyOf" in prop:
        return " or ".join(_schema_type(p, defs) for p in prop["anyOf"])
    if prop.get("type") == "array":
        item = _schema_type(prop.get("items", {}), defs)
        return f"list of ({item})" if " or " in item else f"list of {item}"  # not "list of x or null or null"
    return prop.get("type", "any")


_BOUNDS = (("minimum", ">="), ("exclusiveMinimum", ">"), ("maximum", "<="), ("exclusiveMaximum", "<"))


def _bounds(prop: dict) -> str:
    found = [f"{sign} {prop[key]:g}" if isinstance(prop[key], float) else f"{sign} {prop[key]}" for key, sign in _BOUNDS if key in prop]
    for option in prop.get("anyOf", []):
        found += [f"{sign} {option[key]}" for key, sign in _BOUNDS if key in option]
    return ", ".join(found)


def _default(model, key: str) -> str:
    """The field's default as YAML would spell it (a factory's value too)."""
    from pydantic import BaseModel

    value = model.model_fields[key].get_default(call_default_factory=True)
    if isinstance(value, BaseModel):
        value = value.model_dump(exclude_defaults=True)
    return f"`{json.dumps(value)}`"


def fields_table(model) -> list[str]:
    """One row per field of a pydantic model, from its JSON Schema: name, type, default, bounds, description."""
    schema = model.model_json_schema()
    defs = schema.get("$defs", {})
    required = set(schema.get("required", []))
    rows = ["| key | type | default | allowed | meaning |", "|---|---|---|---|---|"]
    for key, prop in schema.get("properties", {}).items():
        default = "required" if key in required else _default(model, key)
        rows.append(
            f"| `{key}` | {_schema_type(prop, defs)} | {_cell(default)} | {_bounds(prop)} | {_cell(prop.get('description', ''))} |"
        )
    return rows


def preset_reference() -> str:
    from frictionlab.plugin import KINDS
    from frictionlab.preset.schema import FitSettings, Loading, OutputSettings, Preset, SweepParameter, SweepSettings
    from frictionlab.plugin.registry import Registry

    out = [
        "# Preset reference",
        "",
        "Generated from the preset's pydantic models and the built-in plugins' `Params` when",
        "the site is built. `frictionlab schema` prints the same as JSON Schema, with the",
        "parameters of every plugin installed where you run it. A preset is YAML read safely;",
        "an unknown key anywhere is an error naming its dotted path.",
        "",
        "## Top level",
        "",
        *fields_table(Preset),
        "",
    ]
    for title, model in (
        ("loading", Loading),
        ("fit", FitSettings),
        ("output", OutputSettings),
        ("sweep", SweepSettings),
        ("sweep.parameters.PATH", SweepParameter),
    ):
        doc = " ".join((model.__doc__ or "").split()) if model.__doc__ and "pydantic" not in model.__doc__ else ""
        out += [f"## `{title}`", "", *([doc, ""] if doc else []), *fields_table(model), ""]
    out += [
        "## Built-in plugins",
        "",
        "A preset names one plugin of each kind, `{name: ..., params: {...}}`; these are the",
        "ones frictionlab ships (`frictionlab plugins` lists what is installed where you are).",
        "",
    ]
    registry = Registry(discover=False)
    out += ["| kind | name | what it is |", "|---|---|---|"]
    out += [
        f"| {kind} | [`{info.name}`](#{kind}-{info.name}) | {_cell(info.summary)} |"
        for kind in KINDS
        for info in registry.infos(kind)
    ]
    out += [""]
    for kind in KINDS:
        for info in registry.infos(kind):
            out += [f"### {kind}: `{info.name}`", "", _cell(info.summary), ""]
            if info.cls.references:
                out += ["References: " + "; ".join(_reference(ref) for ref in info.cls.references), ""]
            table = fields_table(info.cls.Params)
            out += (table if len(table) > 2 else ["No parameters."]) + [""]
    return "\n".join(out)


# -------------------------------------------------------------- reproduction


def reproduction_page() -> str:
    text = (ROOT / "REPRODUCTION.md").read_text(encoding="utf-8")
    # REPRODUCTION.md sits at the top of the repository; this page sits in docs/explanation/
    return re.sub(r"\]\(docs/", "](../", text)
