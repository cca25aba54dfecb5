"""Environment steps per second for each registered env id and mode, with CartPole as the anchor.

Measured in the same run as the sweep with the env benchmark's timers
(:mod:`collision_env.bench.envs`: random actions, resets at episode ends). Returns a string saying
why instead when the environments are not importable or registered.
"""

from __future__ import annotations

from collections.abc import Callable

from collision_env.envs.registry import bench_scenes

from .envs import single_env_us, vector_env_steps_per_s

#: env id -> the sweep scene it matches most closely (each task's registry entry names it)
MATCHING_SCENE = bench_scenes()
MODES = (("naive", 1), ("posteriori", 1), ("posteriori", 8), ("exact", 1))


def _rates(make_single, make_vector, seconds: float) -> tuple[float, float]:
    """Steps per second of a single env and env-steps per second of a vector env, from the env timers."""
    env = make_single()
    try:
        single = 1e6 / single_env_us(env, seconds)
    finally:
        env.close()
    venv = make_vector()
    try:
        return single, vector_env_steps_per_s(venv, seconds)
    finally:
        venv.close()


def env_rates(quick: bool, log: Callable[[str], None] = print) -> list[dict] | str:
    """Rows ``{env, scene, mode, single_steps_per_s, vector_steps_per_s}`` or a string (why not)."""
    try:
        import gymnasium as gym

        import collision_env
    except Exception as exc:  # pragma: no cover - depends on the install
        return f"left out: the environments could not be imported ({type(exc).__name__}: {exc})"
    ids = getattr(collision_env, "ENV_IDS", ())
    ids = [i for i in ids if i in gym.registry]
    if not ids:
        return "left out: no collision_env environment ids are registered yet"
    seconds, nvec = (0.01, 64) if quick else (0.05, 64)

    def vector(env_id, **kw):
        return lambda: gym.make_vec(env_id, num_envs=nvec, vectorization_mode="vector_entry_point", **kw)

    single, vec = _rates(lambda: gym.make("CartPole-v1"), vector("CartPole-v1"), seconds)
    rows = [
        {"env": "CartPole-v1", "scene": "anchor", "mode": "—", "single_steps_per_s": single, "vector_steps_per_s": vec}
    ]
    for env_id in ids:
        for mode, k in MODES:
            kw = {"mode": mode, "substeps": k}
            try:
                single, vec = _rates(lambda env_id=env_id, kw=kw: gym.make(env_id, **kw), vector(env_id, **kw), seconds)
            except Exception as exc:  # an env that cannot run a mode is a result
                rows.append(
                    {
                        "env": env_id,
                        "scene": MATCHING_SCENE.get(env_id, ""),
                        "mode": f"{mode} k={k}",
                        "single_steps_per_s": float("nan"),
                        "vector_steps_per_s": float("nan"),
                        "note": f"{type(exc).__name__}: {exc}",
                    }
                )
                continue
            label = mode if mode != "posteriori" else f"posteriori k={k}"
            rows.append(
                {
                    "env": env_id,
                    "scene": MATCHING_SCENE.get(env_id, "—"),
                    "mode": label,
                    "single_steps_per_s": single,
                    "vector_steps_per_s": vec,
                }
            )
        log(f"  env {env_id}: done")
    return rows


ENV_FIELDS = ("env", "scene", "mode", "single_steps_per_s", "vector_steps_per_s", "note")
