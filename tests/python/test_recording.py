"""Session recordings: the Model records into its write directory (start_recording,
recording_status, stop_recording), caliper.Recording reads the file without a session (header,
channels, events, keyframes, CSV), the Model replays it (open_replay, seek, replay_status, fork),
and caliper.verify re-simulates it bit for bit."""

import os
import sqlite3
import struct
import time
from typing import NamedTuple

import numpy as np
import pytest

import caliper

ELBOW = "ecce_arm.elbow.position"   # [rad]
HAND = "ecce_arm.hand.position"     # [m], (3,)
IDS = [ELBOW, HAND]
DT = 0.001                          # the arm's time step [s]


class Run(NamedTuple):
    started: caliper.RecordStatus
    stopped: caliper.RecordStatus
    seen: caliper.Data      # what record() took at every step while the Model recorded
    final: list             # get(IDS) at the end


@pytest.fixture(scope="module")
def recorded(session):
    """600 steps of the arm recorded with IDS every 2 steps; commands at steps 0 and 300."""
    model = session.model("model0")
    model.reset()
    started = model.start_recording("run.caliper", IDS, every=2, keyframe_every=100)
    model.set_commands({"elbow_flexor": 4.0, "elbow_extensor": 1.0})
    first = model.record(IDS, steps=300)
    model.set_command("elbow_flexor", 0.5)
    second = model.record(IDS, steps=300)
    final = model.get(IDS)
    stopped = model.stop_recording()
    model.reset()
    seen = caliper.Data(first.channels, np.concatenate([first.time, second.time]),
                        np.concatenate([first.values, second.values]))
    return Run(started, stopped, seen, final)


@pytest.fixture(scope="module")
def recording(recorded):
    return caliper.Recording(recorded.stopped.path)


def wait_for_state(model, state, timeout_s=20.0):
    deadline = time.monotonic() + timeout_s
    while True:
        status = model.status()
        if status.state == state:
            return status
        assert time.monotonic() < deadline, f"still {status.state}, not {state}: {status}"
        time.sleep(0.01)


# --- recording on the Model --------------------------------------------------------------------

def test_start_status_and_stop(session, arm):
    arm.step(100)
    started = arm.start_recording("status.caliper", [ELBOW])
    assert isinstance(started, caliper.RecordStatus)
    assert started.recording and started.error == ""
    assert started.path == os.path.join(session.files_dir, "status.caliper")
    assert started.first_step == 100
    arm.step(250)
    status = arm.recording_status()
    assert status.recording and status.steps == 250 and status.path == started.path
    stopped = arm.stop_recording()
    assert not stopped.recording and stopped.error == ""
    assert stopped.steps == 250 and stopped.bytes > 0
    assert os.path.isfile(stopped.path)
    assert not arm.recording_status().recording
    recording = caliper.Recording(stopped.path)
    assert recording.first_step == 100 and recording.last_step == 350
    assert recording.keyframe_steps[0] == 100
    with pytest.raises(caliper.InvalidParameter) as e:  # never overwritten
        arm.start_recording("status.caliper")
    assert "exists" in str(e.value) and "status.caliper" in str(e.value)
    # one extension, whichever client: the Model names "status" status.caliper, which exists
    with pytest.raises(caliper.InvalidParameter) as e:
        arm.start_recording("status")
    assert "status.caliper" in str(e.value)


def test_a_reset_ends_a_recording(arm):
    arm.start_recording("reset.caliper")
    arm.step(10)
    assert arm.recording_status().recording
    arm.reset()
    assert not arm.recording_status().recording


def test_the_recorded_run(recorded, session):
    assert recorded.started.recording and recorded.started.first_step == 0
    assert recorded.started.path == os.path.join(session.files_dir, "run.caliper")
    assert recorded.stopped.steps == 600 and recorded.stopped.error == ""
    assert len(recorded.seen) == 600


# --- the file, read here -----------------------------------------------------------------------

def test_header(recording, scene_path):
    assert recording.model_name == "ecce_arm"
    assert recording.scene_file_name == os.path.basename(scene_path)
    assert recording.time_step_s == DT
    assert recording.keyframe_every == 100 and recording.channels_every == 2
    assert recording.first_step == 0 and recording.last_step == 600
    assert recording.duration_s == pytest.approx(0.6, rel=1e-9)
    assert recording.engine.startswith("bullet")
    assert [(c.id, c.unit, c.shape) for c in recording.channels] == \
        [(ELBOW, "rad", ()), (HAND, "m", (3,))]
    scenes = recording.scenes()
    assert len(scenes) == 1 and scenes[0].version == 0 and scenes[0].step == 0
    assert b"COLLADA" in scenes[0].data[:500]


def test_channels_data_are_exactly_what_record_saw(recorded, recording):
    data = recording.channels_data()
    assert isinstance(data, caliper.Data)
    assert list(data.steps) == list(range(2, 601, 2))
    assert len(data) == 300
    assert data[ELBOW].shape == (300,) and data[HAND].shape == (300, 3)
    seen = recorded.seen  # every step 1..600: the recording has the even ones
    assert np.array_equal(data.time, seen.time[1::2])
    assert np.array_equal(data.values, seen.values[1::2])
    assert data[ELBOW][-1] == recorded.final[0]
    assert np.array_equal(data[HAND][-1], recorded.final[1])


def test_channels_data_of_a_range(recording):
    part = recording.channels_data(first_step=100, last_step=200)
    assert list(part.steps) == list(range(100, 200, 2))
    whole = recording.channels_data()
    assert np.array_equal(part.values, whole.values[49:99])


def test_command_events(recording):
    events = recording.events(kind="command")
    assert [(e.step, e.target, list(e.values)) for e in events] == [
        (0, "elbow_flexor", [4.0]), (0, "elbow_extensor", [1.0]), (300, "elbow_flexor", [0.5])]
    assert all(e.kind == "command" for e in events)
    later = recording.events(kind="command", first_step=1)
    assert [(e.step, e.target) for e in later] == [(300, "elbow_flexor")]
    kinds = {e.kind for e in recording.events()}
    assert kinds <= {"command", "keyframe", "end"}, kinds  # nothing else happened in it


def test_keyframes(recording):
    assert list(recording.keyframe_steps) == [0, 100, 200, 300, 400, 500]
    assert np.allclose(recording.keyframe_times_s, recording.keyframe_steps * DT, rtol=0,
                       atol=1e-12)


def test_export_csv(recording, tmp_path):
    csv = tmp_path / "run.csv"
    recording.export_csv(csv)
    lines = csv.read_text().splitlines()
    assert lines[0].startswith("time [s],ecce_arm.elbow.position [rad],")
    assert "[m]" in lines[0]
    assert len(lines) == 1 + 300
    table = np.array([[float(x) for x in line.split(",")] for line in lines[1:]])
    data = recording.channels_data()
    assert table.shape == (300, 1 + 4)
    assert np.allclose(table[:, 0], data.time, rtol=1e-12)
    assert np.allclose(table[:, 1:], data.values, rtol=1e-12, atol=1e-15)


# --- verify ------------------------------------------------------------------------------------

def test_verify_an_intact_recording(recorded):
    ok, report = caliper.verify(recorded.stopped.path)
    assert ok, report
    assert "identical" in report and "600 steps" in report


def test_verify_finds_a_changed_sample(recorded, tmp_path):
    copy = tmp_path / "changed.caliper"
    source = sqlite3.connect(f"file:{recorded.stopped.path}?mode=ro", uri=True)
    target = sqlite3.connect(copy)
    source.backup(target)
    source.close()
    (vals,) = target.execute("SELECT vals FROM samples WHERE step = 300").fetchone()
    values = list(struct.unpack(f"<{len(vals) // 8}d", vals))
    values[0] += 1e-9
    target.execute("UPDATE samples SET vals = ? WHERE step = 300",
                   (struct.pack(f"<{len(values)}d", *values),))
    target.commit()
    target.close()
    ok, report = caliper.verify(copy)
    assert not ok
    assert "300" in report, report


# --- replay on the Model -----------------------------------------------------------------------

def test_replay_seek_and_fork(arm, recorded, recording):
    data = recording.channels_data()
    at = {int(s): i for i, s in enumerate(data.steps)}
    opened = arm.open_replay(recorded.stopped.path)
    assert isinstance(opened, caliper.ReplayStatus)
    assert opened.replaying and opened.path == recorded.stopped.path
    assert opened.first_step == 0 and opened.last_step == 600 and opened.step == 0
    assert opened.end_time_s == pytest.approx(0.6, rel=1e-9)
    assert "(replay)" in arm.status().scene
    sought = arm.seek(0.25)
    assert sought.step == 250 and sought.time_s == pytest.approx(0.25, rel=1e-9)
    assert arm.replay_status() == sought
    assert arm.get(ELBOW) == data[ELBOW][at[250]]  # bit for bit
    assert np.array_equal(arm.get(HAND), data[HAND][at[250]])
    assert arm.step(10) == 10
    assert arm.replay_status().step == 260
    assert arm.get(ELBOW) == data[ELBOW][at[260]]
    with pytest.raises(caliper.NotAvailable) as e:  # a replay takes no commands
        arm.set_command("elbow_flexor", 1.0)
    assert "fork" in str(e.value)
    arm.fork()
    assert not arm.replay_status().replaying
    status = arm.status()
    assert status.steps == 260 and "forked" in status.scene
    arm.set_command("elbow_flexor", 1.0)  # simulates on, commands taken again
    assert arm.step(10) == 10
    assert arm.status().steps == 270


def test_a_replay_plays_to_its_end_and_pauses_there(arm, recorded):
    arm.open_replay(recorded.stopped.path)
    arm.seek(0.5)
    arm.real_time_factor = 0  # as fast as possible
    try:
        arm.start()
        status = wait_for_state(arm, "PAUSED")
    finally:
        arm.real_time_factor = 1.0
    assert status.steps == 600
    assert arm.replay_status().step == 600
    final = arm.get(IDS)
    assert final[0] == recorded.final[0]  # the recorded run, bit for bit
    assert np.array_equal(final[1], recorded.final[1])


def test_step_in_a_replay_stops_at_its_end(arm, recorded):
    """A replay "pauses at its end" (docs/recording.md); a step request past it should end
    there too, not simulate beyond the recording."""
    arm.open_replay(recorded.stopped.path)
    arm.seek(0.55)
    ran = arm.step(200)
    status = arm.replay_status()
    assert ran == 50 and status.step == status.last_step == 600, \
        f"step(200) ran {ran} steps to step {status.step}; the end is {status.last_step}"
