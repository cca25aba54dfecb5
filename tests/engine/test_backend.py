"""The compiled kernels and their plain-Python form (no numba installed) give the same results."""

import json
import os
import platform
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from collision_env.engine import BACKEND, Scene, Simulator
from collision_env.engine._jit import HAVE_NUMBA, PYTHON_SLOWDOWN, _numba, prefetch
from collision_env.engine.layout import CAL_RECORD

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
        "periodic": False,
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


def _prefetched_sum(rec, rows, k):
    """Prefetch elements of a record array (the last one among them) and of a 2-D array (with a
    tuple index, the last column among them), then read some."""
    prefetch(rec, k)
    prefetch(rec, rec.shape[0] - 1)
    prefetch(rows, (k, 0))
    prefetch(rows, (0, rows.shape[1] - 1))
    return rec[k]["x"] + rows[k, 0] + rows[0, rows.shape[1] - 1]


def test_prefetch_is_a_hint_that_changes_nothing():
    rec = np.zeros(5, CAL_RECORD)
    rec["x"] = np.arange(5.0)
    rows = np.arange(35, dtype=np.int32).reshape(5, 7)
    before = rec.copy(), rows.copy()
    kernel = _numba.njit(_prefetched_sum) if HAVE_NUMBA else _prefetched_sum  # (not cached: its code is inspected)
    assert kernel(rec, rows, 3) == 3.0 + 21 + 6
    assert (rec == before[0]).all() and (rows == before[1]).all()
    if HAVE_NUMBA and platform.machine() in ("x86_64", "AMD64"):
        (signature,) = kernel.signatures
        assert "prefetcht0" in kernel.inspect_asm(signature)  # the hint reaches the machine code


@pytest.mark.skipif(not HAVE_NUMBA, reason="typing is numba's")
def test_prefetch_wants_one_integer_per_axis():
    from numba.core.errors import TypingError

    @_numba.njit
    def row_only(rows):
        prefetch(rows, 1)

    with pytest.raises(TypingError):
        row_only(np.zeros((2, 2)))


def test_without_numba_the_engine_runs_as_python_with_one_warning_that_says_what_to_install(tmp_path):
    """A platform without numba's wheels installs the package without it: the envs still run, and
    one warning (not one per kernel or per env) says how much slower and what to install."""
    code = (
        "import sys, warnings\n"
        "sys.modules['numba'] = None\n"  # as if it could not be installed
        "warnings.simplefilter('always')\n"
        "import gymnasium as gym\n"
        "import collision_env\n"
        "from collision_env.engine import BACKEND, Scene, Simulator\n"
        "for _ in range(2):\n"
        "    env = gym.make('CollisionEnv/OneBallTarget-v0')\n"
        "    env.reset(seed=0)\n"
        "    env.step(env.action_space.sample())\n"
        "Simulator(Scene(), [[0.0, 0.0]], [[1.0, 0.0]], [1.0]).step(3.0)\n"
        "print(BACKEND)\n"
    )
    root = str(Path(__file__).resolve().parents[2])
    env = {**os.environ, "PYTHONPATH": root, "NUMBA_DISABLE_JIT": "0"}
    done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "python"
    warnings = [line for line in done.stderr.splitlines() if "SlowBackendWarning" in line]
    assert len(warnings) == 1, done.stderr
    assert f"{PYTHON_SLOWDOWN} times slower" in warnings[0] and "pip install numba" in warnings[0]


def test_the_slowdown_the_warning_states_is_the_measured_one():
    """``PYTHON_SLOWDOWN`` is the figure ``python -m collision_env.bench.backend`` measured (within
    a factor of 1.5: it is a guide, rounded, and the machines are noisy)."""
    page = (Path(__file__).resolve().parents[2] / "docs" / "bench" / "backend.md").read_text()
    measured = float(re.search(r"plain Python is \*\*([\d,.]+)×\*\* slower", page)[1].replace(",", ""))
    assert measured / 1.5 <= PYTHON_SLOWDOWN <= measured * 1.5
