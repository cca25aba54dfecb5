"""The example scripts run."""

import importlib.util
import runpy
import sys
from pathlib import Path

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"


def test_the_hard_disk_tutorial_runs(tmp_path, capsys, monkeypatch):
    plot = tmp_path / "hard_disks.png"
    monkeypatch.setattr(
        sys,
        "argv",
        [
            "hard_disks.py",
            *("--n", "256", "--packing", "0.3", "--aspect", "0.866", "--blocks", "4"),
            *("--jam-n", "128", "--rate", "0.1", "--gsd", str(tmp_path / "run.gsd"), "--plot", str(plot)),
        ],
    )
    runpy.run_path(str(EXAMPLES / "hard_disks.py"), run_name="__main__")
    out = capsys.readouterr().out
    assert "Z = PA/NkT" in out and "g(r) peaks at r = 1.0" in out
    assert "jammed at area fraction 0.8" in out
    assert plot.stat().st_size > 0
    if all(importlib.util.find_spec(m) for m in ("freud", "gsd")):
        assert "hexatic order |Psi6|" in out and (tmp_path / "run.gsd").stat().st_size > 0
