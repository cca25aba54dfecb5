"""Playing by hand (collision_env.play), headless: SDL's dummy video driver and injected pygame events."""

import gymnasium as gym
import numpy as np
import pytest

pygame = pytest.importorskip("pygame")

from collision_env import play  # noqa: E402

KEY, UP = pygame.KEYDOWN, pygame.KEYUP


def key(kind, k):
    return pygame.event.Event(kind, key=k)


def player(env_id, seed=0, **kwargs):
    return play.Player(gym.make(env_id, render_mode="human", **kwargs), seed=seed)


def test_arrow_keys_nudge_the_steered_ball_while_held():
    p = player("CollisionEnv/OneBallTarget-v0")
    assert not p.nudge().any()
    p.handle(key(KEY, pygame.K_RIGHT))
    p.handle(key(KEY, pygame.K_UP))
    assert p.nudge().tolist() == [[1.0, 1.0]]
    v = p.env.unwrapped.core.vel[0, 0].copy()
    p.tick()
    assert p.steps == 1 and p.env.unwrapped.core.steps[0] == 1
    dv = p.env.unwrapped.core.vel[0, 0] - v
    assert dv == pytest.approx([0.15, 0.15])  # max_dv per axis (no wall in the way at this seed)
    p.handle(key(UP, pygame.K_RIGHT))
    assert p.nudge().tolist() == [[0.0, 1.0]]
    p.env.close()


def test_a_1d_env_reads_left_and_right_only():
    p = player("CollisionEnv/Line1D-v0")
    p.handle(key(KEY, pygame.K_UP))
    assert p.nudge().tolist() == [[0.0]]
    p.handle(key(KEY, pygame.K_LEFT))
    assert p.nudge().tolist() == [[-1.0]]
    p.tick()
    p.env.close()


@pytest.mark.parametrize("control", ["nudge", "velocity"])
def test_click_and_drag_aims_the_ball_at_the_dragged_velocity(control):
    p = player("CollisionEnv/OneBallTarget-v0", control=control, speed_range=(0.0, 0.0))
    renderer = p.env.unwrapped._get_renderer()
    x, y = p.env.unwrapped.core.pos[0, 0]
    press = renderer._px(x, y)
    release = renderer._px(x + 0.4, y - 0.2)  # drag 0.4 m right, 0.2 m down: aim at (0.4, -0.2) m/s
    p.handle(pygame.event.Event(pygame.MOUSEBUTTONDOWN, pos=press, button=1))
    p.handle(pygame.event.Event(pygame.MOUSEBUTTONUP, pos=release, button=1))
    assert p.aim == pytest.approx([0.4, -0.2], abs=0.01)  # to the pixel
    for _ in range(4):  # 0.15 m/s per axis and step: three steps reach it
        p.tick()
    assert p.aim is None  # reached, and let go
    assert p.env.unwrapped.core.vel[0, 0] == pytest.approx([0.4, -0.2], abs=0.01)
    p.env.close()


def test_a_drag_longer_than_max_speed_aims_at_max_speed():
    p = player("CollisionEnv/OneBallTarget-v0")
    renderer = p.env.unwrapped._get_renderer()
    p.handle(pygame.event.Event(pygame.MOUSEBUTTONDOWN, pos=renderer._px(0.0, 0.0), button=1))
    p.handle(pygame.event.Event(pygame.MOUSEBUTTONUP, pos=renderer._px(0.0, 0.9), button=1))
    p.handle(pygame.event.Event(pygame.MOUSEBUTTONDOWN, pos=renderer._px(-1.5, 0.0), button=1))
    p.handle(pygame.event.Event(pygame.MOUSEBUTTONUP, pos=renderer._px(1.5, 0.0), button=1))
    assert p.aim == pytest.approx([p.cfg.max_speed, 0.0], abs=0.01)
    p.env.close()


def test_the_press_picks_the_nearest_controlled_ball_and_tab_the_next():
    p = player("CollisionEnv/MultiBall-v0")
    assert p.cfg.controlled == (0, 1, 2)
    renderer = p.env.unwrapped._get_renderer()
    p.handle(pygame.event.Event(pygame.MOUSEBUTTONDOWN, pos=renderer._px(*p.env.unwrapped.core.pos[0, 2]), button=1))
    assert p.ball == 2
    p.handle(key(KEY, pygame.K_TAB))
    assert p.ball == 0
    p.handle(key(KEY, pygame.K_DOWN))
    assert p.nudge().tolist() == [[0.0, -1.0], [0.0, 0.0], [0.0, 0.0]]
    p.env.close()


def test_space_steps_once_and_pauses_p_resumes_r_resets_esc_quits():
    p = player("CollisionEnv/Billiards-v0")
    p.handle(key(KEY, pygame.K_SPACE))
    p.tick()
    p.tick()  # paused: a redraw, no step
    assert (p.steps, p.paused) == (1, True)
    p.handle(key(KEY, pygame.K_RETURN))
    p.tick()
    assert p.steps == 2
    p.handle(key(KEY, pygame.K_p))
    p.tick()
    assert (p.steps, p.paused) == (3, False)
    p.handle(key(KEY, pygame.K_r))
    assert p.env.unwrapped.core.steps[0] == 0
    assert not p.quit
    p.handle(key(KEY, pygame.K_ESCAPE))
    assert p.quit
    p.env.close()


def test_an_episode_that_ends_is_reported_and_the_next_begins(capsys):
    p = player("CollisionEnv/OneBallTarget-v0", time_limit=0.2)
    for _ in range(4):
        p.tick()
    assert len(p.episodes) == 1 and p.env.unwrapped.core.steps[0] == 0
    assert capsys.readouterr().out.startswith("episode 1: ")


def test_the_command_plays_until_escape(capsys):
    pygame.display.init()
    for event in (key(KEY, pygame.K_RIGHT), key(KEY, pygame.K_ESCAPE)):
        pygame.event.post(event)
    p = play.main(["CollisionEnv/Line1D-v0", "--seed", "1"])
    assert (p.quit, p.steps) == (True, 1)  # the frame of the escape still takes its step
    assert "arrow keys" in capsys.readouterr().out
    with pytest.raises(SystemExit) as exit_info:
        play.main(["CollisionEnv/Biliards-v0"])
    assert exit_info.value.code == 2
    assert "did you mean 'CollisionEnv/Billiards-v0'?" in capsys.readouterr().err


def test_every_id_plays_a_few_frames(env_id):
    p = player(env_id)
    p.handle(key(KEY, pygame.K_LEFT))
    for _ in range(3):
        p.tick()
    assert p.steps == 3 and np.isfinite(p.episode_return)
    p.env.close()


def test_the_command_takes_any_task_field_as_an_env_keyword(monkeypatch, capsys):
    made = []
    monkeypatch.setattr(play, "play", lambda env_id, **kwargs: made.append({"env_id": env_id, **kwargs}))
    play.main(["CollisionEnv/Billiards-v0", "--mode", "naive", "--dt", "0.1", "--n-targets", "2", "--seed", "4"])
    play.main(["--bounds", "(-1, -1, 1, 1)", "--target-walls", "('left', 'top')"])
    play.main(["CollisionEnv/Line1D-v0", "--window", "None"])  # the preset's time windows off
    assert made == [
        {"env_id": "CollisionEnv/Billiards-v0", "seed": 4, "trails": False, "mode": "naive", "dt": 0.1, "n_targets": 2},
        {
            "env_id": "CollisionEnv/OneBallTarget-v0",
            "seed": None,
            "trails": False,
            "bounds": (-1, -1, 1, 1),
            "target_walls": ("left", "top"),
        },
        {"env_id": "CollisionEnv/Line1D-v0", "seed": None, "trails": False, "window": None},
    ]
    with pytest.raises(SystemExit) as exit_info:
        play.main(["CollisionEnv/Billiards-v0", "--mode", "fastest"])
    assert exit_info.value.code == 2
    assert "mode: expected one of ('naive', 'posteriori', 'exact'), got 'fastest'" in capsys.readouterr().err


def test_help_is_plain_text_and_names_every_field(capsys):
    import dataclasses

    from collision_env.envs import TaskConfig

    with pytest.raises(SystemExit):
        play.main(["--help"])
    out = capsys.readouterr().out
    assert "``" not in out and ":class:" not in out and ":func:" not in out
    assert "as gymnasium.utils.play offers" in out
    for field in dataclasses.fields(TaskConfig):
        if field.init:
            assert f"--{field.name.replace('_', '-')} VALUE" in out
    assert "--mode VALUE          The engine's fidelity mode" in out
    assert play.plain("see :class:`~collision_env.engine.Scene` and ``x``") == "see Scene and x"
