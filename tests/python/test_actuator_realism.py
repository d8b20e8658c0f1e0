"""Heat, friction, cogging and the driver (PWM, slew, command delay), and the biceps muscle's
command delay, on the Model of the shipped arm: set live as parameters, read as DAQ channels,
exported with the scene, recorded and re-simulated bit for bit, and the thermal protection's
warning in the Model's log."""

import glob
import math
import os

import numpy as np
import pytest

import caliper

MOTORS = ("elbow_flexor", "elbow_extensor")
PREFIX = "ecce_arm."

# a datasheet's thermal data, short time constants so that a test heats quickly; R_ha last
THERMAL = (("thermal_resistance_winding_housing", 2.9),
           ("thermal_time_constant_winding", 3.0),
           ("thermal_time_constant_motor", 30.0),
           ("thermal_resistance_housing_ambient", 11.5))
REALISM = (("coulomb_friction", 1.5e-3), ("static_friction", 2e-3), ("viscous_friction", 1e-7),
           ("cogging_amplitude", 3e-4), ("cogging_count", 14), ("pwm_levels", 1024),
           ("slew_rate", 2000), ("command_delay", 0.004), ("current_limit", 6))


def configure(model, settings):
    for motor in MOTORS:
        for name, value in settings:
            model.set(f"{PREFIX}{motor}.{name}", value)


def test_parameters_and_channels(new_session):
    # a session of its own: what it sets live stays there
    with new_session() as s:
        arm = s.model("model0")
        configure(arm, THERMAL + REALISM)
        params = arm.parameters(f"{PREFIX}elbow_flexor.*")
        assert params[f"{PREFIX}elbow_flexor.thermal_resistance_winding_housing"] == (2.9, "K/W")
        assert params[f"{PREFIX}elbow_flexor.command_delay"] == (0.004, "s")
        units = {c.id: c.unit for c in arm.channels(f"{PREFIX}elbow_flexor.*")}
        assert units[f"{PREFIX}elbow_flexor.winding_temperature"] == "degC"
        assert units[f"{PREFIX}elbow_flexor.friction_torque"] == "N m"
        assert units[f"{PREFIX}elbow_flexor.current_limit_now"] == "A"
        # a bad value is refused with the parameter's name and why
        with pytest.raises(caliper.InvalidParameter) as e:
            arm.set(f"{PREFIX}elbow_flexor.cogging_count", 2.5)
        assert "cogging_count" in str(e.value) and "whole" in str(e.value)
        with pytest.raises(caliper.InvalidParameter) as e:
            arm.set(f"{PREFIX}elbow_flexor.command_delay", 100.5)
        assert "at most 100000 " in str(e.value)
        # the muscle's excitation delay: a parameter in seconds, bounded as the motor's
        arm.set(f"{PREFIX}biceps.command_delay", 0.03)
        assert arm.parameters(f"{PREFIX}biceps.command_delay")[
            f"{PREFIX}biceps.command_delay"] == (0.03, "s")
        with pytest.raises(caliper.InvalidParameter) as e:
            arm.set(f"{PREFIX}biceps.command_delay", 100.2)
        assert "biceps" in str(e.value) and "at most 100000 " in str(e.value)
        # the export carries what was set live
        scene = arm.export_scene().decode()
        assert 'name="thermal_time_constant_motor"' in scene and 'name="cogging_count"' in scene
        biceps = scene[scene.index('<actuator name="biceps"'):]
        biceps = biceps[:biceps.index("</actuator>")]
        assert '<param name="command_delay" unit="s">0.03</param>' in biceps, biceps


def test_co_contraction_heats_derates_and_warns(new_session):
    with new_session(options=["log.level=notice"]) as s:
        arm = s.model("model0")
        configure(arm, THERMAL + (("current_limit", 6.0),))
        ids = [f"{PREFIX}{m}.{q}" for m in MOTORS
               for q in ("winding_temperature", "current", "current_limit_now")]
        arm.set_commands({m: 12.0 for m in MOTORS})
        rows = []
        for _ in range(60):
            arm.step(500)
            rows.append(arm.get_values(ids))
        rows = np.array(rows)
        winding = rows[:, 0]
        assert winding[0] < winding[10] < winding[-1] < 125, winding
        assert winding[-1] > 115, winding
        assert rows[-1, 2] < 6.0 and abs(rows[-1, 1]) <= rows[-1, 2] + 1e-9, rows[-1]
        arm.set_commands({m: 0.0 for m in MOTORS})
        logs = "".join(open(p, errors="replace").read()
                       for p in glob.glob(os.path.join(s.directory, "model0.out")))
        assert "elbow_flexor" in logs and "the driver lowers its current limit" in logs, logs[-2000:]


def test_record_and_verify_bit_for_bit(new_session):
    with new_session() as s:
        arm = s.model("model0")
        configure(arm, THERMAL + REALISM)
        arm.set(f"{PREFIX}biceps.command_delay", 0.025)  # the muscle's excitation, 25 steps late
        ids = [f"{PREFIX}elbow_flexor.winding_temperature", f"{PREFIX}elbow_flexor.current",
               f"{PREFIX}elbow_flexor.driver_voltage", f"{PREFIX}elbow_flexor.cogging_torque",
               "ecce_arm.elbow.position", f"{PREFIX}biceps.delayed_command",
               f"{PREFIX}biceps.activation"]
        started = arm.start_recording("realism.caliper", ids, every=1, keyframe_every=250)
        for k in range(150):
            u = 3 + 3 * math.sin(0.2 * k)
            arm.set_commands({"elbow_flexor": u, "elbow_extensor": 6 - u,
                              "biceps": 0.5 + 0.4 * math.sin(0.3 * k)})
            arm.step(10)
        stopped = arm.stop_recording()
        assert started.recording and stopped.steps == 1500 and stopped.error == ""
        ok, report = caliper.verify(stopped.path)
        assert ok, report
        data = caliper.Recording(stopped.path).channels_data()
        assert data[ids[0]][-1] > 25.0  # it heated
        # the delayed, slewed driver voltage moved; a replay from a keyframe gives it again
        assert np.ptp(data[ids[2]]) > 1.0  # [V]
        arm.open_replay(stopped.path)
        arm.seek(1.1)
        at = int(np.searchsorted(data.steps, 1100))
        assert arm.get(ids[2]) == data[ids[2]][at]
        assert arm.get(ids[0]) == data[ids[0]][at]
        # the muscle followed each excitation 25 steps after it was sent (every 10 steps)
        delayed = data[ids[5]]
        sent = [0.5 + 0.4 * math.sin(0.3 * k) for k in range(150)]
        for step in (400, 777, 1234):
            at_step = int(np.searchsorted(data.steps, step))
            assert delayed[at_step] == sent[(step - 1 - 25) // 10]
        assert arm.get(ids[6]) == data[ids[6]][at]
        arm.step(37)
        assert arm.get(ids[3]) == data[ids[3]][at + 37]
        assert arm.get(ids[5]) == data[ids[5]][at + 37]
        assert arm.get(ids[6]) == data[ids[6]][at + 37]


def test_measurement_delays_record_and_verify_bit_for_bit(new_session):
    """A scene with measurement delays (tests/data/collada/measurement_delays.dae: a tendon's
    tension 4 ms late, a hinge's position 2 ms late): the delayed channel is the undelayed one
    4 steps earlier, and a recording re-simulates bit for bit."""
    scene = os.path.join(os.environ.get("CALIPER_SOURCE_DIR", "."), "tests", "data", "collada",
                         "measurement_delays.dae")
    with new_session(scene=scene) as s:
        model = s.model("model0")
        tension = [c.id for c in model.channels("*line.tendon.tension")][0]
        angle = [c.id for c in model.channels("*hinge.position")][0]
        ids = [tension, tension + ".undelayed", angle, angle + ".undelayed"]
        model.pull("link", [0.2, 0, 0], [0.2, 0.2, 0.5])  # turns it about the hinge
        started = model.start_recording("delays.caliper", ids, every=1, keyframe_every=50)
        data = model.record(ids, steps=300)
        stopped = model.stop_recording()
        assert started.recording and stopped.error == ""
        assert np.array_equal(data[ids[0]][4:], data[ids[1]][:-4])  # 4 ms late
        assert np.array_equal(data[ids[2]][2:], data[ids[3]][:-2])  # 2 ms late
        assert np.ptp(data[ids[3]]) > 1e-3  # it moved [rad]
        ok, report = caliper.verify(stopped.path)
        assert ok, report


def test_a_measurement_delay_set_live_lags_its_channel(new_session):
    """set_measurement_delay on the running arm: the channel lags its `.undelayed` value by the
    delay's steps, the export carries the delay, undo removes it, a recording across the edits
    verifies bit for bit; a bad id is refused."""
    with new_session() as s:
        arm = s.model("model0")
        arm.set_commands({"elbow_flexor": 6.0})
        arm.step(20)
        channel = f"{PREFIX}elbow_flexor.current"
        # recorded across the edits: the replay re-simulates them bit for bit
        started = arm.start_recording("delay_edit.caliper", [channel, "ecce_arm.elbow.position"],
                                      every=1, keyframe_every=50)
        assert started.recording
        assert arm.measurement_delays() == {}
        status = arm.set_measurement_delay(channel, 0.002)  # 2 steps of 1 ms
        assert status.last == "delay elbow_flexor.current by 2 ms"
        assert arm.measurement_delays() == {channel: 0.002}
        truth = []
        for k in range(12):
            arm.step(1)
            truth.append(arm.get(channel + ".undelayed"))
            if k >= 2:
                assert arm.get(channel) == truth[k - 2]
        assert truth[0] != truth[-1]  # it moved
        assert '<measurement_delay channel="elbow_flexor.current"' in arm.export_scene().decode()
        with pytest.raises(caliper.EditRefused) as e:
            arm.set_measurement_delay(f"{PREFIX}elbow_flexor.nothing", 0.002)
        assert "elbow_flexor.nothing" in str(e.value)
        with pytest.raises(ValueError):
            arm.set_measurement_delay(channel, float("nan"))
        arm.undo()
        arm.step(1)
        assert channel + ".undelayed" not in {c.id for c in arm.channels(f"{PREFIX}elbow_flexor.*")}
        assert arm.measurement_delays() == {}
        stopped = arm.stop_recording()
        assert stopped.error == "" and stopped.steps == 13
        ok, report = caliper.verify(stopped.path)
        assert ok, report
