"""Random task configurations through the generic env stay valid (hypothesis)."""

import gymnasium as gym
import numpy as np
from gymnasium.utils.env_checker import data_equivalence
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st


@st.composite
def configs(draw):
    dim = draw(st.sampled_from([1, 2]))
    n = draw(st.integers(1, 4 if dim == 1 else 5))
    stick = n >= 2 and dim == 2 and draw(st.booleans())
    cfg = dict(
        preset=None,
        dimension=dim,
        n_balls=n,
        elasticity=0.0 if stick else draw(st.sampled_from([0.0, 0.5, 0.9, 1.0])),
        inelastic="stick" if stick else draw(st.sampled_from(["slip", "stick"])),
        ball_collisions=True if stick else draw(st.booleans()),
        mass_range=draw(st.sampled_from([(1.0, 1.0), (0.1, 3.0), (0.5, 1.5)])),
        radius=draw(st.sampled_from(["mass", "constant", 0.1])),
        layout="random" if dim == 1 else draw(st.sampled_from(["random", "rack"])),
        speed_range=(0.0, draw(st.sampled_from([0.0, 0.5, 2.0]))),
        others_speed_range=(0.0, draw(st.sampled_from([0.0, 1.0]))),
        controlled=tuple(range(draw(st.integers(1, n)))),
        n_targets=draw(st.integers(1, 3)),
        sequential=draw(st.booleans()),
        window=draw(st.sampled_from([None, 1.5])),
        target_width=draw(st.sampled_from([0.3, 1.0])),
        shaping=draw(st.sampled_from([0.0, 1.0])),
        miss_penalty=draw(st.sampled_from([0.0, 0.1])),
        dt=draw(st.sampled_from([0.02, 0.05, 0.2])),
        time_limit=3.0,
    )
    scorers = ["any", "controlled"] + (["others"] if len(cfg["controlled"]) < n else [])
    scorers += ["cluster"] if stick else []
    cfg["scorers"] = draw(st.sampled_from(scorers))
    mode = draw(st.sampled_from(["exact", "posteriori", "naive"]))
    cfg["mode"] = mode
    cfg["substeps"] = 1 if mode == "exact" else draw(st.integers(1, 3))
    return cfg


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(cfg=configs(), seed=st.integers(0, 2**31 - 1))
def test_random_configs_run_and_observations_stay_in_the_box(cfg, seed):
    env = gym.make("CollisionEnv/Target-v0", **cfg)
    obs, info = env.reset(seed=seed)
    assert env.observation_space.contains(obs)
    rng = np.random.default_rng(seed)
    for _ in range(40):
        obs, reward, term, trunc, info = env.step(rng.uniform(-1, 1, env.action_space.shape).astype(np.float32))
        assert env.observation_space.contains(obs) and np.isfinite(reward)
        assert np.isfinite(info["energy"])
        if term or trunc:
            obs, info = env.reset()
    env.close()


@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(cfg=configs(), seed=st.integers(0, 2**31 - 1))
def test_random_configs_native_vector_equals_sync(cfg, seed):
    native = gym.make_vec("CollisionEnv/Target-v0", 3, vectorization_mode="vector_entry_point", **cfg)
    sync = gym.make_vec("CollisionEnv/Target-v0", 3, vectorization_mode="sync", **cfg)
    assert np.array_equal(native.reset(seed=seed)[0], sync.reset(seed=seed)[0])
    rng = np.random.default_rng(seed)
    for _ in range(40):
        a = rng.uniform(-1, 1, native.action_space.shape).astype(np.float32)
        r1, r2 = native.step(a), sync.step(a)
        assert data_equivalence(r1[:4], r2[:4], exact=True)
