"""The native vector env equals the sync vector env step for step, autoresets included; SB3 adapter."""

import pickle

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import data_equivalence
from gymnasium.vector import AutoresetMode

from collision_env.engine import Impacts
from collision_env.envs import CollisionTargetVectorEnv

N_ENVS = 4


def _records(imp):
    """Impact records without the scene column (sync sub-envs all say 0)."""
    rec = imp.array
    return rec[[n for n in rec.dtype.names if n != "scene"]]


def assert_infos_equal(native: dict, sync: dict, n: int):
    assert native.keys() == sync.keys(), (sorted(native), sorted(sync))
    for key, value in sync.items():
        if key == "impacts":
            mask = sync["_impacts"]
            assert isinstance(native[key], Impacts)
            for i in range(n):
                if mask[i]:
                    assert np.array_equal(_records(native[key].for_scene(i)), _records(value[i])), (key, i)
                else:
                    assert len(native[key].for_scene(i)) == 0
        elif key == "final_info":
            assert_infos_equal(native[key], value, n)
        else:
            assert data_equivalence(native[key], value, exact=True), (key, native[key], value)


def run_pair(env_id, autoreset, steps, seed, **kwargs):
    native = gym.make_vec(env_id, N_ENVS, vectorization_mode="vector_entry_point", autoreset_mode=autoreset, **kwargs)
    vector_kwargs = {"autoreset_mode": autoreset}
    sync = gym.make_vec(env_id, N_ENVS, vectorization_mode="sync", vector_kwargs=vector_kwargs, **kwargs)
    assert isinstance(native.unwrapped, CollisionTargetVectorEnv)
    assert native.metadata["autoreset_mode"] == autoreset
    o1, i1 = native.reset(seed=seed)
    o2, i2 = sync.reset(seed=seed)
    assert np.array_equal(o1, o2)
    assert_infos_equal(i1, i2, N_ENVS)
    rng = np.random.default_rng(seed)
    ends = 0
    for t in range(steps):
        a = rng.uniform(-1.3, 1.3, native.action_space.shape).astype(np.float32)
        r1 = native.step(a)
        r2 = sync.step(a)
        for k in range(4):
            assert np.array_equal(r1[k], r2[k]), (t, k, r1[k], r2[k])
            assert r1[k].dtype == r2[k].dtype
        assert_infos_equal(r1[4], r2[4], N_ENVS)
        ends += int((r1[2] | r1[3]).sum())
    native.close()
    sync.close()
    return ends


@pytest.mark.parametrize("mode", [AutoresetMode.NEXT_STEP, AutoresetMode.SAME_STEP])
def test_native_equals_sync_with_autoresets(env_id, mode):
    # short episodes (both the TimeLimit and the env's own time limit) force several autoresets
    ends = run_pair(env_id, mode, steps=45, seed=3, max_episode_steps=12)
    short = {"time_limit": 0.6, **({"window": 0.3} if "Line1D" in env_id else {})}
    ends += run_pair(env_id, mode, steps=45, seed=4, **short)
    assert ends >= 2 * N_ENVS


def test_native_equals_sync_through_terminations():
    # Line1D fails early when a window closes; time windows at [0.x, ...] end episodes fast
    ends = run_pair("CollisionEnv/Line1D-v0", AutoresetMode.NEXT_STEP, steps=120, seed=0, time_limit=3.0, window=0.5)
    assert ends > N_ENVS


def test_native_reset_mask_and_seed_list():
    native = gym.make_vec("CollisionEnv/Billiards-v0", N_ENVS)
    sync = gym.make_vec("CollisionEnv/Billiards-v0", N_ENVS, vectorization_mode="sync")
    seeds = [10, None, 12, 13]
    o1, _ = native.reset(seed=seeds)
    o2, _ = sync.reset(seed=seeds[:1] + [99] + seeds[2:])
    assert np.array_equal(o1[[0, 2, 3]], o2[[0, 2, 3]])
    a = np.zeros(native.action_space.shape, np.float32)
    native.step(a)
    sync.step(a)
    mask = np.array([True, False, True, False])
    o1, i1 = native.reset(seed=[5, 6, 7, 8], options={"reset_mask": mask})
    o2, i2 = sync.reset(seed=[5, 6, 7, 8], options={"reset_mask": mask})
    assert np.array_equal(o1[mask], o2[mask])
    for key in ("energy", "is_success", "targets_hit", "time", "_energy"):
        assert data_equivalence(i1[key], i2[key], exact=True), key


def test_vector_spaces_truncation_and_bad_actions():
    venv = gym.make_vec("CollisionEnv/OneBallTarget-v0", 3, max_episode_steps=5)
    assert venv.single_observation_space == gym.make("CollisionEnv/OneBallTarget-v0").observation_space
    obs, _ = venv.reset(seed=0)
    assert obs.shape == (3, 18) and obs.dtype == np.float32
    a = np.zeros((3, 2), np.float32)
    for _ in range(4):
        assert not venv.step(a)[3].any()
    assert venv.step(a)[3].all()
    bad = a.copy()
    bad[1, 0] = np.nan
    venv.step(bad)  # the autoreset step ignores the actions, as the sync vector env does
    state = venv.unwrapped.get_state()
    with pytest.raises(ValueError, match="NaN"):
        venv.step(bad)
    assert data_equivalence(state["core"], venv.unwrapped.get_state()["core"], exact=True)
    with pytest.raises(ValueError):
        venv.step(np.zeros((2, 2), np.float32))
    with pytest.raises(ValueError):
        gym.make_vec("CollisionEnv/OneBallTarget-v0", 2, autoreset_mode=AutoresetMode.DISABLED)


def test_vector_pickle_and_state():
    venv = gym.make_vec("CollisionEnv/InelasticCluster-v0", 3)
    venv.reset(seed=1)
    rng = np.random.default_rng(0)
    for _ in range(5):
        venv.step(rng.uniform(-1, 1, venv.action_space.shape).astype(np.float32))
    clone = pickle.loads(pickle.dumps(venv))
    state = venv.unwrapped.get_state()
    actions = [rng.uniform(-1, 1, venv.action_space.shape).astype(np.float32) for _ in range(30)]
    first = [venv.step(a)[:4] for a in actions]
    second = [clone.step(a)[:4] for a in actions]
    venv.unwrapped.set_state(state)
    third = [venv.step(a)[:4] for a in actions]
    assert data_equivalence(first, second, exact=True) and data_equivalence(first, third, exact=True)


def test_vector_render_frames():
    pytest.importorskip("pygame")
    venv = gym.make_vec("CollisionEnv/OneBallTarget-v0", 2, render_mode="rgb_array")
    venv.reset(seed=0)
    frames = venv.render()
    assert len(frames) == 2 and frames[0].dtype == np.uint8 and frames[0].ndim == 3
    assert not np.array_equal(frames[0], frames[1])


# ------------------------------------------------------------------------------------------------ SB3


def test_sb3_adapter_matches_dummy_vec_env():
    pytest.importorskip("stable_baselines3")
    from stable_baselines3.common.vec_env import DummyVecEnv

    from collision_env.envs.sb3 import CollisionSB3VecEnv

    env_id = "CollisionEnv/Line1D-v0"
    ours = CollisionSB3VecEnv(env_id, N_ENVS, time_limit=1.0, window=0.4)
    ref = DummyVecEnv([lambda: gym.make(env_id, time_limit=1.0, window=0.4) for _ in range(N_ENVS)])
    ours.seed(21)
    ref.seed(21)
    assert np.array_equal(ours.reset(), ref.reset())
    rng = np.random.default_rng(1)
    dones_seen = 0
    for _ in range(50):
        a = rng.uniform(-1, 1, (N_ENVS, 1)).astype(np.float32)
        o1, r1, d1, inf1 = ours.step(a)
        o2, r2, d2, inf2 = ref.step(a)
        assert np.array_equal(o1, o2) and np.array_equal(r1, r2) and np.array_equal(d1, d2)
        assert r1.dtype == r2.dtype == np.float32
        for x, y in zip(inf1, inf2, strict=True):
            assert x["is_success"] == y["is_success"] and x["nudge"] == y["nudge"]
            assert x["TimeLimit.truncated"] == y["TimeLimit.truncated"]
            assert ("terminal_observation" in x) == ("terminal_observation" in y)
            if "terminal_observation" in x:
                assert np.array_equal(x["terminal_observation"], y["terminal_observation"])
        dones_seen += int(d1.sum())
    assert dones_seen >= N_ENVS


def test_sb3_ppo_trains_on_the_native_vector_env():
    pytest.importorskip("stable_baselines3")
    from stable_baselines3 import PPO

    from collision_env.envs.sb3 import make_sb3_vec_env

    venv = make_sb3_vec_env("CollisionEnv/OneBallTarget-v0", n_envs=8, seed=0, time_limit=1.0)
    model = PPO("MlpPolicy", venv, n_steps=32, batch_size=64, n_epochs=1, device="cpu", seed=0)
    model.learn(total_timesteps=512)
    assert model.num_timesteps >= 512
    assert len(model.ep_info_buffer) > 0 and len(model.ep_success_buffer) > 0


@pytest.mark.parametrize("mode", [AutoresetMode.NEXT_STEP, AutoresetMode.SAME_STEP])
def test_an_info_kept_from_one_step_stays_as_it_was_through_the_next(mode):
    # replay buffers and episode logs keep infos: none of an info's arrays may be the engine's own
    import copy

    env = CollisionTargetVectorEnv(num_envs=4, autoreset_mode=mode, max_episode_steps=3)
    env.reset(seed=0)
    kept = []
    for _ in range(7):
        _, _, _, _, info = env.step(env.action_space.sample())
        kept.append((info, copy.deepcopy(info)))
    for info, then in kept:
        assert info.keys() == then.keys()
        for key, value in then.items():
            if isinstance(value, Impacts):
                np.testing.assert_array_equal(info[key].array, value.array, err_msg=key)
            else:  # (arrays, SAME_STEP's final observations and infos as object arrays)
                assert data_equivalence(info[key], value), key
    assert kept[0][0]["time"][0] != kept[1][0]["time"][0]  # (the clock did move on)
