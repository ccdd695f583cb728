"""An instrument file whose header declares a map its heights do not fill (an X3P of
128 x 10^9 points with 320 points stored) is a damaged file, named as one: the memory
estimate took the header's shape on trust and refused the run as too large (exit 1, 'this
run would need about 11444 GiB'), never saying the file was damaged."""

from __future__ import annotations

import re

import pytest
import yaml

from frictionlab.cli import main
from frictionlab.errors import ExitCode

from .test_scan_edge_cases import rewritten_x3p, rough


@pytest.mark.parametrize("command", ["validate", "run"])
def test_an_x3p_declaring_far_more_points_than_it_holds_is_named_damaged(tmp_path, capsys, command):
    import x3pio

    x3pio.write(tmp_path / "good.x3p", rough(16, 20) * 1e-6, x_scale=1e-7, y_scale=1e-7,
                revision=x3pio.Revision.ISO5436_2000)  # fmt: skip
    rewritten_x3p(tmp_path / "good.x3p", tmp_path / "forged.x3p",
                  xml=lambda text: re.sub(rb"<SizeX>\d+</SizeX>", b"<SizeX>1000000000</SizeX>", text))  # fmt: skip
    preset = {"name": "forged", "realizations": 1, "spectrum": {"name": "surface-file", "params": {"path": "forged.x3p"}},
              "solver": {"name": "mdr"}, "loading": {"start": 0.01, "stop": 0.1, "steps": 3, "unit": "f"}}  # fmt: skip
    (tmp_path / "p.yaml").write_text(yaml.safe_dump(preset))
    code = main([command, str(tmp_path / "p.yaml"), *(["--out", str(tmp_path / "out")] if command == "run" else [])])
    err = capsys.readouterr().err
    assert code == ExitCode.USAGE, err
    assert "a damaged XML 3D surface profile (X3P) file: its binary heights take" in err
    assert "declares 16000000000 points" in err and "would need about" not in err
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize(("kind", "command"), [("surface-file", "validate"), ("surface-file", "run"),
                                               ("profile-file", "validate")])  # fmt: skip
def test_a_gwyddion_file_declaring_far_more_points_than_its_bytes_is_named_damaged(tmp_path, capsys, kind, command):
    """A Gwyddion file of 2 KiB whose header declares 10^8 x 16 points: the memory estimate
    refused it ('this run would need about 143 GiB', exit 1), or the reader's check ('reading
    them takes about 47.7 GiB'), never saying the file was damaged."""
    from .test_scan_edge_cases import write_gwy

    write_gwy(tmp_path / "forged.gwy", rough(16, 16) * 1e-9, 1e-9, 1e-9, xres=10**8, xreal=0.1)
    size = (tmp_path / "forged.gwy").stat().st_size
    preset = {"name": "forged", "realizations": 1, "spectrum": {"name": kind, "params": {"path": "forged.gwy"}},
              "solver": {"name": "mdr"}, "loading": {"start": 0.01, "stop": 0.1, "steps": 3, "unit": "f"}}  # fmt: skip
    (tmp_path / "p.yaml").write_text(yaml.safe_dump(preset))
    code = main([command, str(tmp_path / "p.yaml"), *(["--out", str(tmp_path / "out")] if command == "run" else [])])
    err = capsys.readouterr().err
    assert code == ExitCode.USAGE, err
    assert (f"a damaged or truncated Gwyddion file: its header declares 100000000 x 16 points (x by y), and the file "
            f"has {size:,} bytes, too few to hold them even compressed") in err  # fmt: skip
    assert "GiB" not in err and "Traceback" not in err and not (tmp_path / "out").exists()
