"""The hexatic order through freud: a perfect triangular crystal has |psi6| = 1 everywhere, in a
periodic cell and in a box; an ideal gas has |Psi6| of order 1 / sqrt(N); g6(r) of a crystal is 1;
without freud the functions name the extra to install."""

import math
import sys

import numpy as np
import pytest

from collision_env.engine import Scene, disk_gas
from collision_env.extras import MissingExtra
from collision_env.observables import global_hexatic_order, hexatic_correlation, hexatic_order

pytest.importorskip("freud")


def _rotated_crystal(angle):
    """A periodic crystal of 64 disks, its lattice turned by ``angle`` about the cell's centre: the
    sites of a larger crystal inside a walled box (no periodic cell fits a turned lattice)."""
    big = disk_gas(1024, 0.7, arrangement="crystal", periodic=True, aspect=(32, 32 * math.sqrt(3) / 2))
    centre = np.array(big.scene.period) / 2
    c, s = math.cos(angle), math.sin(angle)
    p = (big.positions - centre) @ np.array([[c, s], [-s, c]])
    inside = (np.abs(p) < 4.0).all(axis=1)
    return p[inside], Scene(bounds=(-4.5, -4.5, 4.5, 4.5))


@pytest.mark.parametrize("aspect", [None, (9, 8 * math.sqrt(3) / 2), (1, math.sqrt(3) / 2)])
def test_a_perfect_crystal_is_perfectly_hexatic_in_a_periodic_cell(aspect):
    n = 64 if aspect == (1, math.sqrt(3) / 2) else 72
    crystal = disk_gas(n, 0.72, arrangement="crystal", periodic=True, aspect=aspect)
    psi = hexatic_order(crystal.positions, crystal.scene)
    assert psi.shape == (n,) and psi.dtype == np.complex128
    np.testing.assert_allclose(psi, 1.0, atol=1e-5)  # (freud works in single precision)
    # the six nearest neighbours are the Voronoi neighbours here
    np.testing.assert_allclose(hexatic_order(crystal.positions, crystal.scene, neighbors=6), psi, atol=1e-5)
    assert abs(global_hexatic_order(crystal.positions, crystal.scene) - 1.0) < 1e-5


def test_a_crystal_in_a_box_is_perfectly_hexatic_and_turning_it_turns_the_phase():
    # the crystal's rows along a wall: the disks on the walls have fewer Voronoi neighbours (their
    # cells clipped by the walls), all at multiples of 60 degrees
    crystal = disk_gas(72, 0.72, arrangement="crystal", periodic=True)
    box = Scene(bounds=crystal.scene.bounds)
    np.testing.assert_allclose(hexatic_order(crystal.positions, box), 1.0, atol=1e-5)
    # turned by 0.1 rad and cut by a square: psi6 turns by 6 times the angle, away from the walls
    # (where a cut lattice's clipped cells may meet across a missing site)
    angle = 0.1
    points, box = _rotated_crystal(angle)
    psi = hexatic_order(points, box)
    interior = (np.abs(points) < 3.0).all(axis=1)
    assert interior.sum() > 20
    np.testing.assert_allclose(psi[interior], np.exp(6j * angle), atol=1e-5)


def test_an_ideal_gas_has_global_order_of_one_over_root_n():
    rng = np.random.default_rng(4)
    cell = Scene(bounds=(0.0, 0.0, 30.0, 30.0), periodic=True)
    samples = rng.uniform(0.0, 30.0, size=(40, 400, 2))
    psi = global_hexatic_order(samples, cell)
    assert psi.shape == (40,)
    # |Psi6|^2 averages <|psi6(j)|^2> / N for uncorrelated disks (neighbours share bonds: a factor
    # of order one more)
    local = hexatic_order(samples[0], cell)
    ratio = np.mean(np.abs(psi) ** 2) / (np.mean(np.abs(local) ** 2) / 400)
    assert 0.5 < ratio < 4.0
    assert np.sqrt(np.mean(np.abs(psi) ** 2)) < 3 / math.sqrt(400)
    box = Scene(bounds=(0.0, 0.0, 30.0, 30.0))
    assert abs(global_hexatic_order(samples[0], box)) < 5 / math.sqrt(400)


def test_g6_of_a_crystal_is_one_and_of_a_gas_decays():
    crystal = disk_gas(256, 0.72, arrangement="crystal", periodic=True)
    r, g6 = hexatic_correlation(crystal.positions, crystal.scene, r_max=4.0, bins=16)
    assert r.shape == g6.shape == (16,)
    occupied = g6 != 0.0  # (shells between the lattice's distances hold no pair)
    np.testing.assert_allclose(g6[occupied], 1.0, atol=1e-4)
    rng = np.random.default_rng(1)
    cell = Scene(bounds=(0.0, 0.0, 20.0, 20.0), periodic=True)
    _, gas = hexatic_correlation(rng.uniform(0.0, 20.0, size=(5, 400, 2)), cell, r_max=8.0, bins=8)
    assert abs(gas[-1]) < 0.05 and gas[0] > gas[-1]


def test_bad_input_is_refused():
    crystal = disk_gas(72, 0.7, arrangement="crystal", periodic=True)
    with pytest.raises(ValueError, match="neighbors"):
        hexatic_order(crystal.positions, crystal.scene, neighbors=0)
    with pytest.raises(ValueError, match="neighbors"):
        hexatic_order(crystal.positions, crystal.scene, neighbors="delaunay")
    with pytest.raises(ValueError, match="bounds"):
        hexatic_order(crystal.positions, Scene(bounds=None))
    with pytest.raises(ValueError, match="outside the box"):
        hexatic_order([[0.5, 0.5], [2.0, 0.5]], Scene(bounds=(0.0, 0.0, 1.0, 1.0)))
    with pytest.raises(ValueError, match="positions"):
        hexatic_order([[0.5, np.nan], [0.2, 0.5]], Scene(bounds=(0.0, 0.0, 1.0, 1.0)))
    with pytest.raises(ValueError, match="r_max"):
        hexatic_correlation(crystal.positions, crystal.scene, r_max=100.0)


def test_without_freud_the_error_names_the_extra(monkeypatch):
    monkeypatch.setitem(sys.modules, "freud", None)
    with pytest.raises(MissingExtra, match=r"'analysis' extra \(freud is missing\)"):
        hexatic_order(np.zeros((2, 2)), Scene(bounds=(-1.0, -1.0, 1.0, 1.0)))
