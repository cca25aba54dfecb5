"""The hard-disk benchmark: a small periodic fluid against the reference equation of state, small
packings compressed to jamming."""

import math

import pytest

from collision_env.bench import physics as P
from collision_env.observables import kolafa_rottner_z


def test_enskog_from_z_is_the_contact_theorem_rate():
    # omega = 2 sqrt(pi) rho sigma g sqrt(kT/m), with Z = 1 + 2 eta g and rho = 4 eta / (pi sigma^2)
    eta = 0.4
    z = kolafa_rottner_z(eta)
    g = (z - 1) / (2 * eta)
    rho = 4 * eta / math.pi
    assert P.enskog_from_z(z) == pytest.approx(2 * math.sqrt(math.pi) * rho * g)


def test_a_small_fluid_meets_the_equation_of_state(monkeypatch):
    monkeypatch.setattr(P, "MELT_COLLISIONS", 200.0)
    monkeypatch.setattr(P, "BLOCK_COLLISIONS", 100.0)
    (row,) = P.equation_of_state(400, packings=(0.3,), log=lambda *a: None)
    # 400 disks: within a few standard errors and a finite-size share of the reference
    assert abs(row["z"] - row["z_kolafa_rottner"]) <= 5 * row["z_err"] + 0.01 * row["z_kolafa_rottner"]
    assert row["omega"] / row["omega_enskog"] == pytest.approx(1.0, abs=0.03)
    results = {
        "machine": "m",
        "cpus": 2,
        "versions": {"numpy": "x", "numba": "y"},
        "timestamp": "t",
        "seconds": 1.0,
        "n": 400,
        "equation_of_state": [row],
        "speed": [{"packing": 0.3, "events": 10, "events_per_s": 1e6}],
        "jamming": P.jamming(((128, 0.1, 2),), log=lambda *a: None),
    }
    text = P.render_markdown(results)
    assert "| 0.30 |" in text and "Kolafa" in text
    # two small packings jammed near O'Hern et al.'s density, summarised in one row
    (summary,) = P.jamming_summary(results["jamming"])
    assert summary["seeds"] == 2 and summary["all_jammed"]
    assert 0.80 < summary["phi_j"] < 0.87 and summary["phi_j_sd"] > 0.0
    assert f"| 128 | 0.1 | 2 | {summary['phi_j']:.4f}" in text
