"""rgb_array frames without a display, human mode in a (dummy) window."""

import os
import subprocess
import sys

import gymnasium as gym
import numpy as np
import pytest

from .conftest import ENV_IDS

pytest.importorskip("pygame")


@pytest.mark.parametrize("trails", [False, True])
def test_rgb_frames_are_nonblank_and_change_as_balls_move(env_id, trails):
    env = gym.make(env_id, render_mode="rgb_array", trails=trails)
    env.reset(seed=1)
    first = env.render()
    assert first.dtype == np.uint8 and first.ndim == 3 and first.shape[2] == 3
    assert first.shape[0] >= 36 and first.shape[1] >= 36
    assert len(np.unique(first.reshape(-1, 3), axis=0)) > 8  # more than a blank background
    a = np.ones(env.action_space.shape, np.float32)
    for _ in range(10):
        env.step(a)
    later = env.render()
    assert later.shape == first.shape and not np.array_equal(first, later)
    env.close()
    env.close()  # closing twice is fine


def test_impact_flash_is_drawn_at_the_contact_point():
    env = gym.make("CollisionEnv/OneBallTarget-v0", render_mode="rgb_array").unwrapped
    env.reset(seed=0)
    for _ in range(200):
        _, _, term, trunc, info = env.step(np.zeros(2, np.float32))
        if len(info["impacts"]):
            break
    ((x, y),) = info["impacts"].point
    with_flash = env.render()
    env._renderer._flashes.clear()
    without = env.render()
    diff = np.abs(with_flash.astype(int) - without.astype(int)).sum(-1)
    ys, xs = np.nonzero(diff)
    px, py = env._renderer._px(x, y)
    assert len(xs) > 0
    # every changed pixel is within the flash ring around the exact contact point
    assert np.hypot(xs - px, ys - py).max() < 30


def test_human_mode_opens_a_window_and_returns_none():
    env = gym.make("CollisionEnv/Billiards-v0", render_mode="human")
    env.reset(seed=0)
    assert env.render() is None
    env.step(env.action_space.sample())
    env.close()


def test_a_window_without_a_display_prints_nothing():
    """A headless machine: no display, no SDL driver chosen, no XDG_RUNTIME_DIR (which SDL's Wayland
    probe complains about); the env checker opens the human window too."""
    code = (
        "import gymnasium as gym, collision_env\n"
        "from gymnasium.utils.env_checker import check_env\n"
        "env = gym.make('CollisionEnv/Line1D-v0', render_mode='human')\n"
        "env.reset(seed=0)\n"
        "env.step(env.action_space.sample())\n"
        "env.close()\n"
        "check_env(gym.make('CollisionEnv/OneBallTarget-v0', render_mode='rgb_array').unwrapped)\n"
        "print('ok')\n"
    )
    hidden = ("DISPLAY", "WAYLAND_DISPLAY", "XDG_RUNTIME_DIR", "SDL_VIDEODRIVER", "PYGAME_HIDE_SUPPORT_PROMPT")
    env = {k: v for k, v in os.environ.items() if k not in hidden}
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=300)
    assert run.returncode == 0, run.stderr
    assert run.stdout == "ok\n" and run.stderr == ""


def test_render_without_mode_warns_and_returns_none():
    env = gym.make("CollisionEnv/OneBallTarget-v0").unwrapped
    env.reset(seed=0)
    with pytest.warns(UserWarning):
        assert env.render() is None


def test_render_fps_is_an_int(env_id):
    env = gym.make(env_id, dt=0.04)
    assert env.metadata["render_fps"] == 25 and isinstance(env.metadata["render_fps"], int)
    assert ENV_IDS
