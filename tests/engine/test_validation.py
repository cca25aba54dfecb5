"""Bad input: a ValueError that names the ball and the field, and the state left as it was."""

import dataclasses
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from collision_env.engine import BatchSimulator, Scene, Simulator, SimulatorState

GOOD = dict(positions=[[-1.0, 0.0], [1.0, 0.0]], velocities=[[1.0, 0.0], [-1.0, 0.0]], masses=[1.0, 2.0])


def make(**changes):
    kw = {**GOOD, **changes}
    scene = kw.pop("scene", Scene())
    return Simulator(scene, kw.pop("positions"), kw.pop("velocities"), kw.pop("masses"), **kw)


@pytest.mark.parametrize(
    "changes, message",
    [
        (dict(positions=[[-1.0, math.nan], [1.0, 0.0]]), "ball 0: position must be finite"),
        (dict(velocities=[[1.0, 0.0], [math.inf, 0.0]]), "ball 1: velocity must be finite"),
        (dict(masses=[1.0, 0.0]), "ball 1: mass must be positive"),
        (dict(masses=[-1.0, 1.0]), "ball 0: mass must be positive"),
        (dict(masses=[1.0, math.nan]), "ball 1: mass must be positive"),
        (dict(radii=[0.1, -0.1]), "ball 1: radius must be positive"),
        (dict(positions=[[-1.0, 0.0], [-0.9, 0.0]]), "ball 0: position overlaps ball 1"),
        (dict(positions=[[-1.95, 0.0], [1.0, 0.0]]), "ball 0: position must keep the ball inside"),
        (dict(positions=[[-1.0, 0.0], [1.0, 0.95]]), "ball 1: position must keep the ball inside"),
        (dict(positions=[[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0]]), "positions: expected shape"),
        (dict(velocities=[[1.0, 0.0]]), "velocities: expected shape"),
        (dict(masses=[1.0, 2.0, 3.0]), "masses: expected shape"),
        (
            dict(scene=Scene(dimension=1, bounds=(-2, -0.55, 2, 0.55)), velocities=[[1, 0.5], [0, 0]]),
            "ball 0: velocity y must be 0 in a 1D scene",
        ),
        (
            dict(scene=Scene(dimension=1, bounds=(-2, -0.55, 2, 0.55)), positions=[[-1, 0], [1, 0.1]]),
            "ball 1: position y must be 0 in a 1D scene",
        ),
        (dict(mode="fast"), "mode: must be one of"),
        (dict(substeps=0), "substeps: must be a positive integer"),
        (dict(substeps=4), "substeps: exact mode"),
        (dict(max_events=0), "max_events"),
        (dict(radii="big"), "radii: expected None, 'constant'"),
    ],
)
def test_construction_rejects_bad_input(changes, message):
    with pytest.raises(ValueError, match=message):
        make(**changes)


@pytest.mark.parametrize(
    "kwargs, message",
    [
        (dict(elasticity=1.5), "elasticity: must lie in"),
        (dict(elasticity=-0.1), "elasticity: must lie in"),
        (dict(elasticity=math.nan), "elasticity: must lie in"),
        (dict(dimension=3), "dimension: must be 1 or 2"),
        (dict(inelastic="glue"), "inelastic: must be"),
        (dict(bounds=(2, -1, -2, 1)), "bounds: need xmin < xmax"),
        (dict(bounds=(0, 0, math.inf, 1)), "bounds: expected four finite numbers"),
        (dict(bounds=(-1e151, -1, 1, 1)), r"bounds: expected four finite numbers within 1e\+150 m"),
    ],
)
def test_scene_rejects_bad_input(kwargs, message):
    with pytest.raises(ValueError, match=message):
        Scene(**kwargs)


def test_touching_balls_are_allowed():
    sim = make(positions=[[-1.0, 0.0], [-1.0 + 2 * 0.2, 0.0]], radii=[0.2, 0.2])
    assert sim.step(0.1)  # they collide at once


@pytest.mark.parametrize(
    "dt, message",
    [(math.nan, "dt: must be finite"), (math.inf, "dt: must be finite"), ("soon", "dt: expected a number")],
)
def test_step_rejects_bad_dt_and_keeps_state(dt, message):
    sim = make()
    before = sim.get_state()
    with pytest.raises(ValueError, match=message):
        sim.step(dt)
    for key, value in sim.get_state().items():
        np.testing.assert_array_equal(value, before[key])


def test_reverse_with_zero_elasticity_is_rejected():
    sim = make(scene=Scene(elasticity=0.0))
    sim.step(0.5)
    before = sim.get_state()
    with pytest.raises(ValueError, match="dt: cannot step backwards with elasticity 0"):
        sim.step(-0.1)
    np.testing.assert_array_equal(sim.positions, before["positions"])


def test_rejected_nudge_and_set_leave_state_untouched():
    sim = make()
    before = sim.get_state()
    with pytest.raises(ValueError, match="ball 1: nudge must be finite"):
        sim.nudge([[0.1, 0.0], [math.nan, 0.0]])
    with pytest.raises(ValueError, match="ball 0: position overlaps ball 1"):
        sim.set_balls(positions=[[0.0, 0.0], [0.1, 0.0]])
    for key, value in sim.get_state().items():
        np.testing.assert_array_equal(value, before[key])


def test_unchecked_nudge_equals_the_checked_one():
    pos = np.array([[[-1.0, 0.0], [1.0, 0.0]]] * 2)
    dv = np.array([[[0.1, -0.2], [0.0, 0.3]], [[0.0, 0.0], [-0.4, 0.0]]])
    checked = BatchSimulator(Scene(), pos, np.zeros((2, 2, 2)), np.ones(2))
    unchecked = BatchSimulator(Scene(), pos, np.zeros((2, 2, 2)), np.ones(2))
    checked.nudge(dv)
    unchecked.nudge(dv, check=False)
    np.testing.assert_array_equal(checked.velocities, unchecked.velocities)
    line = BatchSimulator(Scene(dimension=1, bounds=(-2.0, -0.5, 2.0, 0.5)), pos, np.zeros((2, 2, 2)), np.ones(2))
    dv = np.zeros((2, 2, 2))
    dv[1, 0, 1] = 1.0
    with pytest.raises(ValueError, match="scene 1, ball 0: nudge y must be 0 in a 1D scene"):
        line.nudge(dv)


def test_batch_errors_name_the_scene():
    pos = np.array([[[-1.0, 0.0], [1.0, 0.0]]] * 3)
    vel = np.zeros((3, 2, 2))
    masses = np.ones((3, 2))
    masses[2, 1] = -3
    with pytest.raises(ValueError, match="scene 2, ball 1: mass must be positive"):
        BatchSimulator(Scene(), pos, vel, masses)
    batch = BatchSimulator(Scene(), pos, vel, np.ones(2))
    before = batch.get_state()
    with pytest.raises(ValueError, match="scene 1, ball 0: position must keep the ball inside"):
        batch.set_scenes([0, 1], [[[-1.0, 0.0], [1.0, 0.0]], [[-5.0, 0.0], [1.0, 0.0]]], np.zeros((2, 2, 2)))
    for key, value in batch.get_state().items():
        np.testing.assert_array_equal(value, before[key])


@pytest.mark.parametrize("masses", [None, np.ones((1, 3)), np.ones(2)])
def test_unchecked_set_scenes_still_refuses_wrong_shapes_before_writing(masses):
    """``set_scenes(check=False)`` skips the value checks only: arrays of the wrong shape (masses
    left out, as a checked call allows) are refused before any scene changes."""
    batch = BatchSimulator(Scene(), np.array([[[-1.0, 0.0], [1.0, 0.0]]] * 3), np.zeros((3, 2, 2)), np.ones(2))
    before = batch.get_state()
    with pytest.raises(ValueError, match=r"set_scenes: with check=False, .* masses \("):
        batch.set_scenes(
            np.array([1]), [[[-1.5, 0.0], [1.0, 0.0]]], np.zeros((1, 2, 2)), masses, np.full((1, 2), 0.1), check=False
        )
    for key, value in batch.get_state().items():
        np.testing.assert_array_equal(value, before[key])
    batch.set_scenes(
        np.array([1]),
        [[[-1.5, 0.0], [1.0, 0.0]]],
        np.zeros((1, 2, 2)),
        np.ones((1, 2)),
        np.full((1, 2), 0.1),
        check=False,
    )
    assert batch.positions[1, 0, 0] == -1.5


@pytest.mark.parametrize("index", [[3], [-4], [0.5], [True], [[True, False, True]], "a", None, np.zeros((1, 1), int)])
def test_set_scenes_names_a_bad_index(index):
    batch = BatchSimulator(Scene(), np.array([[[-1.0, 0.0], [1.0, 0.0]]] * 3), np.zeros((3, 2, 2)), np.ones(2))
    before = batch.get_state()
    with pytest.raises(
        ValueError, match=r"index: expected scene indices within the batch of 3 .* or a \(3,\) bool mask"
    ):
        batch.set_scenes(index, [[[-1.0, 0.0], [1.0, 0.0]]], np.zeros((1, 2, 2)))
    for key, value in batch.get_state().items():
        np.testing.assert_array_equal(value, before[key])
    batch.set_scenes([-1], [[[-1.5, 0.0], [1.0, 0.0]]], np.zeros((1, 2, 2)))  # the last scene
    batch.set_scenes([False, True, False], [[[-1.5, 0.0], [1.0, 0.0]]], np.zeros((1, 2, 2)))
    assert batch.positions[1:, 0, 0].tolist() == [-1.5, -1.5]


@pytest.mark.parametrize(
    "call, message",
    [
        (
            lambda: make(velocities=[[1.0, 0.0, 0.0], [0.0, 0.0, 0.0]]),
            r"velocities: expected shape \(2, 2\), got \(2, 3\)",
        ),
        (lambda: make(masses=[1.0, 2.0, 3.0]), r"masses: expected shape \(2,\), got \(3,\)"),
        (lambda: make().nudge([[1.0, 0.0]]), r"nudge: expected shape \(2, 2\), got \(1, 2\)"),
        (lambda: make().nudge([1.0, 0.0]), r"nudge: expected shape \(2, 2\), got \(2,\)"),
        (lambda: make().nudge(0.5), r"nudge: expected shape \(2, 2\), got \(\)"),
        (lambda: make(positions=[1.0, 0.0]), r"positions: expected shape \(N, 2\), got \(2,\)"),
        (lambda: make().set_balls(velocities=[[1.0, 0.0]]), r"velocities: expected shape \(2, 2\), got \(1, 2\)"),
        (lambda: make().set_state(make().get_state().replace(radii=np.ones(3))), r"expected shape \(2,\), got \(3,\)"),
    ],
)
def test_a_single_simulator_gives_shapes_without_a_batch_axis(call, message):
    with pytest.raises(ValueError, match=message):
        call()


def test_a_batch_gives_shapes_with_its_batch_axis():
    batch = BatchSimulator(Scene(), [GOOD["positions"]], [GOOD["velocities"]], GOOD["masses"])
    with pytest.raises(ValueError, match=r"nudge: expected shape \(1, 2, 2\), got \(2, 2\)"):
        batch.nudge(GOOD["velocities"])


@pytest.mark.parametrize(
    "call, typo, meant",
    [
        (lambda: make(substep=4), "substep", "substeps"),
        (lambda: make(max_event=10), "max_event", "max_events"),
        (
            lambda: BatchSimulator(Scene(), [GOOD["positions"]], [GOOD["velocities"]], GOOD["masses"], mode_="naive"),
            "mode_",
            "mode",
        ),
        (lambda: Scene(bound=None), "bound", "bounds"),
        (lambda: Scene(elasticty=0.5), "elasticty", "elasticity"),
    ],
)
def test_a_misspelled_engine_keyword_names_the_closest(call, typo, meant):
    # a TypeError, as for any call, and a ValueError, as other bad arguments are
    for kind in (TypeError, ValueError):
        with pytest.raises(kind, match=rf"'{typo}' \(did you mean '{meant}'"):
            call()


@pytest.mark.parametrize("name", ["positions", "velocities", "masses", "radii", "clusters"])
def test_state_properties_are_read_only_snapshots(name):
    sim = make()
    before = getattr(sim, name)
    with pytest.raises(ValueError, match="read-only"):
        before[0] = 0  # a write raises rather than being dropped
    assert np.array_equal(before, getattr(sim, name))
    batch_view = getattr(sim.batch, name)
    with pytest.raises(ValueError, match="read-only"):
        batch_view[0] = 0


def test_property_snapshots_do_not_follow_the_state():
    sim = make()
    before = sim.positions
    sim.step(0.5)
    assert not np.array_equal(before, sim.positions)
    moved = sim.positions.copy()  # a writable copy, handed back through a setter
    moved[0, 0] -= 0.1
    sim.set_balls(positions=moved)
    assert sim.positions[0, 0] == moved[0, 0]


def test_huge_python_integers_name_the_ball_and_field():
    with pytest.raises(
        ValueError, match="ball 1: masses must be within float64's range, got an integer of about 1e400"
    ):
        make(masses=[1, 10**400])
    with pytest.raises(ValueError, match="ball 0: positions must be within float64's range"):
        make(positions=[[-(10**309), 0], [1, 0]])
    with pytest.raises(ValueError, match="dt: must be within float64's range"):
        make().step(10**400)
    with pytest.raises(ValueError, match="scene elasticity: must lie in"):
        Scene(elasticity=10**400)
    with pytest.raises(ValueError, match="scene bounds: expected numbers within float64's range"):
        Scene(bounds=(0, 0, 10**400, 1))
    for setting in ("collapse_ratio", "collapse_floor", "contact_duration"):
        with pytest.raises(ValueError, match=f"{setting}: must be"):
            make(**{setting: 10**400})


@pytest.mark.parametrize("mode", ["naive", "posteriori"])
def test_substeps_are_bounded(mode):
    from collision_env.engine import MAX_SUBSTEPS

    make(mode=mode, substeps=MAX_SUBSTEPS)
    with pytest.raises(ValueError, match=f"substeps: must be at most {MAX_SUBSTEPS:,}, got 1,000,000,000"):
        make(mode=mode, substeps=10**9)


#: A bad value of each field of a state (for ``make()``'s two balls), and what the error says.
BAD_STATE_FIELDS = {
    "negative mass": ("masses", [-1.0, 2.0], "ball 0: mass must be positive"),
    "zero radius": ("radii", [0.0, 0.2], "ball 0: radius must be positive"),
    "overlap": ("positions", [[0.0, 0.0], [0.1, 0.0]], "ball 0: position overlaps ball 1"),
    "outside": ("positions", [[-5.0, 0.0], [1.0, 0.0]], "ball 0: position must keep the ball inside"),
    "fast": ("velocities", [[1e200, 0.0], [0.0, 0.0]], "ball 0: velocity must be finite, speed within 1e\\+150"),
    "cluster index": ("clusters", [0, 2], "state clusters: ball 1: expected 1"),
    "negative cluster": ("clusters", [-1, 1], "state clusters: ball 0: expected 0"),
    "time": ("time", 1e300, "state time: must be finite and at most 1e\\+150 s"),
    "compensation": ("time_compensation", 1e-3, "state time_compensation: must be within an ulp"),
    "spin": ("omega", [1e200, 0.0], "state omega: ball 0: expected within 1e\\+150 rad/s"),
}


@pytest.mark.parametrize("bad", BAD_STATE_FIELDS, ids=str)
def test_set_state_refuses_what_the_constructor_refuses_and_changes_nothing(bad):
    key, value, message = BAD_STATE_FIELDS[bad]
    sim = make(radii=[0.2, 0.2])
    sim.step(0.3)
    before = sim.get_state()
    with pytest.raises(ValueError, match=message):
        sim.set_state(before.replace(**{key: np.asarray(value)}))
    for k, v in sim.get_state().items():
        np.testing.assert_array_equal(v, before[k])
    sim.set_state(before)  # the state itself is good


def test_set_state_checks_stick_clusters_and_names_missing_keys():
    stick = make(scene=Scene(elasticity=0.0, inelastic="stick"), positions=[[-1.0, 0.0], [-0.5, 0.0]], radii=[0.25] * 2)
    stick.step(0.1)  # the two balls stick
    state = stick.get_state()
    assert state["clusters"].tolist() == [0, 0]
    stick.set_state(state)
    with pytest.raises(ValueError, match="state clusters: ball 0: expected a ball index whose cluster is its own"):
        stick.set_state(state.replace(clusters=np.array([1, 0])))
    with pytest.raises(ValueError, match=r"state: missing \['omega'\]"), pytest.warns(DeprecationWarning):
        stick.set_state({k: v for k, v in state.items() if k != "omega"})
    with pytest.raises(TypeError, match="state: expected a SimulatorState"):
        stick.set_state([1, 2])


@pytest.mark.parametrize("mode", ["exact", "naive", "posteriori"])
def test_set_state_takes_a_stick_cluster_only_as_one_rigid_body_of_touching_balls(mode):
    pos, vel = [[-1.0, 0.0], [-0.5, 0.1], [1.0, 0.0]], [[1.0, 0.0], [0.0, 0.0], [0.0, 0.0]]
    sim = Simulator(Scene(elasticity=0.0, inelastic="stick"), pos, vel, [1.0, 2.0, 1.0], [0.25] * 3, mode=mode)
    sim.step(0.2)  # balls 0 and 1 stick, and the cluster spins
    state = sim.get_state()
    assert state["clusters"].tolist() == [0, 0, 2] and state["omega"][0] != 0.0
    sim.set_state(state)

    def refused(message, **changes):
        with pytest.raises(ValueError, match=message):
            sim.set_state(state.replace(**changes))
        for key, value in sim.get_state().items():
            np.testing.assert_array_equal(value, state[key])

    moving = "moves apart from its stick cluster \\(root ball 0\\): a cluster moves as one rigid body"
    faster = state["velocities"].copy()
    faster[1] += 1e-3 * np.abs(faster).max()
    refused(f"state velocities: ball [01]: {moving}", velocities=faster)
    refused(f"state velocities: ball [01]: {moving}", omega=state["omega"] * 1.01)
    refused(f"state velocities: ball 0: {moving}", clusters=np.array([0, 0, 0]))  # (v_cm moves)
    # ball 2, 1.3 m from the others, glued to them: refused in every mode (the cheap modes stick
    # balls up to a sub-step's reconstruction error apart, not a metre)
    translating = {"velocities": np.tile([0.3, 0.0], (3, 1)), "omega": np.zeros(3), "clusters": np.array([0, 0, 0])}
    far = "does not touch the rest of its stick cluster \\(root ball 0\\)"
    refused(f"state clusters: ball 2: {far}", **translating)


@settings(max_examples=60, deadline=None)
@given(
    n=st.integers(2, 6),
    key=st.sampled_from(["masses", "radii", "velocities", "positions", "clusters", "time"]),
    ball=st.integers(0, 5),
    value=st.sampled_from([-1.0, 0.0, 1e151, 1e200, math.inf, -1e300]),
    mode=st.sampled_from(["exact", "posteriori", "naive"]),
)
def test_set_state_refuses_any_bad_value_and_changes_nothing(n, key, ball, value, mode):
    """A value out of its field's range at any ball, in any mode: a ValueError naming the field
    (or the ball), the state exactly as before."""
    ball %= n
    x = np.linspace(-1.5, 1.5, n)
    sim = Simulator(Scene(), np.stack([x, np.zeros(n)], 1), np.ones((n, 2)), np.ones(n), np.full(n, 0.1), mode=mode)
    state = sim.get_state()
    bad = {k: np.array(v, copy=True) for k, v in state.items()}
    if key == "clusters":
        bad[key][ball] = n + 1 if value > 0 else -1
    elif key == "time":
        if abs(value) <= 1e150:
            return  # a good time
        bad[key] = np.array(value)
    elif key in ("masses", "radii"):
        if key == "masses" and 0.0 < value < math.inf:
            return  # a heavy ball is a good ball (its kinetic energy is finite)
        bad[key][ball] = value
    else:
        if abs(value) <= 1e150:
            return
        bad[key][ball, 0] = value
    with pytest.raises(ValueError, match=f"ball {ball}|state {key}|{key}"):
        sim.set_state(SimulatorState(**bad))
    for k, v in sim.get_state().items():
        np.testing.assert_array_equal(v, state[k])


def test_set_state_names_the_scene_of_a_broken_stick_cluster():
    pos = [[[-1.0, 0.0], [-0.5, 0.1], [1.0, 0.0]]] * 2
    vel = [[[1.0, 0.0], [0.0, 0.0], [0.0, 0.0]]] * 2
    batch = BatchSimulator(Scene(elasticity=0.0, inelastic="stick"), pos, vel, [1.0, 2.0, 1.0], [0.25] * 3)
    batch.step(0.2)
    state = batch.get_state()
    assert state["clusters"].tolist() == [[0, 0, 2]] * 2
    batch.set_state(state)
    velocities = state["velocities"].copy()
    velocities[1, 1] *= 1.1
    with pytest.raises(ValueError, match="state velocities: scene 1, ball 0: moves apart from its stick cluster"):
        batch.set_state(state.replace(velocities=velocities))
    clusters = state["clusters"].copy()
    clusters[1, 2] = 0
    velocities = np.broadcast_to([0.3, 0.0], (2, 3, 2))
    with pytest.raises(ValueError, match="state clusters: scene 1, ball 2: does not touch the rest of its stick"):
        batch.set_state(state.replace(velocities=velocities, omega=np.zeros((2, 3)), clusters=clusters))


def test_set_state_refuses_an_unknown_key_naming_the_closest_and_changes_nothing():
    sim = Simulator(Scene(periodic=True), [[0.0, 0.0], [1.0, 0.0]], [[1.0, 0.0], [0.0, 0.0]], [1.0, 1.0])
    sim.step(3.0)  # (ball 1, hit by ball 0, crosses the cell)
    state = dict(sim.get_state())  # (a dict, as earlier versions gave)
    images = state.pop("images")
    assert images.any()
    typo = {**state, "image": images}  # (with 'images' left out, they would be taken as zeros)
    with pytest.raises(ValueError, match=r"state: unknown key\(s\) 'image' \(did you mean 'images'"):
        with pytest.warns(DeprecationWarning, match="a dict of the state's arrays is deprecated"):
            sim.set_state(typo)
    np.testing.assert_array_equal(sim.images, images)


def test_an_event_cap_beyond_int64_is_refused_by_name():
    with pytest.raises(ValueError, match="max_events: must be at most 9,223,372,036,854,775,807"):
        Simulator(Scene(), [[0.0, 0.0]], [[1.0, 0.0]], [1.0], max_events=10**20)


@pytest.mark.parametrize("past", [1.6e-15, -1.6e-15])
def test_a_position_a_round_off_outside_a_periodic_cell_goes_back_bit_for_bit(past):
    """A step may leave a ball a round-off outside the periodic cell (it is wrapped at its next
    crossing): set_state takes it where it is, so that a state goes back bit for bit."""
    scene = Scene(periodic=True)
    edge = scene.bounds[2] if past > 0 else scene.bounds[0]
    x = edge + past
    sim = Simulator(scene, [[0.0, 0.0], [1.0, 0.3]], [[0.7, 0.2], [-0.3, 0.1]], [1.0, 2.0])
    state = sim.get_state()
    state["positions"][0] = (x, 0.0)
    sim.set_state(state)
    got = sim.get_state()
    np.testing.assert_array_equal(got["positions"], state["positions"])
    np.testing.assert_array_equal(got["images"], state["images"])
    twin = sim.copy()
    twin.set_state(sim.get_state())
    for _ in range(20):
        a, b = sim.step(0.25), twin.step(0.25)
        assert [(i.time, i.point) for i in a] == [(i.time, i.point) for i in b]
    np.testing.assert_array_equal(sim.positions, twin.positions)
    # a position well outside the cell is wrapped into it, its period counted
    state["positions"][0] = (edge + 1e-9 * np.sign(past), 0.0)
    sim.set_state(state)
    assert scene.bounds[0] <= sim.positions[0, 0] < scene.bounds[2]
    assert sim.images[0, 0] == np.sign(past)


def test_get_state_is_a_typed_record_and_a_dict_is_still_taken_with_a_deprecation_warning():
    sim = Simulator(Scene(), [[0.0, 0.0], [1.0, 0.0]], [[1.0, 0.0], [0.0, 0.5]], [1.0, 2.0])
    state = sim.get_state()
    fields = [key for key in SimulatorState.__dataclass_fields__ if key != "last_impact"]  # (the TC model's)
    assert isinstance(state, SimulatorState) and list(state) == fields and state.last_impact is None
    assert state.positions.shape == (2, 2) and state["radii"] is state.radii and state.time == 0.0
    batch = sim.batch.get_state()
    assert batch.positions.shape == (1, 2, 2) and batch.time.shape == (1,)
    with pytest.raises(dataclasses.FrozenInstanceError):
        state.time = 1.0  # type: ignore[misc]
    sim.step(0.3)
    with pytest.warns(DeprecationWarning, match="a dict of the state's arrays is deprecated"):
        sim.set_state(dict(state))
    assert sim.time == 0.0
    np.testing.assert_array_equal(sim.positions, state.positions)
    moved = state.replace(positions=[[0.5, 0.0], [1.0, 0.0]])
    sim.set_state(moved)
    np.testing.assert_array_equal(sim.positions, [[0.5, 0.0], [1.0, 0.0]])
    np.testing.assert_array_equal(state.positions, [[0.0, 0.0], [1.0, 0.0]])  # (the original is unchanged)
