"""Frames of a task scene, drawn on an off-screen pygame surface (no display needed).

A frame shows the play area, the targets on the walls (pending in amber, waiting for their time
window in dim amber, hit in green, failed in grey), the balls (controlled ones ringed in white,
balls whose impacts score marked with a dot, stuck clusters joined by a bar) with velocity arrows,
a flash at the exact contact point of every impact (green on a target, red elsewhere on a wall,
white between balls) and, optionally, ball trails. In a crowd (more than ``CROWD`` balls) only the
controlled and scoring balls get arrows, trails and flashes; the others are drawn as a plain gas.
A bar on top shows the time used, the time windows and the targets. ``rgb_array`` frames are
``(H, W, 3)`` uint8; ``human`` opens a window (off-screen on a Linux machine without a display).
"""

from __future__ import annotations

import math
import os
import sys
from typing import TYPE_CHECKING, Any

import numpy as np

from collision_env.engine.scene import WALL_BOTTOM, WALL_LEFT, WALL_RIGHT
from collision_env.envs.task.layout import TARGET_FAILED, TARGET_GEOMETRY, TARGET_HIT, TARGET_PENDING
from collision_env.extras import require

if TYPE_CHECKING:
    from collision_env.envs._config import TaskConfig
    from collision_env.envs._core import TaskCore

#: Above this many balls, balls that are neither controlled nor scoring are drawn plain (a gas).
CROWD = 16
BG = (18, 22, 34)
AREA = (30, 37, 56)
WALL = (200, 204, 214)
PENDING = (255, 172, 40)
WAITING = (125, 95, 45)
HIT = (70, 220, 120)
FAILED = (110, 110, 118)
ARROW = (235, 238, 245)
CONTROLLED = (255, 214, 70)
PALETTE = [
    (232, 74, 95),
    (80, 170, 255),
    (170, 120, 255),
    (90, 215, 200),
    (255, 130, 60),
    (150, 210, 90),
    (240, 110, 200),
    (120, 140, 255),
]
FLASH_LIFE = 0.4  # s of simulated time


def _pygame():
    os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")
    require("render", "rendering")
    import pygame
    import pygame.gfxdraw

    return pygame


def headless_video_driver() -> None:
    """Before a window opens: on Linux without a display (neither ``DISPLAY`` nor ``WAYLAND_DISPLAY``
    set), tell SDL to draw it off-screen, which is where SDL ends up on such a machine anyway, but
    only after probing Wayland, whose client library prints ``error: XDG_RUNTIME_DIR is invalid or
    not set in the environment.`` A driver chosen in ``SDL_VIDEODRIVER`` is kept."""
    if sys.platform.startswith("linux") and not os.environ.get("DISPLAY") and not os.environ.get("WAYLAND_DISPLAY"):
        os.environ.setdefault("SDL_VIDEODRIVER", "offscreen")


def _fade(colour, f):
    return tuple(int(round(b + (c - b) * f)) for c, b in zip(colour, AREA, strict=True))


class Renderer:
    """Draws scene ``b`` of a :class:`~collision_env.envs._core.TaskCore`."""

    def __init__(
        self,
        cfg: TaskConfig,
        trails: bool = False,
        ppm: float = 150.0,
        margin: int = 26,
        bar: int = 26,
        trail_length: int = 40,
    ) -> None:
        self.pg = _pygame()
        self.cfg = cfg
        self.trails = trails
        self.trail_length = trail_length
        self.ppm = ppm
        self.margin = margin
        self.bar = bar
        assert cfg.bounds is not None  # (None only as an argument of TaskConfig)
        self.bounds: tuple[float, float, float, float] = cfg.bounds
        xmin, ymin, xmax, ymax = self.bounds
        self.width = int(round((xmax - xmin) * ppm)) + 2 * margin
        self.height = int(round((ymax - ymin) * ppm)) + 2 * margin + bar
        self.surf = self.pg.Surface((self.width, self.height))
        self.window: Any = None  # pygame's display surface and clock, once shown (pygame is imported lazily)
        self.clock: Any = None
        self.start()

    # ------------------------------------------------------------------------------------- #
    def start(self) -> None:
        """Forget trails and flashes (a new episode)."""
        self._trail: list = []
        self._flashes: list = []

    def record(self, core: TaskCore, b: int, imp: np.ndarray) -> None:
        """Remember this step's impacts of scene ``b`` (flashes) and the balls' positions (trails)."""
        if self.trails:
            self._trail.append(core.pos[b].copy())
            del self._trail[: -self.trail_length]
        for r in imp[imp["scene"] == b] if len(imp) else ():
            balls = (int(r["ball"]), int(r["other"]))
            self._flashes.append((float(r["time"]), float(r["x"]), float(r["y"]), int(r["wall"]), balls))
        now = float(core.time[b])
        self._flashes = [f for f in self._flashes if now - f[0] <= FLASH_LIFE]

    # ------------------------------------------------------------------------------------- #
    def _px(self, x, y):
        xmin, ymin, xmax, ymax = self.bounds
        return (self.margin + (x - xmin) * self.ppm, self.bar + self.margin + (ymax - y) * self.ppm)

    def to_world(self, px: float, py: float) -> tuple[float, float]:
        """The point (m) that the frame's pixel (``px``, ``py``) shows (the inverse of the drawing's mapping)."""
        xmin, ymin, xmax, ymax = self.bounds
        return (xmin + (px - self.margin) / self.ppm, ymax - (py - self.bar - self.margin) / self.ppm)

    def _segment_px(self, wall, c, hw, out=5):
        xmin, ymin, xmax, ymax = self.bounds
        if wall == WALL_LEFT:
            a, b_, d = self._px(xmin, c - hw), self._px(xmin, c + hw), (-out, 0)
        elif wall == WALL_RIGHT:
            a, b_, d = self._px(xmax, c - hw), self._px(xmax, c + hw), (out, 0)
        elif wall == WALL_BOTTOM:
            a, b_, d = self._px(c - hw, ymin), self._px(c + hw, ymin), (0, out)
        else:
            a, b_, d = self._px(c - hw, ymax), self._px(c + hw, ymax), (0, -out)
        return (a[0] + d[0], a[1] + d[1]), (b_[0] + d[0], b_[1] + d[1])

    def _on_hit_target(self, core, b, wall, x, y):
        s = y if wall in (WALL_LEFT, WALL_RIGHT) else x
        geo = TARGET_GEOMETRY
        for k in range(core.t_wall.shape[1]):
            on_segment = abs(s - core.target_geo[b, k, geo.centre]) <= core.target_geo[b, k, geo.half_width]
            if core.t_status[b, k] == TARGET_HIT and core.t_wall[b, k] == wall and on_segment:
                return True
        return False

    def draw(self, core: TaskCore, b: int) -> np.ndarray:
        pg = self.pg
        gfx = pg.gfxdraw
        surf = self.surf
        cfg = self.cfg
        xmin, ymin, xmax, ymax = self.bounds
        now = float(core.time[b])
        surf.fill(BG)
        x0, y0 = self._px(xmin, ymax)
        x1, y1 = self._px(xmax, ymin)
        pg.draw.rect(surf, AREA, pg.Rect(int(x0), int(y0), int(round(x1 - x0)), int(round(y1 - y0))))
        pg.draw.rect(surf, WALL, pg.Rect(int(x0) - 1, int(y0) - 1, int(round(x1 - x0)) + 2, int(round(y1 - y0)) + 2), 2)

        # targets
        n_t = core.t_wall.shape[1]
        cur = int(core.cur[b])
        for k in range(n_t):
            st = int(core.t_status[b, k])
            if cfg.sequential and st == TARGET_PENDING and k != cur:
                continue  # later targets of a sequence are not shown yet
            c, hw, t_open, t_close = core.target_geo[b, k]
            if st == TARGET_HIT:
                col = HIT
            elif st == TARGET_FAILED:
                col = FAILED
            else:
                col = PENDING if t_open <= now <= t_close else WAITING
            a, e = self._segment_px(int(core.t_wall[b, k]), c, hw)
            pg.draw.line(surf, col, a, e, 8)

        pos, vel, radii = core.pos[b], core.vel[b], core.radii[b]
        n = pos.shape[0]
        featured = [n <= CROWD or i in cfg.controlled or bool(core.scoring[i]) for i in range(n)]

        # trails
        if self.trails and len(self._trail) > 1:
            pts = np.array(self._trail)
            for i in range(pts.shape[1]):
                if not featured[i]:
                    continue
                col = CONTROLLED if i in cfg.controlled else PALETTE[i % len(PALETTE)]
                for j in range(1, len(pts)):
                    f = 0.15 + 0.5 * j / len(pts)
                    pg.draw.line(surf, _fade(col, f), self._px(*pts[j - 1, i]), self._px(*pts[j, i]), 2)

        # clusters (stick scenes): a bar between stuck balls
        body = core.body[b]
        for i in range(n):
            for j in range(i + 1, n):
                if body[i] == body[j]:
                    pg.draw.line(surf, WALL, self._px(*pos[i]), self._px(*pos[j]), 4)

        # balls
        qual = core.scoring
        cluster_mode = cfg.scorers == "cluster"
        for i in range(n):
            cx, cy = self._px(*pos[i])
            r = max(2, int(round(radii[i] * self.ppm)))
            col = CONTROLLED if i in cfg.controlled else PALETTE[i % len(PALETTE)]
            if cfg.radius == "constant" and i in cfg.controlled and cfg.scorers == "others":
                col = (240, 240, 240)  # a cue ball
            ix, iy = int(round(cx)), int(round(cy))
            gfx.filled_circle(surf, ix, iy, r, col)
            gfx.aacircle(surf, ix, iy, r, col)
            if i in cfg.controlled:
                gfx.aacircle(surf, ix, iy, r + 2, (255, 255, 255))
                gfx.aacircle(surf, ix, iy, r + 3, (255, 255, 255))
            scoring = qual[i] and (not cluster_mode or (body == body[i]).sum() > 1)
            if scoring and not (i in cfg.controlled and cfg.scorers == "any"):
                gfx.filled_circle(surf, ix, iy, max(2, r // 4), (20, 20, 20))
        for i in range(n):  # velocity arrows on top
            vx, vy = vel[i]
            speed = math.hypot(vx, vy)
            if speed < 1e-9 or not featured[i]:
                continue
            L = 0.5 * speed * self.ppm  # where the ball will be in 0.5 s
            ux, uy = vx / speed, -vy / speed
            cx, cy = self._px(*pos[i])
            tip = (cx + ux * L, cy + uy * L)
            pg.draw.line(surf, ARROW, (cx, cy), tip, 2)
            h = min(10.0, 0.4 * L)
            left = (tip[0] - h * ux + 0.5 * h * uy, tip[1] - h * uy - 0.5 * h * ux)
            right = (tip[0] - h * ux - 0.5 * h * uy, tip[1] - h * uy + 0.5 * h * ux)
            pg.draw.polygon(surf, ARROW, [tip, left, right])

        # impact flashes at the exact contact points
        for t, x, y, wall, balls in self._flashes:
            age = now - t
            if age < 0 or age > FLASH_LIFE or not any(i >= 0 and featured[i] for i in balls):
                continue
            f = 1.0 - age / FLASH_LIFE
            if wall < 0:
                col = (255, 255, 255)
            else:
                col = HIT if self._on_hit_target(core, b, wall, x, y) else (255, 80, 80)
            px, py = self._px(x, y)
            rr = int(round(5 + 22 * (1.0 - f)))
            colf = _fade(col, f)
            gfx.aacircle(surf, int(round(px)), int(round(py)), rr, colf)
            gfx.aacircle(surf, int(round(px)), int(round(py)), rr + 1, colf)
            gfx.filled_circle(surf, int(round(px)), int(round(py)), 3, colf)

        # status bar: time used, time windows, targets
        steps = int(core.steps[b])
        frac = min(1.0, steps / cfg.n_steps)
        bx, by, bw, bh = self.margin, 8, self.width - 2 * self.margin - 16 * n_t - 8, 10
        pg.draw.rect(surf, AREA, pg.Rect(bx, by, bw, bh))
        for k in range(n_t):
            t_open, t_close = (
                core.target_geo[b, k, TARGET_GEOMETRY.opens],
                core.target_geo[b, k, TARGET_GEOMETRY.closes],
            )
            if t_open > -1e299:
                u0 = bx + bw * max(0.0, t_open / cfg.time_limit)
                u1 = bx + bw * min(1.0, t_close / cfg.time_limit)
                st = int(core.t_status[b, k])
                col = HIT if st == TARGET_HIT else FAILED if st == TARGET_FAILED else WAITING
                pg.draw.rect(surf, col, pg.Rect(int(u0), by, max(1, int(u1 - u0)), bh))
        pg.draw.rect(surf, (120, 170, 255), pg.Rect(bx, by + bh // 2 - 1, int(bw * frac), 3))
        for k in range(n_t):
            st = int(core.t_status[b, k])
            col = HIT if st == TARGET_HIT else FAILED if st == TARGET_FAILED else PENDING
            pg.draw.rect(surf, col, pg.Rect(bx + bw + 8 + 16 * k, by - 1, 12, 12))

        frame = pg.surfarray.array3d(surf)
        return np.ascontiguousarray(frame.transpose(1, 0, 2))

    # ------------------------------------------------------------------------------------- #
    def show(self, frame: np.ndarray, fps: int) -> None:
        pg = self.pg
        if self.window is None:
            headless_video_driver()
            pg.display.init()
            pg.display.set_caption("collision_env")
            self.window = pg.display.set_mode((self.width, self.height))
            self.clock = pg.time.Clock()
        self.window.blit(self.surf, (0, 0))
        pg.event.pump()
        pg.display.update()
        self.clock.tick(fps)

    def close(self) -> None:
        if self.window is not None:
            self.pg.display.quit()
            self.window = None
