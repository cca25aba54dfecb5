"""Every env id in every engine mode, and engine scenes reaching every kernel path, replay the
rollouts recorded in ``tests/data/rollouts.npz`` bit for bit (see ``tests/rollouts.py``)."""

import numpy as np
import pytest

from tests import rollouts


@pytest.fixture(scope="module")
def replayed():
    return rollouts.record()


@pytest.fixture(scope="module")
def recorded():
    with np.load(rollouts.PATH) as data:
        return dict(data)


def test_every_rollout_is_recorded(replayed, recorded):
    assert sorted(replayed) == sorted(recorded)


@pytest.mark.parametrize("group", ["env/", "vector/", "engine/"])
def test_rollouts_replay_bit_for_bit(replayed, recorded, group):
    keys = [k for k in recorded if k.startswith(group)]
    assert keys
    differ = [k for k in keys if not np.array_equal(replayed[k], recorded[k])]
    assert not differ, f"{len(differ)} of {len(keys)} arrays differ from the recording, first {differ[:5]}"
