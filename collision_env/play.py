"""Play any id by hand in a pygame window, as ``gymnasium.utils.play`` offers for Gymnasium's envs.

    python -m collision_env.play CollisionEnv/Billiards-v0
    python -m collision_env.play CollisionEnv/Line1D-v0 --seed 3 --trails
    python -m collision_env.play CollisionEnv/Billiards-v0 --mode naive --dt 0.1 --n-targets 2

Any ``TaskConfig`` field is an option (``--n-targets 2`` sets ``n_targets``), read as a Python
literal (``--bounds "(-1, -1, 1, 1)"``) or else as a string (``--mode naive``).

The env runs in real time (its control step ``dt`` per frame). You steer one of the controlled
balls (ringed in white) at a time:

Controls:

    arrow keys (held)    nudge the ball: each step changes its velocity by max_dv along the arrows
                         (left and right only, in 1D)
    click and drag       aim: the drag (m) is the velocity (m/s) the ball is nudged to, step by step,
                         up to max_speed; the press picks the controlled ball nearest the pointer
    Tab                  steer the next controlled ball
    Space or Enter       take one step and pause (again: one more step)
    P                    pause or resume
    R                    start a new episode
    Esc, closing window  quit

Nudges are planned as the scripted policies plan them (velocity changes over ``max_dv``) and sent
in the form the env's ``control`` reads (``collision_env.envs.scripted.as_env_action``), so the
velocity-control tasks play alike. An episode that ends prints its return and starts the next.
Needs pygame (the ``render`` extra).
"""

from __future__ import annotations

import argparse
import ast
import dataclasses
import difflib
import inspect
import re
from typing import TYPE_CHECKING, Any, cast

import numpy as np

if TYPE_CHECKING:
    import gymnasium as gym

    from collision_env.envs import CollisionTargetEnv

#: The keys and the mouse, as the module's docstring lists them (printed when the game starts).
CONTROLS = __doc__[__doc__.index("Controls:") : __doc__.index("\n\nNudges")]
#: An aim is reached when the ball's velocity is this close to it on each axis (m/s).
AIMED = 1e-6
#: The nudge direction (x, y) of each arrow key, by pygame key name.
ARROWS = {"left": (-1.0, 0.0), "right": (1.0, 0.0), "up": (0.0, 1.0), "down": (0.0, -1.0)}


class Player:
    """The game loop's state, fed pygame events (:meth:`handle`) and advanced a frame at a time
    (:meth:`tick`); :func:`play` drives it from pygame's event queue."""

    def __init__(self, env: gym.Env, seed: int | None = None) -> None:
        import pygame

        from collision_env.envs.scripted import as_env_action, towards

        self.pg = pygame
        """The pygame module (imported when a player is made: the ``render`` extra)."""
        self._as_action, self._towards = as_env_action, towards
        self.env = env
        """The env played, made with ``render_mode="human"``."""
        self._bare = cast("CollisionTargetEnv", env.unwrapped)  # the task env under the wrappers
        self.cfg = self._bare.config
        """The env's ``TaskConfig``."""
        self.held: set[str] = set()
        """The arrow keys held down, by pygame key name."""
        self.ball = 0
        """Index into ``cfg.controlled`` of the steered ball."""
        self.aim: np.ndarray | None = None
        """The velocity the steered ball is being nudged to (after a drag), or ``None``."""
        self._press: np.ndarray | None = None  # world point of a mouse press, until it is released
        self.paused = False
        """Whether the game is paused."""
        self.pending = 0
        """Single steps asked for while paused."""
        self.quit = False
        """Set by Esc or by closing the window."""
        self.steps = 0
        """Steps taken in the current episode."""
        self.episode_return = 0.0
        """The current episode's return so far."""
        self.episodes: list[dict] = []
        """One summary per finished episode: its ``return``, ``success`` and ``targets`` hit."""
        env.reset(seed=seed)

    # ------------------------------------------------------------------------------------ input
    def handle(self, event: Any) -> None:
        """Take one pygame event into account."""
        pg = self.pg
        if event.type == pg.QUIT:
            self.quit = True
        elif event.type in (pg.KEYDOWN, pg.KEYUP):
            name = pg.key.name(event.key)
            if name in ARROWS:
                (self.held.add if event.type == pg.KEYDOWN else self.held.discard)(name)
                self.aim = None  # the keys take over from an aim
            elif event.type == pg.KEYUP:
                return
            elif event.key == pg.K_ESCAPE:
                self.quit = True
            elif event.key in (pg.K_SPACE, pg.K_RETURN, pg.K_KP_ENTER):
                self.paused = True
                self.pending += 1
            elif event.key == pg.K_p:
                self.paused = not self.paused
            elif event.key == pg.K_r:
                self.reset()
            elif event.key == pg.K_TAB:
                self.ball = (self.ball + 1) % len(self.cfg.controlled)
                self.aim = None
        elif event.type == pg.MOUSEBUTTONDOWN and event.button == 1:
            self._press = np.array(self._world(event.pos))
            pos = self._bare.core.pos[0, list(self.cfg.controlled)]
            self.ball = int(np.argmin(np.linalg.norm(pos - self._press, axis=1)))
        elif event.type == pg.MOUSEBUTTONUP and event.button == 1 and self._press is not None:
            drag = np.array(self._world(event.pos)) - self._press
            if self.cfg.dimension == 1:
                drag[1] = 0.0
            self.aim = drag * min(1.0, self.cfg.max_speed / max(float(np.linalg.norm(drag)), 1e-12))
            self._press = None

    def _world(self, pixel) -> tuple[float, float]:
        return self._bare._get_renderer().to_world(*pixel)

    # ------------------------------------------------------------------------------------ steps
    def nudge(self) -> np.ndarray:
        """This step's nudge (velocity changes over ``max_dv``, one row per controlled ball)."""
        cfg = self.cfg
        out = np.zeros((len(cfg.controlled), cfg.dimension), np.float32)
        if self.held:
            out[self.ball] = np.sum([ARROWS[k] for k in self.held], axis=0)[: cfg.dimension]
        elif self.aim is not None:
            v = self._bare.core.vel[0, cfg.controlled[self.ball], : cfg.dimension]
            if np.abs(self.aim[: cfg.dimension] - v).max() <= AIMED:
                self.aim = None  # reached
            else:
                out[self.ball] = self._towards(self.env, self.aim[: cfg.dimension], v)
        return np.clip(out, -1.0, 1.0)

    def tick(self) -> None:
        """One frame: a step if running (or one was asked for while paused), else a redraw."""
        if self.paused and not self.pending:
            self.env.render()
            return
        self.pending = max(0, self.pending - 1)
        action = self._as_action(self.env, self.nudge().ravel())
        _, reward, terminated, truncated, info = self.env.step(action)
        self.steps += 1
        self.episode_return += float(reward)
        if terminated or truncated:
            self.episodes.append(
                {"return": self.episode_return, "success": bool(info["is_success"]), "targets": info["targets_hit"]}
            )
            end = "success" if info["is_success"] else "ended" if terminated else "time up"
            print(f"episode {len(self.episodes)}: {end}, return {self.episode_return:.2f}, {info['targets_hit']} hit")
            self.reset()
        self.pg.display.set_caption(self.caption())

    def reset(self) -> None:
        """Start a new episode (R, or when one ends)."""
        self.env.reset()
        self.episode_return = 0.0
        self.aim = None

    def caption(self) -> str:
        """The window's title: the id, the steered ball, running or paused, the episode's return."""
        ball = self.cfg.controlled[self.ball]
        state = "paused" if self.paused else "running"
        env_id = self.env.spec.id if self.env.spec is not None else "..."
        return f"{env_id}: ball {ball}, return {self.episode_return:.2f}, {state}"


def play(env_id: str, seed: int | None = None, trails: bool = False, **env_kwargs: Any) -> Player:
    """Open ``env_id``'s window and play until Esc or the window closes; returns the final state."""
    import gymnasium as gym

    import collision_env  # noqa: F401  (registers the ids)

    env = gym.make(env_id, render_mode="human", trails=trails, **env_kwargs)
    player = Player(env, seed=seed)
    pg = player.pg
    pg.display.set_caption(player.caption())
    try:
        while not player.quit:
            for event in pg.event.get():
                player.handle(event)
            player.tick()
    finally:
        env.close()
    return player


def plain(text: str) -> str:
    """reStructuredText markup as plain text, for the terminal: ````code```` and
    ``:class:`~a.B``` lose their markup (the role's target keeps its last part with ``~``)."""
    text = re.sub(r":\w+:`~[\w.]*?(\w+)`", r"\1", text)
    text = re.sub(r":\w+:`([^`]*)`", r"\1", text)
    return re.sub(r"``([^`]*)``", r"\1", text)


def field_help() -> dict[str, str]:
    """Each ``TaskConfig`` field's first sentence, from its docstring in the source (plain text)."""
    from collision_env.envs import TaskConfig

    tree = ast.parse(inspect.cleandoc("\n" + inspect.getsource(TaskConfig)))
    body = tree.body[0].body  # type: ignore[attr-defined]
    out = {}
    for node, after in zip(body, body[1:], strict=False):
        doc = getattr(getattr(after, "value", None), "value", None)
        if isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name) and isinstance(doc, str):
            first = " ".join(inspect.cleandoc(doc).split("\n\n")[0].split())
            out[node.target.id] = plain(first.split(". ")[0].rstrip("."))
    return out


def env_value(text: str) -> Any:
    """An option's value: a Python literal (``0.1``, ``(1, 2)``, ``None``, ``True``), else the string."""
    try:
        return ast.literal_eval(text)
    except (ValueError, SyntaxError):
        return text


def build_parser() -> argparse.ArgumentParser:
    """The command line of ``python -m collision_env.play``: the id, ``--seed``, ``--trails`` and one
    option per ``TaskConfig`` field."""
    from collision_env.envs import TaskConfig

    p = argparse.ArgumentParser(
        prog="python -m collision_env.play",
        usage="%(prog)s [env_id] [--seed SEED] [--trails] [--FIELD VALUE ...]",
        description=plain(__doc__.split("\n\n")[0]),
        formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog=CONTROLS,
    )
    p.add_argument("env_id", nargs="?", default="CollisionEnv/OneBallTarget-v0", help="default: %(default)s")
    p.add_argument("--seed", type=int, help="the first episode's seed (default: random)")
    p.add_argument("--trails", action="store_true", help="draw the balls' trails")
    fields = p.add_argument_group("env keywords (any TaskConfig field; default: the id's)")
    helps = field_help()
    for f in dataclasses.fields(TaskConfig):
        if f.init:
            flag = "--" + f.name.replace("_", "-")
            text = helps.get(f.name, "").replace("%", "%%")  # (argparse formats help with %)
            fields.add_argument(
                flag, dest=f.name, type=env_value, metavar="VALUE", help=text, default=argparse.SUPPRESS
            )
    return p


def main(argv: list[str] | None = None) -> Player:
    """``python -m collision_env.play``: check the id and the env keywords (a mistake is one line),
    then :func:`play`; returns the final state."""
    parser = build_parser()
    args = parser.parse_args(argv)
    import gymnasium as gym

    import collision_env

    if args.env_id not in collision_env.ENV_IDS:
        close = difflib.get_close_matches(args.env_id, collision_env.ENV_IDS, n=1, cutoff=0.4)
        hint = f"; did you mean {close[0]!r}?" if close else ""
        parser.error(f"unknown env id {args.env_id!r}{hint} (registered: {', '.join(collision_env.ENV_IDS)})")
    env_kwargs = {k: v for k, v in vars(args).items() if k not in ("env_id", "seed", "trails")}  # (those given)
    try:  # a bad keyword value is one line, before the window opens
        gym.make(args.env_id, **env_kwargs).close()
    except (TypeError, ValueError) as err:
        parser.error(f"{args.env_id}: {err}")
    print(CONTROLS)
    return play(args.env_id, seed=args.seed, trails=args.trails, **env_kwargs)


if __name__ == "__main__":
    from collision_env.extras import run_entry_point

    run_entry_point(main, "collision_env.play", extras=("render",))
