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
    # (on d8ab1a0 henderson_g divided by zero at 1 and returned a number at 2)
    with pytest.raises(ValueError, match="packing"):
        function(packing)


def test_enskog_rate_refuses_bad_input():
    with pytest.raises(ValueError, match="kT"):
        enskog_rate(1.0, 1.0, 0.3, -1.0, 1.0)
    with pytest.raises(ValueError, match="density"):
        enskog_rate(math.nan, 1.0, 0.3, 1.0, 1.0)
    with pytest.raises(ValueError, match="packing"):
        enskog_rate(1.0, 1.0, 1.0, 1.0, 1.0)


def test_li_2022_converts_beta_p_sigma2_to_z_and_finds_its_points():
    from collision_env.observables import li_2022_pressures

    ref = li_2022_pressures(224, "1:1")
    # Z = beta P sigma^2 pi / (4 phi): the N = 224, phi = 0.68 row, 8.49105 +- 0.00019
    z, err = ref.at(0.68)
    assert z == pytest.approx(8.49105 * math.pi / (4 * 0.68), rel=1e-12)
    assert err == pytest.approx(0.00019 * math.pi / (4 * 0.68), rel=1e-12)
    assert ref.sides == (1.0, 1.0) and ref.n == 224
    assert list(ref.packing) == sorted(ref.packing) and ref.packing[0] == 0.67 and ref.packing[-1] == 0.71
    with pytest.raises(ValueError, match="0.670, 0.672"):
        ref.at(0.6)
    with pytest.raises(ValueError, match="N = 72 in 1:1"):
        li_2022_pressures(100, "1:1")


def test_li_2022_series_are_fluid_or_the_n224_loop_and_agree_with_kolafa_rottner_at_large_n():
    from collision_env.observables import LI_2022, li_2022_pressures

    for n, cell in LI_2022:
        ref = li_2022_pressures(n, cell)
        assert ((ref.error > 0) & (ref.error < 1e-3 * ref.pressure)).all()
        assert ref.packing.max() <= (0.71 if n == 224 else 0.68)
    # 870 disks: within the fit's few 1e-4 of the large-N equation of state, in both cells
    for cell in ("1:1", "29:30sqrt3/2"):
        z, _ = li_2022_pressures(870, cell).at(0.67)
        assert z == pytest.approx(kolafa_rottner_z(0.67), rel=5e-4)


def test_li_2022_crystal_cells_are_the_cells_disk_gas_tiles():
    from collision_env.engine import disk_gas
    from collision_env.observables import LI_2022_CELLS

    for n, cell in ((72, "9:8sqrt3/2"), (870, "29:30sqrt3/2")):
        gas = disk_gas(n, 0.7, arrangement="crystal", periodic=True, aspect=LI_2022_CELLS[cell])
        width, height = gas.scene.period
        assert height / width == pytest.approx(LI_2022_CELLS[cell][1] / LI_2022_CELLS[cell][0], rel=1e-12)
