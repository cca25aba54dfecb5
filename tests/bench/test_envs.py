"""The env benchmark runs end to end and writes its tables to its page (smoke test)."""

from collision_env.bench import envs as bench


def test_env_benchmark_writes_its_markdown_page(tmp_path, capsys):
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
        ]
    )
    table = md.read_text()
    assert "| `CollisionEnv/OneBallTarget-v0` | exact |" in table and "| `CartPole-v1` |" in table
