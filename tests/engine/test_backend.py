"""The compiled kernels and their plain-Python form (no numba installed) give the same results."""

import json
import os
import subprocess
import sys

import numpy as np

from collision_env.engine import BACKEND, Scene, Simulator

SCRIPT = """
import json, numpy as np
from collision_env.engine import BACKEND, Scene, Simulator
rng = np.random.default_rng(5)
pos = np.array([[-1.5, -0.5], [-0.5, 0.4], [0.6, -0.3], [1.4, 0.5]])
out = {"backend": BACKEND}
for mode, e, inelastic in [("exact", 1.0, "slip"), ("exact", 0.0, "stick"), ("posteriori", 0.5, "slip"),
                           ("naive", 1.0, "slip")]:
    sim = Simulator(Scene(elasticity=e, inelastic=inelastic), pos, rng.normal(size=(4, 2)) * 2,
                    [0.5, 1.5, 1.0, 2.0], mode=mode)
    impacts = [[h.time, h.ball, h.point[0], h.point[1]] for _ in range(30) for h in sim.step(0.05)]
    out[mode + inelastic] = [sim.positions.tolist(), sim.velocities.tolist(), impacts]
print(json.dumps(out))
"""


def run(disable_jit):
    env = dict(os.environ, NUMBA_DISABLE_JIT="1" if disable_jit else "0")
    done = subprocess.run([sys.executable, "-c", SCRIPT], env=env, capture_output=True, text=True, check=True)
    return json.loads(done.stdout)


def test_python_fallback_matches_compiled_kernels():
    compiled, python = run(False), run(True)
    assert python.pop("backend") == "python"
    assert compiled.pop("backend") == BACKEND
    assert compiled.keys() == python.keys()
    for key in compiled:
        for a, b in zip(compiled[key], python[key], strict=True):
            np.testing.assert_allclose(np.array(a, dtype=float), np.array(b, dtype=float), rtol=1e-12, atol=1e-12)
    assert any(len(v[2]) for v in compiled.values())  # the scenes did collide


def test_models_report_what_the_scene_needs():
    one = Simulator(Scene(bounds=None), [[0, 0]], [[1, 0]], [1.0])
    assert one.models | {"backend": None} == {
        "mode": "exact",
        "substeps": 1,
        "dimension": 2,
        "walls": False,
        "ball_pairs": False,
        "clusters": False,
        "backend": None,
    }
    stick = Simulator(
        Scene(elasticity=0, inelastic="stick", dimension=1, bounds=(-2, -0.5, 2, 0.5)),
        [[-1, 0], [1, 0]],
        [[1, 0], [0, 0]],
        [1, 1],
        mode="naive",
        substeps=3,
    )
    assert stick.models["clusters"] and stick.models["ball_pairs"] and stick.models["dimension"] == 1
    assert not Simulator(
        Scene(elasticity=0, inelastic="stick", ball_collisions=False), [[-1, 0], [1, 0]], [[1, 0], [0, 0]], [1, 1]
    ).models["clusters"]
