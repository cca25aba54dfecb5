"""The contact-network benchmark runs end to end on its quick scenes and writes its page."""

from __future__ import annotations

import json

from collision_env.bench import networks


def test_quick_run_writes_every_row_and_the_struck_rows_reach_every_step_end(tmp_path):
    page, raw = tmp_path / "networks.md", tmp_path / "networks.json"
    assert networks.main(["--quick", "--json", str(raw), "--markdown", str(page)]) == 0
    raw_rows = json.loads(raw.read_text())
    rows, gases = raw_rows["networks"], raw_rows["granular"]
    for where in ("box", "cell"):
        for e in ("0", "0.5"):
            row = rows[f"row e={e} {where}"]
            assert row["balls"] == 1001 and row["steps_reaching_their_end"] == row["steps"]
            assert abs(row["clock_s"] - row["steps"] * networks.FRAME) < 1e-9
    assert {"pile e=0", "pile e=0.5", "heap e=0", "heap e=0.5"} <= rows.keys()
    # the same dense flows under the TC model: every one gets through every step, gaining no energy
    tc_rows = [name for name in rows if name.endswith(" TC")]
    assert len(tc_rows) == 10
    for name in tc_rows:
        assert rows[name]["contact_duration_s"] > 0.0 and rows[name[: -len(" TC")]]["contact_duration_s"] == 0.0
        assert rows[name]["energy_gain"] <= 1e-12
        assert rows[name]["steps_reaching_their_end"] == rows[name]["steps"]
    text = page.read_text()
    assert text.startswith("# Contact networks at e < 1\n")
    assert all(f"| {name} |" in text for name in rows)
    # the granular gas beside the elastic one: the same number of disks, events counted, a ratio
    assert set(gases) == {"1000 disks box", "1000 disks cell"}
    for gas in gases.values():
        assert gas["events_inelastic"] > 0
        assert gas["ratio"] == gas["us_per_event_inelastic"] / gas["us_per_event_elastic"]
        assert f"| {gas['events_inelastic']} |" in text
