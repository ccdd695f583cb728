"""A signal that lands while ``frictionlab study`` writes its files: they are all written,
the command ends as interrupted, and the folder is taken again as the study's."""

import os
import signal

from frictionlab.cli import main
from frictionlab.errors import ExitCode
from frictionlab.tradeoff import outputs

from ..conftest import PRESETS

SMALL = ["--axes", "realizations", "--set", "realizations=4", "--set", "spectrum.params.points=512", "--quiet"]


def test_a_ctrl_c_among_the_study_s_writes_leaves_every_file_and_a_folder_taken_again(tmp_path, monkeypatch, capsys):
    """A Ctrl-C after study.csv and before study.md left study.csv alone and the bare word
    'interrupted'; the same study into that folder was then refused as 'not a study of quickstart'."""
    written = outputs.write_outputs
    writes = []

    def interrupted_between(study, out_dir, text, command=""):
        real_csv = outputs.write_csv

        def csv_then_ctrl_c(fh, rows):
            real_csv(fh, rows)
            os.kill(os.getpid(), signal.SIGINT)  # lands before study.md is written

        monkeypatch.setattr(outputs, "write_csv", csv_then_ctrl_c)
        try:
            writes.append(written(study, out_dir, text, command))
        finally:
            monkeypatch.setattr(outputs, "write_csv", real_csv)
        return writes[-1]

    monkeypatch.setattr(outputs, "write_outputs", interrupted_between)
    out = tmp_path / "study"
    code = main(["study", str(PRESETS / "quickstart.yaml"), "--out", str(out), *SMALL])
    err = capsys.readouterr().err
    assert writes and code == ExitCode.INTERRUPTED
    assert {"study.csv", "study.md"} <= {p.name for p in out.iterdir()}
    assert "interrupted: the files hold the axes finished" in err
    monkeypatch.setattr(outputs, "write_outputs", written)
    assert main(["study", str(PRESETS / "quickstart.yaml"), "--out", str(out), *SMALL]) == ExitCode.OK
