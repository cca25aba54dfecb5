"""Engine test fixtures."""

import pytest

from collision_env.precompile import precompile


@pytest.fixture(scope="session", autouse=True)
def compiled_kernels():
    """Compile the kernels before any test runs: tests that bound a step's time must not time numba."""
    precompile(envs=False)
