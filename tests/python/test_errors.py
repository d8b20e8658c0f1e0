"""Every exception class of caliper.errors raised by the case that should raise it, with the
server's message naming what is wrong; Python's TypeError/ValueError for wrong arguments before
anything is sent; lost processes as ConnectionError, never a hang.

The tests of the module's session come first, then those that start sessions of their own (a
Model without a scene, with a fault point, one killed), so that what those do to their processes
cannot reach the others."""

import socket
import sqlite3
import threading
import time

import numpy as np
import pytest

import caliper
from conftest import SCENE

ELBOW = "ecce_arm.elbow.position"
HAND = "ecce_arm.hand.position"
MASS = "ecce_arm.forearm.mass"


def commands(model):
    return {s.name: s.command for s in model.actuator_states()}


def closed_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


# --- UnknownId ---------------------------------------------------------------------------------

@pytest.mark.parametrize("call, id", [
    (lambda m: m.get("ecce_arm.no_such_body.position"), "ecce_arm.no_such_body.position"),
    (lambda m: m.get([ELBOW, "ecce_arm.nothing"]), "ecce_arm.nothing"),
    (lambda m: m.get_values(["ecce_arm.nothing"]), "ecce_arm.nothing"),
    (lambda m: m.set("ecce_arm.no_such.mass", 1.0), "ecce_arm.no_such.mass"),
    (lambda m: m.set_command("no_such_motor", 1.0), "no_such_motor"),
    (lambda m: m.record(["ecce_arm.no_such_channel"], steps=3), "ecce_arm.no_such_channel"),
], ids=["get", "get-list", "get_values", "set", "set_command", "record"])
def test_unknown_id(arm, call, id):
    with pytest.raises(caliper.UnknownId) as e:
        call(arm)
    assert e.value.id == id
    assert id in str(e.value)
    assert isinstance(e.value, LookupError) and isinstance(e.value, caliper.Error)
    assert arm.status().steps == 0  # nothing ran


def test_unknown_id_in_set_commands_changes_no_command(arm):
    with pytest.raises(caliper.UnknownId) as e:
        arm.set_commands({"elbow_flexor": 3.0, "no_such_motor": 1.0})
    assert e.value.id == "no_such_motor" and "no_such_motor" in str(e.value)
    assert commands(arm)["elbow_flexor"] == 0.0  # atomically: nothing applied


# --- InvalidParameter --------------------------------------------------------------------------

def test_invalid_parameter_out_of_the_models_range(arm):
    original = float(arm.get(MASS))
    with pytest.raises(caliper.InvalidParameter) as e:
        arm.set(MASS, -1.0)
    assert "forearm.mass" in str(e.value) and "positive" in str(e.value)
    assert isinstance(e.value, ValueError)
    assert float(arm.get(MASS)) == original


def test_invalid_parameter_read_only_channel(arm):
    with pytest.raises(caliper.InvalidParameter) as e:
        arm.set(ELBOW, 1.0)
    assert ELBOW in str(e.value) and "read-only" in str(e.value)


def test_invalid_parameter_time_step(arm):
    with pytest.raises(caliper.InvalidParameter) as e:
        arm.time_step_s = 1.0
    assert "time step" in str(e.value)
    assert arm.time_step_s == 0.001


def test_invalid_parameter_too_many_commands(arm):
    with pytest.raises(caliper.InvalidParameter) as e:
        arm.set_commands({f"motor{i}": 1.0 for i in range(100001)})
    assert "100001" in str(e.value) and "100000" in str(e.value)


def test_invalid_parameter_recording_outside_the_write_directory(arm):
    with pytest.raises(caliper.InvalidParameter) as e:
        arm.start_recording("/etc/caliper-test.caliper")
    assert "/etc/caliper-test.caliper" in str(e.value) and "model.write_dir" in str(e.value)
    assert not arm.recording_status().recording


# --- NotAvailable on the module's Model --------------------------------------------------------

def test_not_available_without_a_replay(arm):
    with pytest.raises(caliper.NotAvailable) as e:
        arm.seek(0.5)
    assert "replay" in str(e.value) and "model0" in str(e.value)
    with pytest.raises(caliper.NotAvailable) as e:
        arm.fork()
    assert "replay" in str(e.value)


# --- LoadFailed --------------------------------------------------------------------------------

def test_load_failed_names_the_malformed_file_and_keeps_the_scene(arm, tmp_path):
    bad = tmp_path / "broken_arm.dae"
    bad.write_text("<?xml version='1.0'?>\n<COLLADA><library_visual_scenes><oops\n")
    with pytest.raises(caliper.LoadFailed) as e:
        arm.load(bad)
    assert str(bad) in str(e.value)
    assert "malformed" in str(e.value)
    status = arm.status()
    assert status.scene == SCENE  # the Model keeps its scene
    assert arm.step(5) == 5


def test_load_failed_names_a_missing_file(arm, tmp_path):
    missing = tmp_path / "no_such_scene.dae"
    with pytest.raises(caliper.LoadFailed) as e:
        arm.load(missing)
    assert "no_such_scene.dae" in str(e.value)
    assert arm.status().scene == SCENE


def test_load_failed_from_bytes_names_the_file(arm):
    with pytest.raises(caliper.LoadFailed) as e:
        arm.load_bytes("garbage_scene.dae", b"<COLLADA>not a scene")
    assert "garbage_scene.dae" in str(e.value)
    assert arm.status().scene == SCENE


# --- LimitExceeded -----------------------------------------------------------------------------

def test_limit_exceeded_ids_in_one_get(arm):
    with pytest.raises(caliper.LimitExceeded) as e:
        arm.get([ELBOW] * 100001)
    assert e.value.limit == 100000
    assert "100001 ids" in str(e.value) and "model0" in str(e.value)
    assert arm.get([ELBOW] * 1000)[-1].shape == ()  # within the limit


def test_limit_exceeded_channel_patterns(arm):
    with pytest.raises(caliper.LimitExceeded) as e:
        arm.channels("*" * 9)
    assert e.value.limit == 8 and "'*'" in str(e.value)
    with pytest.raises(caliper.LimitExceeded) as e:
        arm.channels("x" * 1025)
    assert e.value.limit == 1024 and "1025 characters" in str(e.value)


def test_limit_exceeded_values_subscribed(arm):
    with pytest.raises(caliper.LimitExceeded) as e:
        arm.record(["ecce_arm.hand.rotation"] * 20000, steps=1)  # 180,000 values
    assert e.value.limit == 100000
    assert "180000 values" in str(e.value)
    assert arm.status().steps == 0
    assert len(arm.record(ELBOW, steps=100)) == 100  # the Model subscribes on


# --- EditRefused -------------------------------------------------------------------------------

def test_edit_refused_changes_nothing(arm):
    before = arm.edit_status()
    with pytest.raises(caliper.EditRefused) as e:
        arm.remove_tendon("no_such")
    assert "no_such" in str(e.value) and "tendon" in str(e.value)
    with pytest.raises(caliper.EditRefused) as e:
        arm.set_mass("no_such_body", 1.0)
    assert "no_such_body" in str(e.value)
    with pytest.raises(caliper.EditRefused) as e:
        arm.pull("no_such_body", (0, 0, 0), (0, 0, 1))
    assert "no_such_body" in str(e.value)
    assert arm.edit_status() == before


def test_edit_refused_nothing_to_undo(arm):
    assert arm.edit_status().undo == ""
    with pytest.raises(caliper.EditRefused) as e:
        arm.undo()
    assert "undo" in str(e.value)


# --- RecordingError, FormatError (files, no session) -------------------------------------------

def test_recording_error_names_the_file(tmp_path):
    text = tmp_path / "notes.caliper"
    text.write_text("not a recording\n" * 10)
    with pytest.raises(caliper.RecordingError) as e:
        caliper.Recording(text)
    assert str(text) in str(e.value)
    other = tmp_path / "other.sqlite"
    db = sqlite3.connect(other)
    db.execute("CREATE TABLE t (x INTEGER)")
    db.commit()
    db.close()
    with pytest.raises(caliper.RecordingError) as e:
        caliper.Recording(other)
    assert str(other) in str(e.value)
    with pytest.raises(caliper.RecordingError) as e:
        caliper.Recording(tmp_path / "missing.caliper")
    assert "missing.caliper" in str(e.value)


def test_format_error_names_the_file(tmp_path):
    bad = tmp_path / "experiments.json"
    bad.write_text('{"scene": "arm.dae", "duration_s": 1,,}')
    with pytest.raises(caliper.FormatError) as e:
        caliper.load_experiments(bad)
    assert str(bad) in str(e.value)
    assert isinstance(e.value, ValueError)
    wrong = tmp_path / "wrong.json"
    wrong.write_text('{"scene": "%s", "duration_s": "long", "record": ["%s"]}' % (SCENE, ELBOW))
    with pytest.raises(caliper.FormatError) as e:
        caliper.load_experiments(wrong)
    assert str(wrong) in str(e.value) and "duration_s" in str(e.value)


# --- Python's own errors, before anything is sent ----------------------------------------------

@pytest.mark.parametrize("call, error, argument", [
    pytest.param(lambda m: m.set_command(1, 2), TypeError, "actuator", id="set_command(1, 2)"),
    pytest.param(lambda m: m.set_command("elbow_flexor", "six"), TypeError, "value",
                 id="set_command-str"),
    pytest.param(lambda m: m.set_command("elbow_flexor", None), TypeError, "value",
                 id="set_command-None"),
    pytest.param(lambda m: m.set_command("elbow_flexor", [1.0, 2.0]), ValueError, "value",
                 id="set_command-two-values"),
    pytest.param(lambda m: m.get(5), TypeError, "ids", id="get(5)"),
    pytest.param(lambda m: m.get([ELBOW, 3]), TypeError, "ids", id="get-list-with-int"),
    pytest.param(lambda m: m.get_values(None), TypeError, "ids", id="get_values(None)"),
    pytest.param(lambda m: m.set_commands([1, 2]), TypeError, "commands",
                 id="set_commands([1, 2])"),
    pytest.param(lambda m: m.set_commands({1: 2.0}), TypeError, "commands",
                 id="set_commands-int-key"),
    pytest.param(lambda m: m.set_commands({"elbow_flexor": "x"}), TypeError,
                 "commands['elbow_flexor']", id="set_commands-str-value"),
    pytest.param(lambda m: m.set(MASS, [1.0, 2.0]), ValueError, "value", id="set-two-values"),
    pytest.param(lambda m: m.step(0), ValueError, "n must be", id="step(0)"),
    pytest.param(lambda m: m.record(ELBOW, steps=0), ValueError, "steps", id="record-steps-0"),
    pytest.param(lambda m: m.record(ELBOW), TypeError, "steps", id="record-no-steps"),
    pytest.param(lambda m: m.record([], steps=1), ValueError, "ids", id="record-no-ids"),
    pytest.param(lambda m: m.start_recording("x.caliper", every=0), ValueError, "every",
                 id="start_recording-every-0"),
    pytest.param(lambda m: setattr(m, "real_time_factor", "fast"), TypeError,
                 "real_time_factor", id="real_time_factor-str"),
])
def test_wrong_arguments_raise_python_errors_naming_them(arm, call, error, argument):
    with pytest.raises(error) as e:
        call(arm)
    assert not isinstance(e.value, caliper.Error)
    assert argument in str(e.value)
    assert arm.status().steps == 0
    assert all(c == 0.0 for c in commands(arm).values())
    assert not arm.recording_status().recording


@pytest.mark.parametrize("call, argument, what", [
    pytest.param(lambda m: m.set_command("elbow_flexor", float("nan")), "value", "NaN",
                 id="set_command-nan"),
    pytest.param(lambda m: m.set_command("elbow_flexor", float("inf")), "value", "infinite",
                 id="set_command-inf"),
    pytest.param(lambda m: m.set_commands({"elbow_flexor": float("-inf")}),
                 "commands['elbow_flexor']", "infinite", id="set_commands-inf"),
    pytest.param(lambda m: m.set(MASS, float("nan")), "value", "NaN", id="set-nan"),
    pytest.param(lambda m: m.set(MASS, np.array([np.inf])), "value", "infinite",
                 id="set-inf-array"),
    pytest.param(lambda m: setattr(m, "time_step_s", float("nan")), "time_step_s", "finite",
                 id="time_step_s-nan"),
    pytest.param(lambda m: setattr(m, "real_time_factor", float("inf")), "real_time_factor",
                 "finite", id="real_time_factor-inf"),
    pytest.param(lambda m: m.pull("hand", (0, 0, float("nan")), (0, 0, 1)), "point_m", "NaN",
                 id="pull-point-nan"),
    pytest.param(lambda m: m.pull("hand", (0, 0, 0), (0, float("inf"), 1)), "target_m",
                 "infinite", id="pull-target-inf"),
    pytest.param(lambda m: m.set_mass("forearm", float("nan")), "mass_kg", "finite",
                 id="set_mass-nan"),
    pytest.param(lambda m: m.seek(float("nan")), "time_s", "finite", id="seek-nan"),
])
def test_nan_and_infinity_are_refused_before_sending(arm, call, argument, what):
    mass = float(arm.get(MASS))
    with pytest.raises(ValueError) as e:
        call(arm)
    assert not isinstance(e.value, caliper.Error)
    assert argument in str(e.value) and what in str(e.value)
    assert float(arm.get(MASS)) == mass
    assert all(c == 0.0 for c in commands(arm).values())
    assert arm.time_step_s == 0.001 and arm.real_time_factor == 1.0


def test_huge_sizes_are_refused_before_sending(arm):
    mass = float(arm.get(MASS))
    began = time.monotonic()
    with pytest.raises(ValueError) as e:
        arm.set(MASS, np.ones(10**7))
    assert "10000000" in str(e.value) and MASS in str(e.value)
    with pytest.raises(ValueError) as e:
        arm.set_command("elbow_flexor", np.ones(10**6))
    assert "value" in str(e.value)
    with pytest.raises(ValueError) as e:
        arm.step(2**40)
    assert str(2**40) in str(e.value) and "n must be" in str(e.value)
    with pytest.raises(ValueError):
        arm.step(-1)
    assert time.monotonic() - began < 5.0
    assert float(arm.get(MASS)) == mass
    assert arm.status().steps == 0


# --- sessions of their own ---------------------------------------------------------------------

def test_not_available_without_a_scene(new_session):
    local = new_session(scene=None)
    model = local.model("model0")
    assert model.status().state == "EMPTY"
    for call in (lambda: model.step(1), lambda: model.get(ELBOW), lambda: model.start(),
                 lambda: model.set_command("elbow_flexor", 1.0), lambda: model.export_scene()):
        with pytest.raises(caliper.NotAvailable) as e:
            call()
        assert "no scene" in str(e.value) and "model0" in str(e.value)
    model.load(SCENE)
    assert model.step(5) == 5


@pytest.mark.parametrize("kind", ["simulation_fault", "bad_alloc", "out_of_range",
                                  "runtime_error", "unknown"])
def test_run_failed_says_how_many_steps_ran(new_session, kind):
    local = new_session(options=[f"model.inject_fault={kind}@50"])
    model = local.model("model0")
    with pytest.raises(caliper.RunFailed) as e:
        model.step(100)
    assert e.value.steps == 49 and e.value.steps < 100
    assert "model0" in str(e.value) and "49 of 100" in str(e.value)
    status = model.status()
    assert status.state == "FAULTED" and status.steps == 49
    assert status.last_error and status.last_error in str(e.value)
    with pytest.raises(caliper.NotAvailable) as e:  # faulted: reset first
        model.step(1)
    assert "fault" in str(e.value)
    model.reset()
    assert model.step(100) == 100  # the fault point fires once


def test_record_on_a_faulting_model_raises_run_failed(new_session):
    """record() steps the Model like step(): a fault on the way is RunFailed, not a short or
    empty Data (nor a 10 s wait)."""
    local = new_session(options=["model.inject_fault=simulation_fault@50"])
    model = local.model("model0")
    began = time.monotonic()
    try:
        with pytest.raises(caliper.RunFailed) as e:
            data = model.record(ELBOW, steps=100)
            print(f"record returned {data!r} after {time.monotonic() - began:.1f} s")
        assert e.value.steps == 49
    finally:
        assert model.status().state == "FAULTED"
    assert time.monotonic() - began < 5.0


def test_connection_error_for_a_closed_port():
    port = closed_port()
    began = time.monotonic()
    with pytest.raises(caliper.ConnectionError) as e:
        caliper.connect(f"corbaname::127.0.0.1:{port}", timeout_s=2.0)
    assert time.monotonic() - began < 4.0
    assert isinstance(e.value, ConnectionError)  # Python's built-in too
    assert f"127.0.0.1:{port}" in str(e.value)
    assert e.value.address == f"corbaname::127.0.0.1:{port}"


def test_a_killed_model_raises_connection_error_in_the_stepping_thread(new_session):
    local = new_session(models=2)
    model, other = local.model("model0"), local.model("model1")
    outcome = {}

    def run():
        try:
            outcome["steps"] = model.step(10**7)  # about 10 minutes of work
        except BaseException as error:  # noqa: B902 - handed to the test's thread
            outcome["error"] = error

    worker = threading.Thread(target=run, daemon=True)
    worker.start()
    deadline = time.monotonic() + 10
    while model.status().state != "RUNNING":
        assert time.monotonic() < deadline, "step(10**7) did not start"
        assert worker.is_alive(), outcome
        time.sleep(0.01)
    killed = time.monotonic()
    local.kill("model0")
    worker.join(timeout=local.timeout_s)  # well within the session's 5 s deadline
    assert not worker.is_alive(), "step() hangs after its Model was killed"
    print(f"step() raised {time.monotonic() - killed:.3f} s after the kill")
    error = outcome.get("error")
    assert isinstance(error, caliper.ConnectionError), outcome
    assert "model0" in str(error)
    began = time.monotonic()
    with pytest.raises(caliper.ConnectionError):
        model.status()
    assert time.monotonic() - began < local.timeout_s
    assert other.status().state in ("STOPPED", "PAUSED")  # the other Model is untouched
    assert other.step(10) == 10


def test_a_failed_connect_leaves_other_sessions_working(new_session):
    """A connect() that fails must not take the process's ORB down with it."""
    local = new_session()
    model = local.model("model0")
    assert model.step(1) == 1
    with pytest.raises(caliper.ConnectionError):
        caliper.connect(f"corbaname::127.0.0.1:{closed_port()}", timeout_s=2.0)
    assert model.status().steps == 1


def test_a_second_local_session_leaves_the_first_working(new_session):
    first = new_session()
    model = first.model("model0")
    assert model.step(1) == 1
    second = new_session()
    assert second.model("model0").step(2) == 2
    assert model.status().steps == 1
