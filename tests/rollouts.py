"""Recorded rollouts: every env id in every engine mode, and engine scenes that reach every kernel path.

:func:`record` runs them and returns their outputs as named arrays; ``tests/data/rollouts.npz``
holds what it returned when the file was made (``python -m tests.rollouts`` writes it again), and
``tests/test_rollouts.py`` checks that the code of today returns the same, bit for bit. A
refactoring of the kernels must leave every one of these numbers unchanged.

Only the impact fields named in :data:`IMPACT_FIELDS` are recorded, so that a field added to the
impact records later does not invalidate the file.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import gymnasium as gym
import numpy as np

import collision_env
from collision_env.engine import MODES, BatchSimulator, Scene

PATH = Path(__file__).parent / "data" / "rollouts.npz"
#: The impact record fields compared (those the file was recorded with).
IMPACT_FIELDS = ("scene", "time", "ball", "other", "wall", "x", "y", "speed")
ENV_STEPS = 40
ENV_OPTIONS = {"": {}, "predicted": {"observe": "predicted", "aim": "predicted", "control": "velocity"}}


def _impacts(records) -> np.ndarray:
    """Impact records as an (n, 8) float64 array of :data:`IMPACT_FIELDS`."""
    records = np.asarray(records)
    return np.stack([records[f].astype(np.float64) for f in IMPACT_FIELDS], axis=-1).reshape(-1, len(IMPACT_FIELDS))


def _env_rollout(env_id, mode, options, out):
    kwargs = dict(mode=mode, **options)
    if mode != "exact":
        kwargs["substeps"] = 3
    env = gym.make(env_id, **kwargs)
    rng = np.random.default_rng(7)
    obs, _ = env.reset(seed=3)
    rows, rewards, impacts = [obs], [], []
    for _ in range(ENV_STEPS):
        obs, reward, terminated, truncated, info = env.step(rng.uniform(-1, 1, env.action_space.shape))
        rows.append(obs)
        rewards.append((reward, terminated, truncated))
        impacts.append(_impacts(info["impacts"].array))
        if terminated or truncated:
            obs, _ = env.reset()
            rows.append(obs)
    env.close()
    key = f"env/{env_id}/{mode}/{'+'.join(options) or 'default'}"
    out[f"{key}/obs"] = np.array(rows)
    out[f"{key}/reward"] = np.array(rewards, dtype=np.float64)
    out[f"{key}/impacts"] = np.concatenate(impacts) if impacts else np.zeros((0, len(IMPACT_FIELDS)))


def _vector_rollout(env_id, out):
    envs = gym.make_vec(env_id, num_envs=3, vectorization_mode="vector_entry_point")
    rng = np.random.default_rng(11)
    obs, _ = envs.reset(seed=5)
    rows, rewards = [obs], []
    for _ in range(ENV_STEPS):
        obs, reward, terminated, truncated, _ = envs.step(rng.uniform(-1, 1, envs.action_space.shape))
        rows.append(obs)
        rewards.append(np.stack([reward, terminated, truncated]).astype(np.float64))
    envs.close()
    out[f"vector/{env_id}/obs"] = np.array(rows)
    out[f"vector/{env_id}/reward"] = np.array(rewards)


def _gas(n, phi, seed, box=1.0):
    """``n`` equal disks at area fraction ``phi`` on a jittered square lattice in ``[-box, box]^2``,
    with random velocities."""
    rng = np.random.default_rng(seed)
    side = int(np.ceil(np.sqrt(n)))
    r = np.sqrt(phi * (2 * box) ** 2 / (n * np.pi))
    h = 2 * box / side
    cells = np.stack(np.meshgrid(np.arange(side), np.arange(side)), -1).reshape(-1, 2)[:n]
    pos = -box + h * (cells + 0.5) + rng.uniform(-1, 1, (n, 2)) * max(0.0, 0.5 * h - r) * 0.9
    return pos, rng.normal(size=(n, 2)), np.ones(n), np.full(n, r)


def _scenes():
    """Engine scenes: ``name -> (scene, positions, velocities, masses, radii, options, steps)``,
    steps being a list of ``dt`` (negative: backwards)."""
    r = 0.1
    gas100 = _gas(100, 0.3, 1)
    gas5k = _gas(5000, 0.3, 2)
    pile = _gas(30, 0.5, 3, box=0.6)
    stick = ([[-0.65, 0], [0.6, 0.12], [0.0, 0.5]], [[0, 0], [-1, 0], [0.3, -0.8]], [1.8, 0.3, 0.7], None)
    galperin = ([[-1.0, 0.0], [0.0, 0.0]], [[0.0, 0.0], [-1.0, 0.0]], [1.0, 1e6], [0.1, 0.1])
    cradle = ([[-1.5, 0], [-0.2, 0], [0.0, 0], [0.2, 0], [0.4, 0]], [[2, 0]] + [[0, 0]] * 4, [1.0] * 5, [0.1] * 5)
    squeeze = ([[-1.0, 0.0], [0.0, 0.0]], [[0.0, 0.0], [-1.0, 0.0]], [1.0, 1e12], [0.1, 0.1])
    corner = (
        [[-2 + r, -1 + r], [-2 + r, -1 + 3 * r], [-1.0, -0.5]],
        [[0, 0], [0, 0], [-1.2, -0.6]],
        [1.0, 2.0, 1e10],
        [r] * 3,
    )
    frames = [1 / 60] * 30
    line = Scene(bounds=(-2.0, -0.55, 1e4, 0.55), dimension=1)
    return {
        "gas100": (Scene(bounds=(-1, -1, 1, 1)), *gas100, {}, frames),
        "gas100-reverse": (Scene(bounds=(-1, -1, 1, 1), elasticity=0.8), *gas100, {}, [0.2, 0.2, -0.2, -0.2]),
        "gas5000": (Scene(bounds=(-1, -1, 1, 1)), *gas5k, {}, [1 / 60] * 2),
        "gas100-inelastic": (Scene(bounds=(-1, -1, 1, 1), elasticity=0.3), *gas100, {}, frames),
        "pile-e0": (Scene(bounds=(-0.6, -0.6, 0.6, 0.6), elasticity=0.0), *pile, {}, frames),
        "stick": (Scene(elasticity=0.0, inelastic="stick"), *stick, {}, [0.05] * 60),
        "galperin": (Scene(bounds=(-2.0, -0.55, 1e4, 0.55), dimension=1), *galperin, {"max_events": 10**5}, [5.0]),
        "cradle": (Scene(bounds=None), *cradle, {}, [0.5, 0.5, 0.5]),
        "squeeze": (
            Scene(bounds=(-2.0, -0.55, 1e4, 0.55), elasticity=0.05, dimension=1),
            *squeeze,
            {},
            [0.01] * 150,
        ),
        "corner": (Scene(elasticity=0.05), *corner, {}, [1 / 60] * 60),
        "free": (Scene(bounds=None, elasticity=0.9), *gas100, {}, [0.1] * 5),
        "line-cap": (line, *galperin, {"max_events": 50}, [5.0, 5.0]),
    }


def _engine_rollout(name, mode, substeps, spec, out):
    scene, pos, vel, mass, radii, options, steps = spec
    sim = BatchSimulator(scene, [pos], [vel], mass, radii, mode=mode, substeps=substeps, **options)
    states, times, impacts = [], [], []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for dt in steps:
            impacts.append(_impacts(sim.step(dt)))
            states.append(np.concatenate([sim.positions[0], sim.velocities[0]], axis=-1))
            times.append(sim.time[0])
    key = f"engine/{name}/{mode}/{substeps}"
    out[f"{key}/state"] = np.array(states)
    out[f"{key}/time"] = np.array(times)
    out[f"{key}/impacts"] = np.concatenate(impacts)


def record() -> dict[str, np.ndarray]:
    """Run every rollout; its outputs by name."""
    out: dict[str, np.ndarray] = {}
    for env_id in collision_env.ENV_IDS:
        for mode in MODES:
            for options in ENV_OPTIONS:
                if options and mode != "exact":
                    continue
                _env_rollout(env_id, mode, ENV_OPTIONS[options], out)
        _vector_rollout(env_id, out)
    for name, spec in _scenes().items():
        for mode, substeps in (("exact", 1), ("naive", 1), ("posteriori", 4)):
            if mode != "exact" and name in ("gas5000", "galperin", "line-cap", "squeeze"):
                continue  # (exact mode's paths: the bucket queue, long cascades and the event cap)
            _engine_rollout(name, mode, substeps, spec, out)
    return out


if __name__ == "__main__":
    PATH.parent.mkdir(parents=True, exist_ok=True)
    data = record()
    np.savez_compressed(PATH, **data)
    print(f"{len(data)} arrays, {PATH.stat().st_size / 1e6:.2f} MB -> {PATH}")
