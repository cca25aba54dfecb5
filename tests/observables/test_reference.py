"""What the hard-disk fluid is known to do: the equation of state against the exact virial
coefficients, Henderson against Kolafa & Rottner, Enskog's rate; and each refuses area fractions it
has no meaning at."""

import math

import pytest

from collision_env.observables import (
    KOLAFA_ROTTNER,
    enskog_rate,
    henderson_g,
    henderson_z,
    kolafa_rottner_z,
)


def test_enskog_rate_values():
    assert henderson_g(0.0) == 1.0
    assert henderson_g(0.5) == pytest.approx((1 - 7 / 32) / 0.25)
    # a 50-disk gas in a 2 m box: n = 50/4, sigma = 0.04, eta = 0.0157, kT = 0.5 -> 1.29 per s
    eta = 50 * math.pi * 0.02**2 / 4.0
    assert enskog_rate(50 / 4.0, 0.04, eta, 0.5, 1.0) == pytest.approx(1.29, abs=0.01)


def test_kolafa_rottner_reproduces_the_exact_virial_coefficients():
    # Z = 1 + 2 eta + 4 (B3/B2^2) eta^2 + 8 (B4/B2^3) eta^3 + ..., with the exact hard-disk
    # B3/B2^2 = 4/3 - sqrt(3)/pi and B4/B2^3 = 2 - 9 sqrt(3)/(2 pi) + 10/pi^2 (Clisby & McCoy 2006).
    # x = eta/(1 - eta) = eta + eta^2 + ..., so x^i holds eta^k with the weight binom(k - 1, i - 1).
    def eta_coefficient(k):
        return sum(c * math.comb(k - 1, i - 1) for i, c in KOLAFA_ROTTNER.items() if 1 <= i <= k)

    b3 = 4.0 / 3.0 - math.sqrt(3.0) / math.pi
    b4 = 2.0 - 4.5 * math.sqrt(3.0) / math.pi + 10.0 / math.pi**2
    assert eta_coefficient(1) == 2.0
    assert eta_coefficient(2) == pytest.approx(4 * b3, rel=1e-7)
    assert eta_coefficient(3) == pytest.approx(8 * b4, rel=1e-7)
    assert kolafa_rottner_z(0.0) == 1.0
    assert kolafa_rottner_z(0.3) == pytest.approx(sum(c * (0.3 / 0.7) ** i for i, c in KOLAFA_ROTTNER.items()))


def test_henderson_agrees_with_kolafa_rottner_where_it_should():
    assert henderson_z(0.5) == pytest.approx(1 + 2 * 0.5 * henderson_g(0.5))  # the contact theorem
    for eta in (0.1, 0.2, 0.3, 0.4, 0.5):
        assert henderson_z(eta) == pytest.approx(kolafa_rottner_z(eta), rel=5e-3)
    assert henderson_z(0.65) > 1.02 * kolafa_rottner_z(0.65)
    with pytest.raises(ValueError, match="where the fit holds"):
        kolafa_rottner_z(0.72)


@pytest.mark.parametrize("function", [henderson_g, henderson_z, kolafa_rottner_z])
@pytest.mark.parametrize("packing", [1.0, 2.0, -0.1, math.nan, math.pi / (2 * math.sqrt(3)), True, "0.3"])
def test_area_fractions_without_meaning_are_refused(function, packing):
    # issue 39: henderson_g divided by zero at 1 and returned a number at 2
    with pytest.raises(ValueError, match="packing"):
        function(packing)


def test_enskog_rate_refuses_bad_input():
    with pytest.raises(ValueError, match="kT"):
        enskog_rate(1.0, 1.0, 0.3, -1.0, 1.0)
    with pytest.raises(ValueError, match="density"):
        enskog_rate(math.nan, 1.0, 0.3, 1.0, 1.0)
    with pytest.raises(ValueError, match="packing"):
        enskog_rate(1.0, 1.0, 1.0, 1.0, 1.0)
