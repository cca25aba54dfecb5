"""Environment steps per second for each registered env id and mode, with CartPole as the anchor.

Measured in the same run as the sweep (random actions, resets at episode ends). Returns a string
saying why instead when the environments are not importable or registered.
"""

from __future__ import annotations

import time

from collision_env.envs.registry import bench_scenes

#: env id -> the sweep scene it matches most closely (each task's registry entry names it)
MATCHING_SCENE = bench_scenes()
MODES = (("naive", 1), ("posteriori", 1), ("posteriori", 8), ("exact", 1))


def _rate(make, steps):
    env = make()
    try:
        env.reset(seed=0)
        env.action_space.seed(0)
        actions = [env.action_space.sample() for _ in range(min(steps, 256))]
        def run(n):
            for k in range(n):
                out = env.step(actions[k % len(actions)])
                term, trunc = out[2], out[3]
                if not hasattr(term, "__len__") and (term or trunc):  # vector envs reset themselves
                    env.reset()

        run(min(20, steps))  # warm-up
        t0 = time.perf_counter()
        run(steps)
        return time.perf_counter() - t0
    finally:
        env.close()


def env_rates(quick: bool, log=print):
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
    steps, vsteps, nvec = (300, 30, 64) if quick else (2000, 200, 64)
    rows = []
    anchors = [("CartPole-v1", "anchor", "—")]
    for env_id, scene, mode in anchors:
        single = _rate(lambda env_id=env_id: gym.make(env_id), steps)
        vec = _rate(lambda env_id=env_id: gym.make_vec(env_id, num_envs=nvec, vectorization_mode="vector_entry_point"),
                    vsteps)
        rows.append({"env": env_id, "scene": scene, "mode": mode, "single_steps_per_s": steps / single,
                     "vector_steps_per_s": vsteps * nvec / vec})
    for env_id in ids:
        for mode, k in MODES:
            kw = {"mode": mode, "substeps": k}
            try:
                single = _rate(lambda env_id=env_id, kw=kw: gym.make(env_id, **kw), steps)
                vec = _rate(lambda env_id=env_id, kw=kw: gym.make_vec(
                    env_id, num_envs=nvec, vectorization_mode="vector_entry_point", **kw), vsteps)
            except Exception as exc:  # an env that cannot run a mode is a result
                rows.append({"env": env_id, "scene": MATCHING_SCENE.get(env_id, ""), "mode": f"{mode} k={k}",
                             "single_steps_per_s": float("nan"), "vector_steps_per_s": float("nan"),
                             "note": f"{type(exc).__name__}: {exc}"})
                continue
            label = mode if mode != "posteriori" else f"posteriori k={k}"
            rows.append({"env": env_id, "scene": MATCHING_SCENE.get(env_id, "—"), "mode": label,
                         "single_steps_per_s": steps / single, "vector_steps_per_s": vsteps * nvec / vec})
        log(f"  env {env_id}: done")
    return rows


ENV_FIELDS = ("env", "scene", "mode", "single_steps_per_s", "vector_steps_per_s", "note")
