"""An optional package that is not installed is said with the pip command that brings it,
never as an internal error (exit 70): checked with the package hidden in a fresh process."""

import subprocess
import sys

import pytest

from frictionlab.errors import ExitCode, MissingDependency, require


def run_without(modules, argv, cwd):
    """``frictionlab ARGV`` in a fresh interpreter in which ``modules`` cannot be imported."""
    code = (
        "import sys\n"
        f"for name in {list(modules)!r}: sys.modules[name] = None  # import name -> ModuleNotFoundError\n"
        "from frictionlab.cli.main import main\n"
        f"sys.exit(main({list(argv)!r}))\n"
    )
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=cwd, timeout=120)


def test_the_dask_executor_without_dask_names_the_extra_not_a_bug(tmp_path):
    """The memory check asks Dask for its workers' limits before the executor starts: it says it too."""
    done = run_without(["dask", "distributed"], ["run", "quickstart", "--executor", "dask", "--out", "o"], tmp_path)
    assert done.returncode == ExitCode.USAGE, done.stderr
    assert 'pip install "frictionlab[dask]"' in done.stderr
    assert "internal error" not in done.stderr and "Traceback" not in done.stderr
    assert done.stderr.count("\n") == 1 and done.stdout == ""  # one line, and no run folder begun
    assert not (tmp_path / "o").exists()


def test_the_dask_executor_without_the_memory_check_says_it_too(tmp_path):
    done = run_without(["distributed"], ["run", "quickstart", "--executor", "dask", "--no-memory-check", "--quiet",
                                         "--out", "o"], tmp_path)  # fmt: skip
    assert done.returncode == ExitCode.USAGE and 'pip install "frictionlab[dask]"' in done.stderr, done.stderr


def test_the_dashboard_without_bokeh_is_refused_before_anything_starts(tmp_path):
    """Dask serves its dashboard's pages only with bokeh: without it --dashboard printed an address
    whose every page answered 404. The refusal names the extra that brings it."""
    done = run_without(["bokeh"], ["run", "quickstart", "--executor", "dask", "--dashboard", "--workers", "1",
                                   "--out", "o"], tmp_path)  # fmt: skip
    assert done.returncode == ExitCode.USAGE, done.stderr
    assert '--dashboard needs bokeh, which is not installed: pip install "frictionlab[dask]"' in done.stderr
    assert "Traceback" not in done.stderr and "Dask dashboard" not in done.stderr and not (tmp_path / "o").exists()


def test_a_missing_package_reached_anywhere_is_said_with_its_pip_command(tmp_path):
    """A command that imports an optional package without ``require`` still gets the message, not exit 70."""
    code = (
        "import sys\n"
        "sys.modules['pandas'] = None\n"
        "import frictionlab.cli.plugins as command\n"
        "def handler(args):\n"
        "    import pandas\n"
        "command.run = handler\n"
        "from frictionlab.cli.main import main\n"
        "sys.exit(main(['plugins']))\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path, timeout=60)
    assert done.returncode == ExitCode.USAGE, done.stderr
    assert 'frictionlab plugins needs pandas, which is not installed: pip install "frictionlab[pandas]"' in done.stderr


def test_a_missing_module_of_frictionlab_itself_stays_a_bug(monkeypatch, capsys):
    import frictionlab.cli.plugins
    from frictionlab.cli import main

    def broken(args):
        import frictionlab.no_such_module  # noqa: F401

    monkeypatch.setattr(frictionlab.cli.plugins, "run", broken)
    assert main(["plugins"]) == ExitCode.INTERNAL
    assert "internal error" in capsys.readouterr().err


@pytest.mark.parametrize(
    ("module", "command"),
    [("pandas", 'pip install "frictionlab[pandas]"'), ("distributed", 'pip install "frictionlab[dask]"'),
     ("bokeh", 'pip install "frictionlab[dask]"'),
     ("ipywidgets", 'pip install "frictionlab[notebook]"'), ("scipy", 'pip install "scipy>=1.11"'), ("yaml", 'pip install "pyyaml>=6.0"'),
     ("ruamel", 'pip install "ruamel.yaml>=0.18"'),
     ("not_a_dependency", "pip install . in frictionlab's clone (it installs frictionlab again with every dependency)")],
)  # fmt: skip
def test_require_names_the_extra_of_each_optional_package(monkeypatch, module, command):
    monkeypatch.setitem(sys.modules, module, None)
    with pytest.raises(MissingDependency) as caught:
        require(module, "this feature")
    assert str(caught.value) == f"this feature needs {module}, which is not installed: {command}"
    assert caught.value.exit_code == ExitCode.USAGE


def test_every_extra_named_is_one_pyproject_declares():
    import tomllib

    from frictionlab.errors import EXTRAS

    from ..conftest import ROOT

    declared = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["optional-dependencies"]
    assert set(EXTRAS.values()) <= set(declared)
    for module, extra in EXTRAS.items():  # the extra really brings the module
        assert any(line.lower().startswith(module.lower()) or f"[{module}" in line for line in declared[extra]), extra


def test_a_missing_matplotlib_keeps_the_numbers_and_says_how_to_mend_the_install(tmp_path):
    done = run_without(["matplotlib"], ["run", "quickstart", "--set", "realizations=4", "--workers", "1", "--quiet",
                                        "--out", "o"], tmp_path)  # fmt: skip
    assert done.returncode == ExitCode.RUNTIME_FAILURE, done.stderr
    assert "cannot draw" in done.stderr and "drawing needs matplotlib, which is not installed: pip install" in done.stderr
    assert "internal error" not in done.stderr
    assert (tmp_path / "o" / "summary.json").is_file() and (tmp_path / "o" / "curve.csv").is_file()


def test_a_missing_dependency_is_named_with_its_requirement_not_a_reinstall_from_an_index():
    """frictionlab is installed from its clone, not from an index: "pip install
    --force-reinstall frictionlab" finds no such distribution. Each dependency it declares is
    named with the requirement that brings it back."""
    from importlib.metadata import requires

    from frictionlab.errors import dependency_command

    declared = [req for req in requires("frictionlab") if "extra ==" not in req]
    modules = {"pyyaml>=6.0": "yaml", "ruamel.yaml>=0.18": "ruamel", "array-api-compat>=1.9": "array_api_compat"}
    for req in declared:
        module = modules.get(req, req.split(">=")[0])
        assert dependency_command(module) == f'pip install "{req}"'


@pytest.mark.parametrize("limited", [True, False])
def test_a_library_that_cannot_start_under_a_memory_limit_is_said_as_the_limit(tmp_path, limited):
    """Under ulimit -v 102400 pydantic's compiled core sometimes failed to start without saying
    why ('SystemError: error return without exception set' from the import): an internal error
    (exit 70). Under a process limit it is the limit, named with the package; without one it
    stays a bug."""
    package = tmp_path / "lib" / "site-packages" / "pydantic"
    package.mkdir(parents=True)
    (package / "__init__.py").write_text('raise SystemError("error return without exception set")\n')
    limit = "import resource; resource.setrlimit(resource.RLIMIT_AS, (1 << 45, resource.RLIM_INFINITY))\n"
    code = (
        f"{limit if limited else ''}import sys; sys.path.insert(0, {str(package.parent)!r})\n"
        "from frictionlab.cli.main import main\n"
        "sys.exit(main(['run', 'quickstart', '--no-plot', '--out', 'o']))\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path, timeout=120)
    if limited:
        assert done.returncode == ExitCode.RUNTIME_FAILURE, done.stderr
        assert done.stderr.startswith("error: out of memory loading pydantic; raise the process limit (ulimit -v is ")
        assert "internal error" not in done.stderr and "Traceback" not in done.stderr
    else:
        assert done.returncode == ExitCode.INTERNAL, done.stderr
        assert "internal error: SystemError: error return without exception set" in done.stderr


@pytest.mark.parametrize("failure", ["MemoryError()", "ImportError('the install seems to be broken') from "
                                     "ImportError('libfoo.so: failed to map segment from shared object')"],
                         ids=["memory-error", "import-error-raised-from-a-library-not-mapped"])  # fmt: skip
def test_a_library_that_runs_out_of_memory_as_it_loads_is_said_as_the_limit(tmp_path, failure):
    """Under ulimit -v 102400 an import that ran out of memory was said 'out of memory; ask for
    fewer points, realizations or workers' (of `validate`, `predict`: the program itself did
    not fit); scipy's 'install seems to be broken', raised from a library that could not be
    mapped, was an internal error (exit 70), or, reading an instrument file, 'not installed'."""
    package = tmp_path / "lib" / "site-packages" / "pydantic"
    package.mkdir(parents=True)
    (package / "__init__.py").write_text(f"raise {failure}\n")
    code = (
        "import resource; resource.setrlimit(resource.RLIMIT_AS, (1 << 45, resource.RLIM_INFINITY))\n"
        f"import sys; sys.path.insert(0, {str(package.parent)!r})\n"
        "from frictionlab.cli.main import main\n"
        "sys.exit(main(['run', 'quickstart', '--no-plot', '--out', 'o']))\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path, timeout=120)
    assert done.returncode == ExitCode.RUNTIME_FAILURE, done.stderr
    library = "pydantic" if failure == "MemoryError()" else "libfoo.so"
    assert done.stderr.startswith(f"error: out of memory loading {library}; raise the process limit (ulimit -v is "), done.stderr
    assert "fewer points" not in done.stderr and "internal error" not in done.stderr and "Traceback" not in done.stderr
