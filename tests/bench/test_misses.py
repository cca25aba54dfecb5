"""The cache-miss count: its cache model, its traced arrays, and a small gas counted end to end."""

from __future__ import annotations

import json

import numpy as np
import pytest

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


def test_records_report_every_line_they_span_and_indices_count_as_numpy_counts_them():
    cache = misses.LineCache(100)
    cache.counting = True
    buffer = np.zeros(4 * 64 + 64, dtype=np.uint8)
    start = -buffer.ctypes.data % 64 + 16  # records of 64 bytes that start 16 bytes into a line
    record = np.dtype([(f"f{k}", np.float64) for k in range(8)])
    records = buffer[start : start + 3 * 64].view(record).view(misses.TracedArray)
    records.tag, records.cache = "records", cache
    _ = records[1]  # a record: both lines it spans
    line = (records.address + 64) // misses.LINE
    assert set(cache.held) == {line, line + 1}
    grid = np.zeros((5, 8)).view(misses.TracedArray)  # rows of one line's width
    grid.tag, grid.cache = "grid", cache
    column = grid[:, 3]
    grid[-1, 0] = 1.0  # the last row
    _ = column[2]  # a strided view: row 2, column 3
    assert {(grid.address + offset) // misses.LINE for offset in (4 * 64, 2 * 64 + 3 * 8)} <= set(cache.held)
    assert cache.misses == {"records": 2, "grid": 2}


def test_a_small_gas_misses_nothing_in_a_large_cache_and_its_records_in_a_tiny_one(tmp_path):
    """(``main`` counts in a fresh interpreter on the Python path, since numba is on here.) The
    tiny cache's count is also split by source line, every line of it: the lines add up to the
    arrays' counts, and the neighbour test of a prediction reads records."""
    out = tmp_path / "misses.json"
    for kib in (2048, 4):
        assert misses.main(["--sizes", "200", "--cache-kib", str(kib), "--sites", "1000", "--json", str(out)]) == 0
        (row,) = json.loads(out.read_text())
        assert row["n"] == 200 and row["events"] > 50
        if kib == 2048:  # every array fits, and every line was fetched before the count
            assert row["misses_per_event"] == {} and row["sites"] == []
        else:
            assert row["misses_per_event"]["rec"] > 1.0
            by_array = {}
            for site in row["sites"]:
                by_array[site["array"]] = by_array.get(site["array"], 0.0) + site["per_event"]
            assert by_array == pytest.approx(row["misses_per_event"])
            assert any(s["array"] == "rec" and s["site"].startswith("scheduler._partner_event:") for s in row["sites"])
