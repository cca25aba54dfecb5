"""The predicted observation (observe="predicted"): each ball's next wall impact as the engine will
produce it, checked against the impacts that then happen; checkers and single-vs-vector equality."""

import warnings

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env
from gymnasium.vector import AutoresetMode

from collision_env.envs import PRESET_IDS
from collision_env.envs.task.layout import BALL_OBS, PREDICTED_OBS, SCENE_FLOATS, TARGET_GEOMETRY
from tests.envs.test_vector import run_pair

IDS = sorted(PRESET_IDS.values())
NP = len(PREDICTED_OBS)


def _predicted(obs, n_blocks):
    return obs[-n_blocks * NP :].reshape(n_blocks, NP)


def _normalised(cfg, x, y):
    xmin, ymin, xmax, ymax = cfg.bounds
    return 2 * (x - xmin) / (xmax - xmin) - 1, 2 * (y - ymin) / (ymax - ymin) - 1


@pytest.mark.parametrize("env_id", IDS)
def test_prediction_is_the_impact_that_happens_when_nothing_is_nudged(env_id):
    # A gas is chaotic: round-off differences between one long look-ahead step and many control
    # steps grow by about a mean free path over a radius per collision, so the crowd is checked
    # over a horizon of a few collisions per ball.
    lookahead = 0.5 if "Crowd" in env_id else 10.0
    env = gym.make(env_id, observe="predicted", observed_balls="all", lookahead=lookahead).unwrapped
    cfg = env.config
    plain = gym.make(env_id, observed_balls="all").unwrapped.config.obs_dim
    assert env.observation_space.shape == (cfg.obs_dim,) and cfg.obs_dim == plain + NP * cfg.n_balls
    checked = 0
    for seed in range(4):
        obs, _ = env.reset(seed=seed)
        env.action_space.seed(seed)
        # a few random nudges set the balls moving, then the agent stops acting
        for _ in range(10):
            obs, _, term, trunc, _ = env.step(env.action_space.sample())
            if term or trunc:
                break
        if term or trunc:
            continue
        pred, now = _predicted(obs, cfg.n_balls), env.core.time[0]
        first = {}
        zero = np.zeros(env.action_space.shape, np.float32)
        while not (term or trunc) and len(first) < cfg.n_balls and env.core.time[0] - now <= lookahead:
            _, _, term, trunc, info = env.step(zero)
            for r in info["impacts"].array:
                if r["wall"] >= 0 and r["ball"] not in first:
                    first[int(r["ball"])] = r
        for i in range(cfg.n_balls):
            p = pred[i]
            if i not in first:  # no impact in the time played: none predicted inside it either
                assert p[PREDICTED_OBS.time] >= min(env.core.time[0] - now - cfg.dt, lookahead) / cfg.time_limit
                continue
            r = first[i]
            if r["time"] - now > cfg.lookahead:
                continue
            x, y = _normalised(cfg, r["x"], r["y"])
            assert p[PREDICTED_OBS.x] == pytest.approx(x, abs=1e-5), (seed, i)
            assert p[PREDICTED_OBS.y] == pytest.approx(y, abs=1e-5), (seed, i)
            assert p[PREDICTED_OBS.time] == pytest.approx((r["time"] - now) / cfg.time_limit, abs=1e-5), (seed, i)
            checked += 1
    assert checked >= 2


def test_hits_flag_says_whether_the_coasting_ball_scores():
    env = gym.make("CollisionEnv/OneBallTarget-v0", observe="predicted").unwrapped
    cfg = env.config
    for aim_at_target in (True, False):
        env.reset(seed=1)
        core = env.core
        k = int(core.cur[0])
        wall, centre = int(core.t_wall[0, k]), core.target_geo[0, k, TARGET_GEOMETRY.centre]
        xmin, ymin, xmax, ymax = cfg.bounds
        r = core.radii[0, 0]
        spot = {0: (xmin + r, centre), 1: (xmax - r, centre), 2: (centre, ymin + r), 3: (centre, ymax - r)}[wall]
        if not aim_at_target:  # the mirror image across the box's centre: the opposite wall
            spot = (-spot[0], -spot[1])
        direction = np.subtract(spot, (0.0, 0.0))
        velocity = 0.8 * direction / np.linalg.norm(direction)
        core.batch.set_scenes([0], np.zeros((1, 1, 2)), velocity[None, None])
        zero = np.zeros(2, np.float32)
        obs, *_ = env.step(zero)
        hits = _predicted(obs, 1)[0, PREDICTED_OBS.hits]
        assert hits == (1.0 if aim_at_target else 0.0)
        for _ in range(80):  # coast to the next wall impact
            obs, reward, _, _, info = env.step(zero)
            if len(info["impacts"]):
                break
        assert len(info["impacts"]) == 1
        scored = int(env.core.cur[0]) > k
        assert scored == aim_at_target


SCORING = {"predicted_impact": "scoring", "aim": "predicted", "shaping": 1.0}
CHECKED = [(env_id, {}) for env_id in IDS] + [
    (i, SCORING) for i in ("CollisionEnv/Billiards-v0", "CollisionEnv/MultiBall-v0")
]


@pytest.mark.parametrize(
    "env_id, extra", CHECKED, ids=lambda x: ("scoring" if x else "next") if isinstance(x, dict) else None
)
def test_checkers_and_vector_equality_with_predictions(env_id, extra):
    pytest.importorskip("stable_baselines3")
    from stable_baselines3.common.env_checker import check_env as sb3_check_env

    kwargs = {"observe": "predicted", **extra}
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_env(gym.make(env_id, **kwargs).unwrapped, skip_render_check=True)
        sb3_check_env(gym.make(env_id, **kwargs).unwrapped, warn=True)
    # (a look-ahead that fills the engine's impact buffer is resumed exactly where it stopped, so a
    # batch and a single scene agree bit for bit however many impacts their look-aheads record)
    for mode in (AutoresetMode.NEXT_STEP, AutoresetMode.SAME_STEP):
        assert run_pair(env_id, mode, steps=30, seed=2, max_episode_steps=10, **kwargs) >= 4


def test_only_the_controlled_balls_can_be_observed():
    # the crowd's gas has no blocks: ball 0's, the target's and the globals', then ball 0's prediction
    full = gym.make("CollisionEnv/Crowd-v0", observe="predicted", observed_balls="all").unwrapped
    few = gym.make("CollisionEnv/Crowd-v0", observe="predicted").unwrapped
    assert few.config.observed_balls == "controlled" and few.observation_space.shape == (18 + NP,)
    o_full, _ = full.reset(seed=5)
    o_few, _ = few.reset(seed=5)
    n, nb = full.config.n_balls, len(BALL_OBS)
    assert np.array_equal(o_few[:nb], o_full[:nb])  # ball 0
    assert np.array_equal(o_few[nb:-NP], o_full[n * nb : -n * NP])  # targets and globals
    assert np.array_equal(o_few[-NP:], o_full[-n * NP :][:NP])  # ball 0's prediction


def test_bad_observe_and_lookahead_are_value_errors():
    with pytest.raises(ValueError, match="observe"):
        gym.make("CollisionEnv/OneBallTarget-v0", observe="everything")
    with pytest.raises(ValueError, match="observed_balls"):
        gym.make("CollisionEnv/OneBallTarget-v0", observed_balls="some")
    with pytest.raises(ValueError, match="lookahead"):
        gym.make("CollisionEnv/OneBallTarget-v0", observe="predicted", lookahead=0.0)
    with pytest.raises(ValueError, match="predicted_impact"):
        gym.make("CollisionEnv/OneBallTarget-v0", observe="predicted", predicted_impact="last")


def test_predicted_aim_equals_straight_aim_where_nothing_is_in_the_way():
    # one ball, no other balls: flying straight on is exactly what the engine predicts (as long as
    # the ball reaches a wall within the look-ahead: small nudges keep it moving)
    kwargs = {"lookahead": 200.0}
    straight = gym.make("CollisionEnv/OneBallTarget-v0", **kwargs).unwrapped
    predicted = gym.make("CollisionEnv/OneBallTarget-v0", aim="predicted", **kwargs).unwrapped
    straight.action_space.seed(0)
    assert predicted.core.ahead is not None and straight.core.ahead is None
    for seed in range(3):
        o1, _ = straight.reset(seed=seed)
        o2, _ = predicted.reset(seed=seed)
        assert np.array_equal(o1, o2)  # the plain observation either way
        rewards = []
        for _ in range(120):
            a = 0.3 * straight.action_space.sample()
            r1 = straight.step(a)
            r2 = predicted.step(a)
            assert np.array_equal(r1[0], r2[0]) and r1[2:4] == r2[2:4]
            assert r1[1] == pytest.approx(r2[1], abs=1e-9)
            rewards.append(r1[1])
            if r1[2] or r1[3]:
                break
        assert any(r != 0.0 for r in rewards)


def test_predicted_aim_sees_through_ball_to_ball_transfer():
    # Billiards: the cue ball sent straight at an object ball; the straight heuristic sees no
    # scoring ball moving (phi = -1), the prediction sees the object ball's wall impact coming
    env = gym.make("CollisionEnv/Billiards-v0", aim="predicted", shaping=1.0).unwrapped
    env.reset(seed=0)
    core = env.core
    cue, ball = core.pos[0, 0].copy(), core.pos[0, 1].copy()
    aim = (ball - cue) / np.linalg.norm(ball - cue)
    vel = np.zeros((1, core.cfg.n_balls, 2))
    vel[0, 0] = 1.5 * aim
    core.batch.set_scenes([0], core.pos[0][None].copy(), vel)
    env.step(np.zeros(2, np.float32))
    phi = core.scene_f[0, SCENE_FLOATS.phi]
    assert -1.0 < phi <= 0.0


def test_scoring_prediction_looks_past_a_miss_for_the_impact_on_the_target():
    # one ball sent straight away from its target's wall at the target's centre: its next wall
    # impact is on the opposite wall (a miss), the one after it lands on the target. With
    # predicted_impact="next" the block shows the miss; with "scoring", the hit, which then happens
    # at the predicted time and place.
    blocks, phis = {}, {}
    for which in ("next", "scoring"):
        env = gym.make(
            "CollisionEnv/OneBallTarget-v0",
            observe="predicted",
            aim="predicted",
            lookahead=20.0,
            predicted_impact=which,
        ).unwrapped
        cfg = env.config
        env.reset(seed=1)
        core = env.core
        k = int(core.cur[0])
        wall, centre = int(core.t_wall[0, k]), core.target_geo[0, k, TARGET_GEOMETRY.centre]
        side = wall < 2  # a target on the left or right wall
        position = np.array([0.0, centre] if side else [centre, 0.0])
        away = np.array([1.0, 0.0] if side else [0.0, 1.0]) * (1.0 if wall % 2 == 0 else -1.0)
        core.batch.set_scenes([0], position[None, None], 0.8 * away[None, None])
        zero = np.zeros(2, np.float32)
        obs, *_ = env.step(zero)
        now = env.core.time[0]
        blocks[which] = block = _predicted(obs, 1)[0]
        phis[which] = core.scene_f[0, SCENE_FLOATS.phi]  # minus the distance from the nearest impact to the target
        if which == "next":
            assert block[PREDICTED_OBS.hits] == 0.0
            continue
        assert block[PREDICTED_OBS.hits] == 1.0
        for _ in range(400):  # coast: the miss, then the hit
            obs, _, term, _, info = env.step(zero)
            walls = [r for r in info["impacts"].array if r["wall"] >= 0]
            if walls and walls[-1]["wall"] == wall:
                break
        else:
            pytest.fail("the ball never came back to its target's wall")
        r = walls[-1]
        assert int(env.core.cur[0]) > k  # it scored
        x, y = _normalised(cfg, r["x"], r["y"])
        assert block[PREDICTED_OBS.x] == pytest.approx(x, abs=1e-5)
        assert block[PREDICTED_OBS.y] == pytest.approx(y, abs=1e-5)
        assert block[PREDICTED_OBS.time] == pytest.approx((r["time"] - now) / cfg.time_limit, abs=1e-5)
    # the miss is the hit's mirror image across the axis the ball flies along, and comes first
    across, along = (PREDICTED_OBS.x, PREDICTED_OBS.y) if side else (PREDICTED_OBS.y, PREDICTED_OBS.x)
    assert blocks["next"][across] == pytest.approx(-blocks["scoring"][across], abs=1e-5)
    assert blocks["next"][along] == pytest.approx(blocks["scoring"][along], abs=1e-5)
    assert blocks["next"][PREDICTED_OBS.time] < blocks["scoring"][PREDICTED_OBS.time]
    # the aiming potential: the miss lies a wall away from the target; the later hit is on it
    assert phis["next"] < -0.1 and phis["scoring"] == 0.0


def test_scoring_prediction_changes_only_the_blocks_of_scoring_balls_that_will_hit():
    # Billiards under the same random actions, "next" beside "scoring": the cue ball (whose impacts
    # never score) and every object ball with no hit ahead keep their next impact, and everything
    # outside the predicted blocks is the same; where they differ, "scoring" shows a hit later on
    kwargs = {"observe": "predicted", "lookahead": 10.0, "control": "velocity"}
    envs = {
        w: gym.make("CollisionEnv/Billiards-v0", predicted_impact=w, **kwargs).unwrapped for w in ("next", "scoring")
    }
    n = envs["next"].config.n_balls
    differ = 0
    for seed in range(3):
        first = {w: env.reset(seed=seed)[0] for w, env in envs.items()}
        assert np.array_equal(first["next"][: -n * NP], first["scoring"][: -n * NP])
        rng = np.random.default_rng(seed)
        for _ in range(120):
            a = rng.uniform(-1, 1, 3).astype(np.float32)
            a[2] = 1.0 if rng.random() < 0.2 else -1.0  # steer now and then, else coast
            steps = {w: env.step(a) for w, env in envs.items()}
            o_next, o_scoring = steps["next"][0], steps["scoring"][0]
            assert np.array_equal(o_next[: -n * NP], o_scoring[: -n * NP])
            assert steps["next"][1:4] == steps["scoring"][1:4]
            p_next, p_scoring = _predicted(o_next, n), _predicted(o_scoring, n)
            assert np.array_equal(p_next[0], p_scoring[0])  # the cue ball
            for i in range(1, n):
                if p_scoring[i, PREDICTED_OBS.hits] == 0.0 or p_next[i, PREDICTED_OBS.hits] == 1.0:
                    assert np.array_equal(p_next[i], p_scoring[i]), (seed, i)
                else:
                    differ += 1
                    assert p_scoring[i, PREDICTED_OBS.time] > p_next[i, PREDICTED_OBS.time]
            if steps["next"][2] or steps["next"][3]:
                break
    assert differ > 0
