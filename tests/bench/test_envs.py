"""The env benchmark runs end to end and writes its tables into the README block (smoke test)."""

from collision_env.bench import envs as bench
from collision_env.bench.readme import markers


def test_env_benchmark_writes_markdown_and_readme_block(tmp_path, capsys):
    start, end = markers("bench:envs")
    readme = tmp_path / "README.md"
    readme.write_text(f"before\n{start}\nold\n{end}\nafter\n")
    md = tmp_path / "envs.md"
    bench.main(
        [
            "--seconds",
            "0.05",
            "--num-envs",
            "4",
            "--ids",
            "CollisionEnv/OneBallTarget-v0",
            "--markdown",
            str(md),
            "--readme",
            str(readme),
        ]
    )
    table = md.read_text()
    assert "| `CollisionEnv/OneBallTarget-v0` | exact |" in table and "| `CartPole-v1` |" in table
    text = readme.read_text()
    assert text.startswith(f"before\n{start}\n") and text.endswith(f"{end}\nafter\n")
    assert table.strip() in text and "old" not in text
