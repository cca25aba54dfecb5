"""The README's generated blocks are rewritten only between their own markers."""

from collision_env.bench.readme import markers, replace_block


def test_block_replaced_only_between_its_markers(tmp_path):
    start, end = markers("bench:study")
    other_start, other_end = markers("agents:study")
    readme = tmp_path / "README.md"
    readme.write_text(f"intro\n{start}\nold\n{end}\nmiddle\n{other_start}\nkeep\n{other_end}\noutro\n")
    assert replace_block(readme, "bench:study", "new table\n")
    assert readme.read_text() == f"intro\n{start}\nnew table\n{end}\nmiddle\n{other_start}\nkeep\n{other_end}\noutro\n"


def test_missing_markers_leave_the_file_unchanged(tmp_path):
    plain = tmp_path / "plain.md"
    plain.write_text("no markers\n")
    assert not replace_block(plain, "bench:study", "x")
    assert plain.read_text() == "no markers\n"
