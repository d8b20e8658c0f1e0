"""caliper.Model on the shipped arm: loading, stepping and running, the time step and real-time
factor, commands, channels and parameters as numpy arrays, lossless records and streams, scene
editing with undo/redo, and pulls.

Every test gets model0 of the module's session reset (the `arm` fixture, conftest.py) and puts
back what it changes (parameters, the time step, the scene)."""

import time

import numpy as np
import pytest

import caliper

ELBOW = "ecce_arm.elbow.position"          # [rad], scalar
HAND = "ecce_arm.hand.position"            # [m], (3,)
ROTATION = "ecce_arm.hand.rotation"        # (3, 3)
MASS = "ecce_arm.forearm.mass"             # [kg], writable parameter
TENSION = "ecce_arm.elbow_flexor.tendon.tension"  # [N]
DRIVE = {"elbow_flexor": 6.0, "elbow_extensor": 1.0}  # [V]: bends the elbow


def wait_until(condition, timeout_s=10.0, what="the condition"):
    """Polls `condition()` until it is true; fails after `timeout_s`."""
    deadline = time.monotonic() + timeout_s
    while True:
        value = condition()
        if value:
            return value
        if time.monotonic() > deadline:
            pytest.fail(f"{what} did not happen within {timeout_s} s")
        time.sleep(0.01)


# --- loading -----------------------------------------------------------------------------------

def test_load_by_path_starts_the_scene_stopped_at_time_zero(arm, scene_path):
    arm.step(50)
    warnings = arm.load(scene_path)
    assert isinstance(warnings, list)
    status = arm.status()
    assert status.state == "STOPPED"
    assert status.scene == scene_path
    assert status.steps == 0 and status.sim_time_s == 0.0
    assert arm.edit_status().undo == ""
    assert arm.step(3) == 3


def test_load_sent_by_content_names_the_file(arm, scene_path):
    try:
        arm.load(scene_path, send=True)
        status = arm.status()
        assert "ecce_arm.dae" in status.scene and "by content" in status.scene
        assert arm.step(10) == 10
    finally:
        arm.load(scene_path)


def test_load_bytes_of_export_scene_keeps_tuned_parameters(arm, scene_path):
    channels = arm.channels("*")
    original = float(arm.get(MASS))
    try:
        arm.set(MASS, 1.5)
        data = arm.export_scene()
        assert isinstance(data, bytes) and data.lstrip().startswith(b"<?xml")
        arm.load_bytes("tuned_arm.dae", data)
        status = arm.status()
        assert "tuned_arm.dae" in status.scene
        assert status.state == "STOPPED" and status.steps == 0
        assert float(arm.get(MASS)) == pytest.approx(1.5, rel=1e-6)
        assert [c.id for c in arm.channels("*")] == [c.id for c in channels]
        assert arm.step(10) == 10
    finally:
        arm.load(scene_path)
    assert float(arm.get(MASS)) == pytest.approx(original, rel=1e-6)


# --- stepping, running, time -------------------------------------------------------------------

def test_step_returns_n_and_advances_time(arm):
    dt = arm.time_step_s
    total = 0
    for n in (1, 7, 250):
        assert arm.step(n) == n
        total += n
        status = arm.status()
        assert status.steps == total
        assert status.sim_time_s == pytest.approx(total * dt, rel=1e-9)
        assert status.state == "PAUSED"


def test_start_pause_stop(arm):
    arm.start()
    try:
        wait_until(lambda: arm.status().steps > 20, what="the Model running")
        running = arm.status()
        assert running.state == "RUNNING" and running.sim_time_s > 0
    finally:
        arm.pause()
    paused = arm.status()
    assert paused.state == "PAUSED"
    time.sleep(0.1)  # not a synchronisation: a paused Model must not move meanwhile
    again = arm.status()
    assert again.steps == paused.steps and again.sim_time_s == paused.sim_time_s
    arm.stop()
    stopped = arm.status()
    assert stopped.state == "STOPPED"
    assert stopped.steps == 0 and stopped.sim_time_s == 0.0


def test_reset_goes_back_to_the_initial_state_bit_for_bit(arm):
    before = arm.get_values([ELBOW, HAND, TENSION])
    arm.set_commands(DRIVE)
    arm.step(300)
    assert not np.array_equal(arm.get_values([ELBOW, HAND, TENSION]), before)
    arm.reset()
    status = arm.status()
    assert status.state == "PAUSED"
    assert status.steps == 0 and status.sim_time_s == 0.0
    assert np.array_equal(arm.get_values([ELBOW, HAND, TENSION]), before)
    assert all(s.command == 0.0 for s in arm.actuator_states())  # reset zeroes the commands


def test_reset_of_a_running_model_rewinds_it_and_it_runs_on(arm):
    """Model.reset's docstring: back to time 0; a running Model runs on from there (as
    `caliper-ctl reset`: rewind, keep running)."""
    arm.start()
    try:
        wait_until(lambda: arm.status().steps > 200, what="the Model running")
        arm.reset()
        status = arm.status()
        assert status.state == "RUNNING", status
        assert status.steps < 200, status  # rewound: it started again from 0
    finally:
        arm.pause()


def test_time_step_set_and_get(arm):
    assert arm.time_step_s == pytest.approx(0.001)
    try:
        arm.time_step_s = 0.002
        assert arm.time_step_s == 0.002
        assert arm.status().time_step_s == 0.002
        assert arm.step(10) == 10
        assert arm.status().sim_time_s == pytest.approx(0.02, rel=1e-9)
    finally:
        arm.time_step_s = 0.001
    assert arm.time_step_s == 0.001


def test_real_time_factor_set_and_get(arm):
    assert arm.real_time_factor == 1.0
    try:
        arm.real_time_factor = 0.5
        assert arm.real_time_factor == 0.5
        assert arm.status().real_time_factor == 0.5
        arm.real_time_factor = 0  # as fast as possible
        assert arm.real_time_factor == 0.0
    finally:
        arm.real_time_factor = 1.0
    assert arm.real_time_factor == 1.0


# --- commands ----------------------------------------------------------------------------------

def test_set_command_and_set_commands(arm):
    arm.set_command("elbow_flexor", 2.5)
    states = {s.name: s for s in arm.actuator_states()}
    assert states["elbow_flexor"].command == 2.5
    assert float(arm.get("ecce_arm.elbow_flexor.command")) == 2.5
    arm.set_commands(DRIVE)
    states = {s.name: s for s in arm.actuator_states()}
    assert states["elbow_flexor"].command == 6.0
    assert states["elbow_extensor"].command == 1.0
    units = {a.name: a.command_unit for a in arm.actuators()}
    assert units["elbow_flexor"] == "V"
    start = float(arm.get(ELBOW))
    arm.step(500)
    assert float(arm.get(ELBOW)) > start + 0.05  # the flexor bends the elbow


# --- channels, get, set ------------------------------------------------------------------------

def test_get_gives_arrays_in_the_channels_shape(arm):
    elbow = arm.get(ELBOW)
    assert isinstance(elbow, np.ndarray) and elbow.dtype == np.float64 and elbow.shape == ()
    hand = arm.get(HAND)
    assert hand.shape == (3,) and np.all(np.isfinite(hand))
    assert arm.get(ROTATION).shape == (3, 3)
    values = arm.get([ELBOW, HAND, ROTATION])
    assert isinstance(values, list) and [v.shape for v in values] == [(), (3,), (3, 3)]
    assert np.array_equal(values[1], hand)
    assert np.allclose(values[2] @ values[2].T, np.eye(3), atol=1e-6)  # a rotation


def test_get_values_is_flat_in_the_order_of_the_ids(arm):
    arm.set_commands(DRIVE)
    arm.step(100)
    flat = arm.get_values([ELBOW, HAND, ROTATION])
    assert flat.shape == (1 + 3 + 9,) and flat.dtype == np.float64
    arrays = arm.get([ELBOW, HAND, ROTATION])
    assert np.array_equal(flat, np.concatenate([a.ravel() for a in arrays]))


def test_channels_units_and_shapes_agree_with_get(arm):
    channels = arm.channels("*")
    assert len(channels) > 100
    by_id = {c.id: c for c in channels}
    assert by_id[ELBOW].unit == "rad" and by_id[ELBOW].shape == ()
    assert by_id[HAND].unit == "m" and by_id[HAND].shape == (3,)
    assert by_id[ROTATION].shape == (3, 3)
    assert by_id[TENSION].unit == "N"
    assert by_id[MASS].unit == "kg" and by_id[MASS].writable and by_id[MASS].static
    assert not by_id[ELBOW].writable and not by_id[ELBOW].static
    values = arm.get([c.id for c in channels])
    assert len(values) == len(channels)
    mismatched = [(c.id, c.shape, v.shape) for c, v in zip(channels, values)
                  if tuple(c.shape) != v.shape or c.size != v.size]
    assert mismatched == []
    elbow_only = arm.channels("ecce_arm.elbow.*")
    assert elbow_only and all(c.id.startswith("ecce_arm.elbow.") for c in elbow_only)
    assert ELBOW in [c.id for c in elbow_only]


def test_set_a_parameter_and_read_it_back(arm):
    original = float(arm.get(MASS))
    try:
        arm.set(MASS, 1.25)
        assert float(arm.get(MASS)) == pytest.approx(1.25, rel=1e-6)
        arm.set(MASS, np.array([0.75]))
        assert float(arm.get(MASS)) == pytest.approx(0.75, rel=1e-6)
    finally:
        arm.set(MASS, original)
    assert float(arm.get(MASS)) == pytest.approx(original, rel=1e-6)


def test_status(arm, scene_path):
    status = arm.status()
    assert isinstance(status, caliper.Status)
    assert status.scene == scene_path
    assert status.time_step_s == 0.001
    assert status.last_error == ""
    arm.step(10)
    status = arm.status()
    assert status.steps == 10 and status.sim_time_s == pytest.approx(0.01, rel=1e-9)
    assert arm.fault is None


# --- lossless records and streams --------------------------------------------------------------

def test_record_is_lossless(arm):
    arm.set_commands(DRIVE)
    data = arm.record([ELBOW, HAND], steps=1000, every=10)
    assert isinstance(data, caliper.Data)
    assert len(data) == 100 and data.time.shape == (100,)
    assert data.values.shape == (100, 4)
    assert data[ELBOW].shape == (100,) and data[HAND].shape == (100, 3)
    assert data.units == {ELBOW: "rad", HAND: "m"}
    steps = np.diff(data.time)
    assert np.all(steps > 0)
    assert np.allclose(steps, 10 * 0.001, rtol=1e-9, atol=1e-12)
    assert arm.status().steps == 1000
    assert data[ELBOW][-1] > data[ELBOW][0] + 0.05


def test_record_every_step_ends_with_the_final_state(arm):
    arm.set_commands(DRIVE)
    data = arm.record([ELBOW, HAND], steps=500)
    assert len(data) == 500
    status = arm.status()
    assert data.time[-1] == status.sim_time_s
    assert data[ELBOW][-1] == arm.get(ELBOW)
    assert np.array_equal(data[HAND][-1], arm.get(HAND))


def test_record_every_n_steps_samples_steps_1_plus_multiples_of_every(arm):
    """record(steps=1000, every=10) samples steps 1, 11, ..., 991 (documented: the first step,
    then every `every`, as every DAQ subscription does), and a get() after the record returns the
    state after step 1000, 9 steps after the last sample."""
    arm.set_commands(DRIVE)
    data = arm.record([ELBOW, HAND], steps=1000, every=10)
    assert len(data) == 100
    dt = arm.time_step_s
    assert np.allclose(data.time, dt * (1 + 10 * np.arange(100)), rtol=0, atol=1e-12)
    status = arm.status()
    assert status.steps == 1000
    assert status.sim_time_s == pytest.approx(data.time[-1] + 9 * dt, abs=1e-12)
    assert data[ELBOW][-1] != arm.get(ELBOW)  # the arm moved on for 9 more steps


def test_record_of_any_number_of_steps_is_complete(arm):
    """The Model pushes a lossless feed's samples in batches (about 50 ms of simulated time); the
    samples of a last, partial batch belong to the record too, at once."""
    began = time.monotonic()
    data = arm.record(ELBOW, steps=101)
    took = time.monotonic() - began
    assert arm.status().steps == 101
    assert len(data) == 101, f"{len(data)} of 101 samples, after {took:.1f} s"
    assert took < 5.0


def test_record_by_duration(arm):
    data = arm.record(ELBOW, duration_s=0.25)
    assert len(data) == 250
    assert arm.status().steps == 250


def test_stream_blocks_concatenate_to_the_record_bit_for_bit(arm):
    ids = [ELBOW, HAND, TENSION]
    arm.set_commands(DRIVE)
    recorded = arm.record(ids, steps=1000, every=5)
    arm.reset()
    arm.set_commands(DRIVE)
    blocks = list(arm.stream(ids, block_steps=250, blocks=4, every=5))
    assert [len(b) for b in blocks] == [50, 50, 50, 50]
    assert np.array_equal(np.concatenate([b.time for b in blocks]), recorded.time)
    assert np.array_equal(np.concatenate([b.values for b in blocks]), recorded.values)
    assert arm.status().steps == 1000


# --- editing and pulls -------------------------------------------------------------------------

def test_set_mass_with_undo_and_redo(arm):
    before = arm.edit_status()
    original = float(arm.get(MASS))
    edited = arm.set_mass("forearm", 0.7)
    try:
        assert isinstance(edited, caliper.EditStatus)
        assert edited.revision == before.revision + 1
        assert "forearm" in edited.last and "forearm" in edited.undo and edited.redo == ""
        assert float(arm.get(MASS)) == pytest.approx(0.7, rel=1e-6)
        undone = arm.undo()
        assert undone.revision == before.revision + 2
        assert undone.undo == before.undo and "forearm" in undone.redo
        assert float(arm.get(MASS)) == pytest.approx(original, rel=1e-6)
        redone = arm.redo()
        assert redone.revision == before.revision + 3 and redone.redo == ""
        assert float(arm.get(MASS)) == pytest.approx(0.7, rel=1e-6)
        assert arm.edit_status() == redone
    finally:
        arm.undo()
    assert float(arm.get(MASS)) == pytest.approx(original, rel=1e-6)
    assert arm.edit_status().revision == before.revision + 4


def test_pull_and_release(arm):
    target = np.array([0.4, 0.0, 1.2])  # [m], world
    start = arm.get(HAND)
    arm.pull("hand", (0.0, 0.0, 0.0), target, 200.0)
    arm.step(500)
    pulled = arm.get(HAND)
    assert np.linalg.norm(pulled - target) < 0.5 * np.linalg.norm(start - target)
    arm.release_pull()
    arm.step(1000)
    released = arm.get(HAND)
    assert np.linalg.norm(released - target) > 2 * np.linalg.norm(pulled - target)


# --- a session of its own ----------------------------------------------------------------------

def test_fault_property_names_the_fault(new_session):
    local = new_session(options=["model.inject_fault=runtime_error@20"])
    model = local.model("model0")
    assert model.fault is None
    with pytest.raises(caliper.RunFailed):
        model.step(100)
    assert model.status().state == "FAULTED"
    assert model.fault == model.status().last_error
    assert model.fault and "injected" in model.fault
    model.reset()
    assert model.fault is None
    assert model.step(100) == 100


def test_control_cycle_is_set_commands_step_and_get_in_one_call(arm):
    """The Model's control_cycle gives bit for bit what the three calls give, and refuses a bad
    command or id without stepping."""
    ids = [ELBOW, HAND]
    actions = [{"elbow_flexor": 6.0 - 0.5 * k, "elbow_extensor": 0.3 * k} for k in range(12)]
    one_call = [arm.control_cycle(a, 7, ids) for a in actions]
    arm.reset()
    three_calls = []
    for a in actions:
        arm.set_commands(a)
        arm.step(7)
        three_calls.append(arm.get_values(ids))
    assert all(np.array_equal(x, y) for x, y in zip(one_call, three_calls))
    assert one_call[-1].shape == (4,)
    steps = arm.status().steps
    with pytest.raises(caliper.UnknownId):
        arm.control_cycle({"no_such_motor": 1.0}, 7, ids)
    with pytest.raises(caliper.UnknownId):
        arm.control_cycle({"elbow_flexor": 1.0}, 7, ["no.such.id"])
    with pytest.raises(ValueError, match="commands"):
        arm.control_cycle({"elbow_flexor": float("nan")}, 7, ids)
    assert arm.status().steps == steps


def test_parameters_give_values_with_units(arm):
    params = arm.parameters("ecce_arm.forearm.*")
    value, unit = params["ecce_arm.forearm.mass"]
    assert unit == "kg" and value.shape == () and float(value) > 0
    assert all(c.static for c in arm.channels("ecce_arm.forearm.*") if c.id in params)
    assert "ecce_arm.forearm.position" not in params  # a state, not a parameter
