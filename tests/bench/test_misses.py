"""The cache-miss count: its cache model, its traced arrays, and a small gas counted end to end."""

from __future__ import annotations

import json

import numpy as np

from collision_env.bench import misses


def test_the_cache_keeps_the_most_recently_used_lines():
    cache = misses.LineCache(2)
    cache.counting = True
    for line in (1, 2, 1, 3, 2, 1):  # 3 evicts 2 (1 was used since), then 2 evicts 1, then 1 evicts 3
        cache.touch(line, "a")
    assert cache.misses == {"a": 5}
    assert list(cache.held) == [2, 1]


def test_a_traced_array_reports_the_line_of_each_element_it_is_indexed_at():
    cache = misses.LineCache(100)
    cache.counting = True
    rows = np.zeros((4, 16)).view(misses.TracedArray)  # rows of 128 bytes (numpy aligns them to 16)
    rows.tag, rows.cache = "rows", cache
    rows[1, 0] = 1.0
    rows[1, 8] = 2.0
    _ = rows[1, 9]  # 8 bytes on: the line just fetched
    _ = rows[2]  # a row: its first line
    _ = rows[:, 0]  # a slice: a view, nothing read yet
    assert cache.misses == {"rows": 3}
    assert set(cache.held) == {(rows.address + offset) // misses.LINE for offset in (128, 192, 256)}


def test_a_small_gas_misses_nothing_in_a_large_cache_and_its_records_in_a_tiny_one(tmp_path):
    """(``main`` counts in a fresh interpreter on the Python path, since numba is on here.)"""
    out = tmp_path / "misses.json"
    for kib in (2048, 4):
        assert misses.main(["--sizes", "200", "--cache-kib", str(kib), "--json", str(out)]) == 0
        (row,) = json.loads(out.read_text())
        assert row["n"] == 200 and row["events"] > 50
        if kib == 2048:  # every array fits, and every line was fetched before the count
            assert row["misses_per_event"] == {}
        else:
            assert row["misses_per_event"]["cal_rec"] > 1.0
