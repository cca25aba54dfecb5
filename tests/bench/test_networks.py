"""The contact-network benchmark runs end to end on its quick scenes and writes its page."""

from __future__ import annotations

import json

from collision_env.bench import networks


def test_quick_run_writes_every_row_and_the_struck_rows_reach_every_step_end(tmp_path):
    page, raw = tmp_path / "networks.md", tmp_path / "networks.json"
    assert networks.main(["--quick", "--json", str(raw), "--markdown", str(page)]) == 0
    rows = json.loads(raw.read_text())
    for where in ("box", "cell"):
        for e in ("0", "0.5"):
            row = rows[f"row e={e} {where}"]
            assert row["balls"] == 1001 and row["steps_reaching_their_end"] == row["steps"]
            assert abs(row["clock_s"] - row["steps"] * networks.FRAME) < 1e-9
    assert {"pile e=0", "pile e=0.5", "heap e=0", "heap e=0.5"} <= rows.keys()
    text = page.read_text()
    assert text.startswith("# Contact networks at e < 1\n")
    assert all(f"| {name} |" in text for name in rows)
