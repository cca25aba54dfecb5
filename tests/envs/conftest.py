import os

# Rendering draws on off-screen pygame surfaces; "human" mode tests need a window, so they use
# SDL's dummy video driver (set before pygame is imported anywhere).
os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
os.environ.setdefault("SDL_AUDIODRIVER", "dummy")
os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")

import gymnasium as gym
import pytest

import collision_env

ENV_IDS = list(collision_env.ENV_IDS)
PRESET_IDS = [i for i in ENV_IDS if not i.endswith("/Target-v0")]


@pytest.fixture(params=ENV_IDS)
def env_id(request):
    return request.param


def make_unwrapped(env_id, **kwargs):
    return gym.make(env_id, **kwargs).unwrapped
