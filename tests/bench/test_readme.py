"""The README's generated blocks are rewritten only between their own markers, and every report
script's output tail (printed table, JSON, page or block) is the one helper."""

import json

from collision_env.bench.readme import markers, replace_block, write_outputs


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


def test_the_output_tail_prints_the_table_and_writes_json_and_a_titled_page(tmp_path, capsys):
    out, page = tmp_path / "raw.json", tmp_path / "page.md"
    write_outputs("| a |\n|---|\n", {"x": [1, 2]}, json_path=out, markdown=page, title="# Title", indent=2)
    assert capsys.readouterr().out == "| a |\n|---|\n\n"
    assert json.loads(out.read_text()) == {"x": [1, 2]} and out.read_text() == '{\n  "x": [\n    1,\n    2\n  ]\n}\n'
    assert page.read_text() == "# Title\n\n| a |\n|---|\n"  # one final newline, whatever the text ends with
    write_outputs("plain", markdown=page)
    assert page.read_text() == "plain\n"


def test_the_output_tail_writes_only_what_it_is_given(tmp_path, capsys):
    out = tmp_path / "raw.json"
    write_outputs("text", None, json_path=out, echo=False)  # no results (a rendered run): no JSON
    assert not out.exists() and capsys.readouterr().out == ""


def test_the_output_tail_fills_a_block_and_leaves_a_page_without_markers_alone(tmp_path, capsys):
    start, end = markers("agents:rllib")
    page = tmp_path / "agents.md"
    page.write_text(f"# Agents\n{start}\nold\n{end}\n")
    write_outputs("new", markdown=page, block="agents:rllib", echo=False)
    assert page.read_text() == f"# Agents\n{start}\nnew\n{end}\n"
    bare = tmp_path / "bare.md"
    bare.write_text("nothing here\n")
    write_outputs("new", markdown=bare, block="agents:rllib", echo=False)
    assert bare.read_text() == "nothing here\n" and "left unchanged" in capsys.readouterr().out


def test_the_output_tail_with_a_title_adds_a_missing_block_or_makes_the_page(tmp_path):
    page = tmp_path / "physics.md"
    write_outputs("fluid", markdown=page, block="bench:physics", title="# Physics", echo=False)
    write_outputs("li", markdown=page, block="bench:literature", title="# Physics", echo=False)
    write_outputs("fluid 2", markdown=page, block="bench:physics", title="# Physics", echo=False)
    (p0, p1), (l0, l1) = markers("bench:physics"), markers("bench:literature")
    assert page.read_text() == f"# Physics\n\n{p0}\nfluid 2\n{p1}\n\n{l0}\nli\n{l1}\n"
