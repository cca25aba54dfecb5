"""The peer comparison (bench.peer) on a small gas: this engine's probe, the peer's output parsed, the table."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from collision_env.bench import peer


def test_the_slices_hold_the_collisions_asked_for_at_enskogs_rate():
    # 2 sqrt(pi) n g(sigma) at phi = 0.3: 2.40 collisions per disk per unit time (the peer's own 2.398)
    assert peer.collision_rate(0.3) == pytest.approx(2.40, abs=0.01)
    n = 1000
    assert 0.5 * n * peer.collision_rate(0.7) * peer.slice_time(n, 0.7) == pytest.approx(peer.SLICE_COLLISIONS)


def test_this_engines_probe_times_collisions_at_the_fluids_rate(monkeypatch):
    monkeypatch.setattr(peer, "SLICE_COLLISIONS", 20_000)
    root = Path(peer.__file__).resolve().parents[2]
    got = peer.run_ours(400, 0.3, root)
    assert got["us_per_collision"] > 0.0 and math.isfinite(got["us_per_collision"])
    # the melted fluid collides at Enskog's rate within the finite size's few per cent
    assert got["collision_rate"] == pytest.approx(peer.collision_rate(0.3), rel=0.1)
    assert 0.0 < got["bytes_per_disk"] < 1e5


def test_the_peers_result_line_is_read_and_the_table_rendered(tmp_path):
    line = (
        "RESULT N=1000 packfrac=0.3 shell=2.5 init_s=0.000 timed_simtime=750.001 collisions=899239 steps=1882663 "
        "wall_s=1.4467 coll_per_s=6.216e+05 us_per_coll=1.6088 best_slice_cpu_us_per_coll=0.7436 us_per_step=0.7684 "
        "coll_per_particle_per_time=2.3980 sizeof_particle=368 maxrss_kB=2324 rss_bytes_per_particle=2379.8"
    )
    fake = tmp_path / "md2d"
    fake.write_text(f"#!/bin/sh\necho Starting\necho '{line}'\n")
    fake.chmod(0o755)
    got = peer.run_peer(fake, 1000, 0.3)
    assert got == {"us_per_collision": 0.7436, "collision_rate": 2.398, "bytes_per_disk": 2379.8}
    ours = {"us_per_collision": 0.5, "collision_rate": 2.4, "bytes_per_disk": 300.0, "build_bytes_per_disk": 400.0}
    row = {"n": 1000, "phi": 0.3, "peer": got, "ours": {**ours, "rounds": [0.5]}, "speedup": 0.7436 / 0.5}
    result = {"rows": [row], "peer": "p", "rounds": 1, "machine": "m", "timestamp": "t"}
    text = peer.render_markdown(result)
    assert "| 1,000 | 0.3 | 0.744 | 0.500 | **1.49x** | 2380 | 300 | 400 |" in text
    json.dumps(result)


def test_without_the_peers_source_there_is_no_peer(tmp_path):
    assert peer.build_peer(tmp_path / "missing", tmp_path) is None
