"""The README and the documentation site say only what is true of the code: every
`frictionlab` command shown parses with the real parser, every benchmark flag shown
exists, every relative link of the README resolves, every test the extremes page names
exists, and the generated references cover every command, flag and plugin parameter.
(`mkdocs build --strict` in CI checks the site's own links and anchors.)"""

from __future__ import annotations

import argparse
import contextlib
import importlib.util
import io
import re
import shlex
from pathlib import Path

import pytest

from frictionlab.cli.main import build_parser
from frictionlab.plugin.registry import Registry

from .conftest import ROOT

DOCS = ROOT / "docs"
PAGES = sorted(DOCS.rglob("*.md"))
README = ROOT / "README.md"
TEST_COMMAND = 'pip install -e ".[test]" && pytest'


def _text(path: Path) -> str:
    return path.read_text(encoding="utf-8")


def _reference_hooks():
    spec = importlib.util.spec_from_file_location("docs_reference_hooks", DOCS / "hooks" / "reference.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


# ------------------------------------------------------------------ the README


def test_the_readme_is_at_most_200_lines():
    lines = _text(README).count("\n")
    assert lines <= 200, f"README.md has {lines} lines; the rest belongs in docs/"


def test_the_test_command_is_verbatim_in_the_readme_and_in_ci():
    assert TEST_COMMAND in _text(README)
    ci_lines = [line.strip() for line in _text(ROOT / ".ci" / "run").splitlines()]
    assert TEST_COMMAND in ci_lines, ".ci/run must run the README's test command as a line of its own"


def test_ci_builds_the_docs_strictly():
    ci = _text(ROOT / ".ci" / "run")
    assert "mkdocs build --strict" in ci
    assert '"mkdocs-material' in _text(ROOT / "pyproject.toml")


def _relative_links(text: str) -> list[str]:
    targets = re.findall(r"\]\(([^)\s]+)\)", text)
    return [t.split("#", 1)[0] for t in targets if not re.match(r"[a-z]+:", t) and not t.startswith("#")]


@pytest.mark.parametrize("doc", ["README.md", "ARCHITECTURE.md", "examples/frictionlab-gaussian/README.md"])
def test_relative_links_resolve(doc):
    path = ROOT / doc
    missing = [t for t in _relative_links(_text(path)) if not (path.parent / t).exists()]
    assert not missing, f"{doc} links to missing files: {missing}"


# ------------------------------------------------------ nothing outside the repo


def _project_files():
    roots = [
        "README.md", "ARCHITECTURE.md", "REPRODUCTION.md", "mkdocs.yml", "pyproject.toml", ".ci",
        "docs", "frictionlab", "plugins", "presets", "examples", "tests", "benchmarks",
    ]  # fmt: skip
    for root in roots:
        path = ROOT / root
        files = [path] if path.is_file() else path.rglob("*")
        for file in files:
            if file.is_file() and (file.suffix in {".md", ".py", ".yaml", ".yml", ".toml", ".tcss", ".txt"} or file.name == "run"):
                yield file


OUTSIDE = re.compile(r"\.\./shared|\b" + "SP" + "EC" + r"\b")  # spelled apart: this file names no such document


def test_no_project_file_points_outside_the_repository():
    offending = []
    for file in _project_files():
        for number, line in enumerate(_text(file).splitlines(), 1):
            if OUTSIDE.search(line):
                offending.append(f"{file.relative_to(ROOT)}:{number}: {line.strip()[:80]}")
    assert not offending, "a user-facing file points to a document outside the repository:\n" + "\n".join(offending)


# --------------------------------------------------------- commands that parse


def _code_lines(text: str) -> list[tuple[str, str]]:
    """("block", line) for each line of a fenced code block (a `$ ` prompt stripped) and
    ("inline", span) for each inline code span."""
    lines = []
    for block in re.findall(r"^ *```[a-z]*\n(.*?)^ *```", text, flags=re.S | re.M):
        lines += [("block", line.strip().removeprefix("$ ")) for line in block.splitlines()]
    lines += [("inline", span) for span in re.findall(r"(?<!`)`([^`\n]+)`(?!`)", text)]
    return lines


def _invocations(line: str, program: str) -> list[list[str]]:
    """Each `program ...` command of a shell line (after `&&`, `;`, `|`, env assignments)."""
    found = []
    for part in re.split(r"&&|;|\||\s>\s", line.split(" #", 1)[0]):
        try:
            words = shlex.split(part)
        except ValueError:
            continue
        while words and re.match(r"^[A-Z_]+=", words[0]):
            words = words[1:]
        if words and words[0] == program:
            found.append(words[1:])
    return found


def _documented(program: str, kind: str | None = None) -> list[tuple[str, list[str]]]:
    out = []
    for path in [README, *PAGES]:
        for found, line in _code_lines(_text(path)):
            if kind in (None, found):
                out += [(str(path.relative_to(ROOT)), argv) for argv in _invocations(line, program)]
    return out


def _is_usage_synopsis(argv: list[str]) -> bool:
    """`frictionlab COMMAND --help`, `frictionlab tui [PRESET] ...`: a form, not a command."""
    return any(w.startswith("[") or w == "..." or re.fullmatch(r"[A-Z][A-Z_]+", w) for w in argv)


COMMANDS = [(where, argv) for where, argv in _documented("frictionlab", "block") if not _is_usage_synopsis(argv)]
MENTIONS = [  # `frictionlab COMMAND --help` names no command
    (where, argv) for where, argv in _documented("frictionlab", "inline") if argv and argv[0] != "COMMAND"
]


def test_the_docs_show_commands():
    assert len(COMMANDS) >= 20 and len(MENTIONS) >= 20
    shown = {argv[0] for _, argv in COMMANDS + MENTIONS}
    assert {"run", "resume", "validate", "schema", "plugins", "report", "predict", "tui", "study"} <= shown


@pytest.mark.parametrize("where,argv", COMMANDS, ids=[" ".join(a)[:60] for _, a in COMMANDS])
def test_every_command_shown_is_a_real_command_with_real_flags(where, argv):
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        try:
            build_parser().parse_args(argv)
        except SystemExit as exc:
            assert exc.code == 0 and "--help" in argv, f"{where}: `frictionlab {shlex.join(argv)}`: {err.getvalue()}"


def _subcommands(parser: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    return next(a.choices for a in parser._actions if isinstance(a, argparse._SubParsersAction))


@pytest.mark.parametrize("where,argv", MENTIONS, ids=[" ".join(a)[:60] for _, a in MENTIONS])
def test_every_command_named_in_the_text_exists_with_its_flags(where, argv):
    """Inline code may name a command without its arguments (`frictionlab run`), or
    sketch one (`frictionlab tui [PRESET] [--presets DIR]`): its command and flags must exist."""
    parser = build_parser()
    if argv[0].startswith("-"):
        sub = parser
    else:
        assert argv[0] in _subcommands(parser), f"{where}: no command `frictionlab {argv[0]}`"
        sub = _subcommands(parser)[argv[0]]
    options = {o for action in sub._actions for o in action.option_strings}
    for word in argv:
        flag = word.strip("[]").split("=", 1)[0]
        if flag.startswith("--"):
            assert flag in options, f"{where}: `frictionlab {argv[0]}` has no flag {flag}"


BENCHMARKS = [
    (where, argv)
    for where, argv in _documented("python")
    if argv and argv[0].startswith("benchmarks/") and not _is_usage_synopsis(argv)
]


@pytest.mark.parametrize("where,argv", BENCHMARKS, ids=[" ".join(a) for _, a in BENCHMARKS])
def test_every_benchmark_shown_exists_with_its_flags(where, argv):
    script = ROOT / argv[0]
    assert script.is_file(), f"{where}: {argv[0]} does not exist"
    source = _text(script)
    for flag in (w for w in argv[1:] if w.startswith("--")):
        assert f'"{flag}"' in source, f"{where}: {argv[0]} has no flag {flag}"


def test_python_modules_run_as_shown_exist():
    shown = {argv[1] for _, argv in _documented("python") if len(argv) > 1 and argv[0] == "-m"}
    assert "frictionlab.paper.calibration" in shown
    for module in shown:
        assert importlib.util.find_spec(module) is not None, f"python -m {module}: no such module"


# ------------------------------------------------------------ generated pages


def test_the_cli_reference_covers_every_command_and_flag():
    page = _reference_hooks().cli_reference()

    def walk(parser: argparse.ArgumentParser, prefix: str):
        for action in parser._actions:
            if isinstance(action, argparse._HelpAction):
                continue
            for option in action.option_strings:
                assert f"`{option}`" in page, f"the CLI reference misses {prefix} {option}"
            if isinstance(action, argparse._SubParsersAction):
                for name, sub in action.choices.items():
                    assert re.search(rf"^##+ {re.escape((prefix + ' ' + name).strip())}$", page, flags=re.M), (
                        f"the CLI reference has no section for {prefix} {name}"
                    )
                    walk(sub, f"{prefix} {name}".strip())

    walk(build_parser(), "")


def test_the_preset_reference_covers_every_section_and_builtin_parameter():
    page = _reference_hooks().preset_reference()
    for section in ("loading", "fit", "output", "sweep"):
        assert f"## `{section}`" in page
    registry = Registry(discover=False)
    for info in registry.infos():
        assert f"### {info.kind}: `{info.name}`" in page
        for field in info.cls.Params.model_fields:
            assert f"| `{field}` |" in page, f"the preset reference misses {info.kind} {info.name}: {field}"


def test_the_reproduction_page_is_the_report_with_its_figures_found():
    page = _reference_hooks().reproduction_page()
    assert page.startswith(_text(ROOT / "REPRODUCTION.md").split("\n", 1)[0])
    figures = re.findall(r"!\[[^\]]*\]\(([^)]+)\)", page)
    assert figures, "REPRODUCTION.md has no figures"
    for figure in figures:  # the page is docs/explanation/reproduction.md
        assert (DOCS / "explanation" / figure).resolve().is_file(), figure


# ------------------------------------------------------- facts named in pages


def test_every_test_the_extremes_page_names_exists():
    page = _text(DOCS / "explanation" / "extremes.md")
    names = set(re.findall(r"`(?:\w+::)?(test_\w+)`", page))
    assert len(names) >= 10
    defined = set()
    for file in (ROOT / "tests").rglob("test_*.py"):
        defined |= set(re.findall(r"^(?:async )?def (test_\w+)", _text(file), flags=re.M))
    assert not names - defined, f"docs/explanation/extremes.md names tests that do not exist: {sorted(names - defined)}"


def _nav_pages(section: str) -> list[str]:
    """The pages of one section of mkdocs.yml's nav."""
    import yaml

    nav = yaml.safe_load((ROOT / "mkdocs.yml").read_text(encoding="utf-8"))["nav"]
    (entries,) = [item[section] for item in nav if isinstance(item, dict) and section in item]
    return [page for entry in entries for page in entry.values()]


@pytest.mark.parametrize("section", ["Tutorials", "How-to", "Reference"])
def test_the_home_page_and_the_readme_link_every_tutorial_how_to_and_reference_page(section):
    """The home page's "Where to go" lists every page of these sections (it had left out
    the instrument-file tutorial, the loads how-to and the JSON reference); the README
    every tutorial and how-to."""
    home = _text(DOCS / "index.md")
    assert [page for page in _nav_pages(section) if f"]({page})" not in home] == []
    if section != "Reference":  # the README names the generated reference pages by what they hold
        assert [page for page in _nav_pages(section) if f"](docs/{page})" not in _text(README)] == []


@pytest.mark.parametrize("page", ["README.md", "docs/getting-started.md"])
def test_every_extra_of_the_package_is_named_where_installing_is(page):
    """pyproject.toml's optional dependencies, each named as `".[extra]"` on the install
    pages (`bench`, Tamaas for the benchmarks, was named nowhere)."""
    import tomllib

    extras = tomllib.loads(_text(ROOT / "pyproject.toml"))["project"]["optional-dependencies"]
    assert [extra for extra in extras if f'".[{extra}]"' not in _text(ROOT / page)] == []
