"""The event-chain benchmark: both methods on the dense state point, run short, agree on the pressure,
and the table says what was measured."""

import math

from collision_env.bench import chains as B


def test_a_short_run_of_both_methods_agrees_and_renders(monkeypatch):
    for name, value in [
        ("MELT_EVENTS", 1_000_000),
        ("CHAIN_EVENTS", 4_000_000),
        ("MD_FRAMES", 400),
        ("RATE_ROUNDS", 2),
        ("RATE_EVENTS", 200_000),
        ("RATE_FRAMES", 20),
        ("SCAN", (0.5, 2.0)),
        ("SCAN_EVENTS", 1_000_000),
        ("SETTLE_FRAMES", 5),
    ]:
        monkeypatch.setattr(B, name, value)
    results = B.run(quick=False, log=lambda *a: None)
    chains, md, speed = results["chains"], results["md"], results["rates"]
    # a dense fluid (Li et al. 2022, N = 224, phi = 0.68, square cell: Z = 9.807): both within their
    # errors of each other (a short run: the errors may be inf, then the looser bound holds)
    assert 9.6 < chains["z"] < 10.0 and 9.6 < md["z"] < 10.0
    assert abs(chains["z"] - md["z"]) < max(5 * math.hypot(chains["z_err"], md["z_err"]), 0.05) or math.isinf(
        chains["z_err"] + md["z_err"]
    )
    assert speed["liftings_per_s"] > 0 and speed["collisions_per_s"] > 0
    assert chains["cpu_seconds_to_target"] == chains["events_to_target"] / speed["liftings_per_s"]
    assert 40 < chains["liftings_per_chain"] < 80  # (about 4 sqrt(224) = 60)
    assert [row["factor"] for row in results["scan"]] == [0.5, 2.0]
    text = B.render_markdown(results)
    assert "| exact-mode MD |" in text and "| 0.5 |" in text and "10⁻⁴" in text
