"""Shell completion made from the parser, checked by completing in real shells: bash
always (the function driven through COMP_WORDS in an interactive bash), zsh and fish
when installed."""

from __future__ import annotations

import argparse
import re
import shlex
import shutil
import subprocess

import pytest

from frictionlab.cli.completion import command_specs, settable_paths
from frictionlab.cli.main import COMMANDS, build_parser
from frictionlab.options import EXECUTORS
from frictionlab.preset import preset_json_schema, set_path
from frictionlab.preset.builtin import builtin_presets

from ..conftest import SMALL_PRESET, merge, run_cli


ANSI = re.compile(r"\x1b\[[0-9;?]*[A-Za-z]")
NAMES = [command.__name__.rsplit(".", 1)[-1] for command in COMMANDS]
BUILTINS = {p.name for p in builtin_presets()}
needs_bash = pytest.mark.skipif(shutil.which("bash") is None, reason="bash is not installed")


@pytest.fixture(scope="module")
def bash_script(tmp_path_factory):
    script = tmp_path_factory.mktemp("completion") / "frictionlab.bash"
    script.write_text(run_cli("completion", "bash").stdout)
    return script


def bash_complete(script, *words: str, cwd=None) -> list[str]:
    """The candidates bash's completion function offers for the last of ``words`` (as typed,
    split as bash splits a line: ``--out=DIR`` is three words)."""
    line = " ".join(shlex.quote(w) for w in words)
    code = (f"source {shlex.quote(str(script))}\ncomplete -p frictionlab >/dev/null || exit 9\n"
            f"COMP_WORDS=({line})\nCOMP_CWORD={len(words) - 1}\n_frictionlab\nprintf '%s\\n' \"${{COMPREPLY[@]}}\"")  # fmt: skip
    done = subprocess.run(["bash", "--norc", "-i", "-c", code], capture_output=True, text=True, timeout=30, cwd=cwd,
                          stdin=subprocess.DEVNULL)  # fmt: skip
    assert done.returncode == 0, done.stderr
    return done.stdout.split()


@needs_bash
def test_bash_completes_commands_and_options_once_each(bash_script):
    assert set(bash_complete(bash_script, "frictionlab", "re")) == {"resume", "report"}
    assert set(bash_complete(bash_script, "frictionlab", "")) == set(NAMES)
    assert "--no-plot" in bash_complete(bash_script, "frictionlab", "run", "--no")
    options = bash_complete(bash_script, "frictionlab", "run", "quickstart", "--")
    assert options.count("--help") == 1 and len(options) == len(set(options))
    run = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction)).choices["run"]
    assert set(options) == {o for a in run._actions for o in a.option_strings if o.startswith("--")}


@needs_bash
@pytest.mark.parametrize("before", [["run"], ["run", "quickstart"], ["resume", "runs/x", "--quiet"]])
def test_bash_offers_exactly_the_executors_after_executor(bash_script, tmp_path, before):
    (tmp_path / "serial-notes.yaml").write_text("")  # a file that would be offered by a file completion
    assert bash_complete(bash_script, "frictionlab", *before, "--executor", "", cwd=tmp_path) == list(EXECUTORS)
    assert bash_complete(bash_script, "frictionlab", *before, "--executor", "pr", cwd=tmp_path) == ["processes"]


@needs_bash
def test_bash_offers_builtin_and_local_presets_where_a_preset_goes(bash_script, tmp_path):
    (tmp_path / "my.yaml").write_text("")
    (tmp_path / "notes.txt").write_text("")
    (tmp_path / "presets").mkdir()
    offered = set(bash_complete(bash_script, "frictionlab", "run", "", cwd=tmp_path))
    assert offered == BUILTINS | {"my.yaml", "presets"}  # a folder on the way to a preset, not notes.txt
    assert bash_complete(bash_script, "frictionlab", "run", "qu", cwd=tmp_path) == ["quickstart"]
    assert set(bash_complete(bash_script, "frictionlab", "validate", "quickstart", "m", cwd=tmp_path)) == {
        "my.yaml", "mdr-vs-halfspace"}  # every word of validate's PRESET...
    assert set(bash_complete(bash_script, "frictionlab", "presets", "copy", "bena")) == {n for n in BUILTINS if n.startswith("bena")}


@needs_bash
def test_bash_offers_what_presets_takes_and_nothing_it_refuses(bash_script):
    assert bash_complete(bash_script, "frictionlab", "presets", "") == ["copy"]
    assert bash_complete(bash_script, "frictionlab", "completion", "f") == ["fish"]


@needs_bash
def test_bash_offers_files_and_folders_where_they_are_expected(bash_script, tmp_path):
    (tmp_path / "ca.pem").write_text("")
    (tmp_path / "cluster").mkdir()
    assert set(bash_complete(bash_script, "frictionlab", "run", "quickstart", "--tls-ca-file", "", cwd=tmp_path)) == {
        "ca.pem", "cluster"}  # fmt: skip
    assert bash_complete(bash_script, "frictionlab", "run", "quickstart", "--out", "", cwd=tmp_path) == ["cluster"]
    assert bash_complete(bash_script, "frictionlab", "run", "quickstart", "--out", "=", "", cwd=tmp_path) == ["cluster"]
    assert bash_complete(bash_script, "frictionlab", "run", "quickstart", "--workers", "", cwd=tmp_path) == []
    assert bash_complete(bash_script, "frictionlab", "predict", "--a-ci", "1", "2", "--fr") == ["--from"]


@needs_bash
def test_bash_completes_set_paths_from_the_schema(bash_script):
    assert bash_complete(bash_script, "frictionlab", "run", "quickstart", "--set", "spectrum.params.hu") == [
        "spectrum.params.hurst="]  # fmt: skip
    assert bash_complete(bash_script, "frictionlab", "run", "quickstart", "--set", "spectrum.params.hurst", "=", "") == []
    after = bash_complete(bash_script, "frictionlab", "run", "quickstart", "--set", "seed", "=", "3", "--wo")
    assert after == ["--workers"]  # the value after "=" is not taken for a positional


def test_every_settable_path_is_one_set_accepts_and_a_plugins_parameter_is_there():
    paths = settable_paths(preset_json_schema())
    assert {"seed", "realizations", "loading.steps", "spectrum.params.hurst", "solver.params.youngs_modulus"} <= set(paths)
    assert "sweep" not in paths and not any(p.endswith(".") for p in paths)
    for path in paths:  # each names a field a preset has: setting it is no "not a known field"
        data = merge(SMALL_PRESET, {})
        set_path(data, path, "1")
        node = data
        for part in path.split("."):
            node = node[part]
        assert node == "1", path


def test_the_parser_walk_finds_every_command_and_its_value_kinds():
    specs = {c.path: c for c in command_specs(build_parser())}
    assert set(NAMES) <= set(specs) and "presets copy" in specs
    assert specs["run"].options["--executor"].words == tuple(EXECUTORS)
    assert specs["run"].options["--out"].kind == "dirs" and specs["schema"].options["--out"].kind == "files"
    assert specs["run"].options["--set"].kind == "settings" and specs["run"].positionals[0].kind == "presets"
    assert specs["validate"].positionals[0].repeats and specs["presets copy"].positionals[0].kind == "builtins"
    assert specs["predict"].options["--a-ci"].count == 2 and specs["run"].options["--quiet"].count == 0


ZSH_TAB = r"""
zmodload zsh/zpty
zpty shell 'zsh -f -i'
zpty -w shell "PS1='> '; autoload -U compinit && compinit -u -D; source ${(q)1}"
zpty -n -w shell "$2"$'\t'
local out="" chunk
integer quiet=0 i
for i in {1..200}; do  # read until a second of silence after the completion, at most 20 s
  if zpty -r -t shell chunk; then out+=$chunk; quiet=0; else sleep 0.1; (( quiet++ )); fi
  [[ $out == *$'\a'* || $out == *"$2"?* ]] && (( quiet >= 10 )) && break
done
zpty -d shell
print -r -- "$out"
"""


def zsh_tab(script, line: str) -> str:
    """What an interactive zsh shows after ``line`` and one TAB, the script loaded
    as its completion: the completed line, or the listed candidates."""
    done = subprocess.run(["zsh", "-f", "-c", ZSH_TAB, "zsh", str(script), line], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    return ANSI.sub("", done.stdout).replace("\r", "\n")


@pytest.mark.skipif(shutil.which("zsh") is None, reason="zsh is not installed (the script is still checked as text below)")
def test_zsh_completion_by_tab_in_an_interactive_zsh(tmp_path, cli):
    script = tmp_path / "_frictionlab"
    script.write_text(cli("completion", "zsh").stdout)
    listed = zsh_tab(script, "frictionlab re")
    assert "report" in listed and "resume" in listed and "validate" not in listed
    assert "frictionlab run quickstart" in zsh_tab(script, "frictionlab run qu")
    assert "frictionlab completion fish" in zsh_tab(script, "frictionlab completion f")
    assert "frictionlab presets copy benad2012-fig" in zsh_tab(script, "frictionlab presets copy bena")
    assert "frictionlab run quickstart --executor processes" in zsh_tab(script, "frictionlab run quickstart --executor pr")


@pytest.mark.skipif(shutil.which("fish") is None, reason="fish is not installed (the script is still checked as text below)")
def test_fish_completion_in_a_real_fish(tmp_path, cli):
    script = tmp_path / "frictionlab.fish"
    script.write_text(cli("completion", "fish").stdout)

    def complete(line: str) -> list[str]:
        code = f"source {shlex.quote(str(script))}; complete -C {shlex.quote(line)}"
        done = subprocess.run(["fish", "--no-config", "-c", code], capture_output=True, text=True, timeout=30,
                              cwd=tmp_path)  # fmt: skip
        assert done.returncode == 0, done.stderr
        return [row.split("\t")[0] for row in done.stdout.splitlines()]

    (tmp_path / "my.yaml").write_text("")
    (tmp_path / "notes.txt").write_text("")
    (tmp_path / "presets").mkdir()
    assert set(complete("frictionlab run ")) == BUILTINS | {"my.yaml", "presets/"}  # not notes.txt
    assert set(complete("frictionlab run quickstart --tls-cert ")) >= {"my.yaml", "notes.txt"}
    assert complete("frictionlab run quickstart --set spectrum.params.hu") == ["spectrum.params.hurst="]

    assert set(complete("frictionlab re")) == {"report", "resume"}
    assert "--no-plot" in complete("frictionlab run --no")
    assert complete("frictionlab completion f") == ["fish"]
    assert "quickstart" in complete("frictionlab run qu")
    assert "benad2012-fig2" in complete("frictionlab presets copy bena")
    assert sorted(complete("frictionlab run quickstart --executor ")) == sorted(EXECUTORS)  # fish sorts them
    assert complete("frictionlab presets ") == ["copy"]


def test_zsh_and_fish_scripts_are_made_from_the_same_walk(cli):
    zsh = cli("completion", "zsh").stdout
    assert zsh.startswith("#compdef frictionlab\n") and "bashcompinit" in zsh and "complete -F _frictionlab frictionlab" in zsh
    fish = cli("completion", "fish").stdout
    for name in NAMES:
        assert f"-n __fish_use_subcommand -a {name} " in fish
    assert "-n '__fish_seen_subcommand_from run' -l no-plot\n" in fish
    assert f"-n '__fish_seen_subcommand_from run' -l executor -r -x -a '{' '.join(EXECUTORS)}'\n" in fish
    assert "spectrum.params.hurst=" in fish
    helps = [line.split(" -n ")[1] for line in fish.splitlines() if line.endswith(" -l help")]
    assert len(helps) == 2 and helps[0].startswith("__fish_use_subcommand ")  # once at the top, once after a command
    assert helps[1].startswith("'not __fish_use_subcommand; and __fish_seen_subcommand_from run ")
    if shutil.which("fish"):
        done = subprocess.run(["fish", "--no-execute"], input=fish, capture_output=True, text=True, timeout=30)
        assert done.returncode == 0, done.stderr
