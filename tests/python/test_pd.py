"""The PD controller twice, in lock-step on the same scene: the C++ component caliper-pd-controller
driving model0, and its arithmetic written in Python driving model1 through caliper. Their elbow
trajectories, sampled every step by lossless feeds, are equal bit for bit.

The run lasts 5 s of simulated time: with the default gains the motors saturate (flexor 6 V,
extensor 0 V) until the elbow passes about 0.55 rad (2.7 s), and the extensor leaves 0 V only
after 4.3 s; a shorter run would compare two saturated schedules and miss a wrong gain or bias
(checked: kp 20.0001, kd 1.0001 or bias 1.0001 in Python then differ from the component; at
1.5 s kp 20.0001 went unnoticed)."""

import os
import signal
import subprocess
import tempfile
import time

import numpy as np
import pytest

import caliper

ROOT = os.path.abspath(os.environ.get("CALIPER_SOURCE_DIR") or os.path.join(
    os.path.dirname(os.path.abspath(__file__)), "..", ".."))
SCENE = os.path.join(ROOT, "models", "ecce_arm.dae")
ELBOW = "ecce_arm.elbow.position"

# config/pd_controller.conf and the component's defaults; the target as on the command line
TARGET = 0.8
KP, KD, BIAS, MAX = 20.0, 1.0, 1.0, 6.0
STEPS_PER_TICK = 10
RUN_S = 5.0  # [s] of simulated time
FLEXOR, EXTENSOR = "elbow_flexor", "elbow_extensor"


def clamp(v, lo, hi):
    """std::clamp: lo if v < lo, hi if hi < v, else v."""
    return lo if v < lo else (hi if hi < v else v)


class PythonPd:
    """PdControllerComponent::OnActivated and OnExecute, operation for operation."""

    def __init__(self, model, kp=KP, kd=KD, bias=BIAS, max_v=MAX, target=TARGET):
        self.model = model
        self.kp, self.kd, self.bias, self.max, self.target = kp, kd, bias, max_v, target
        channels = model.channels("*.elbow.position")  # as the component finds its joint
        assert channels, "the Model has no joint 'elbow'"
        self.position_id = channels[0].id
        self.velocity_id = self.position_id[:-len("position")] + "velocity"
        self.commands = []  # (flexor, extensor) per tick

    def tick(self):
        q, qd = self.model.get([self.position_id, self.velocity_id])  # one get call
        q, qd = float(q), float(qd)
        u = self.kp * (self.target - q) - self.kd * qd
        flexor, extensor = clamp(self.bias + u, 0.0, self.max), clamp(self.bias - u, 0.0, self.max)
        self.model.set_commands({FLEXOR: flexor, EXTENSOR: extensor})  # one call, both
        self.commands.append((flexor, extensor))
        self.model.step(STEPS_PER_TICK)


def wait_until(predicate, timeout_s, what, poll_s=0.02):
    deadline = time.monotonic() + timeout_s
    while not predicate():
        if time.monotonic() > deadline:
            pytest.fail(f"timed out after {timeout_s} s waiting for {what}")
        time.sleep(poll_s)


@pytest.fixture(scope="module")
def runs():
    """Both controllers on 2 fresh Models of a private session; what each feed took."""
    out = {}
    with caliper.LocalSession(models=2, scene=SCENE) as session, \
            tempfile.TemporaryDirectory(prefix="caliper-pd-test-") as tmp:
        model0, model1 = session.model("model0"), session.model("model1")
        assert model0.status().steps == 0 and model1.status().steps == 0
        out["start_q"] = float(model0.get(ELBOW))

        # the C++ component against model0; its feed opened first, so that it sees every step
        feed0 = model0.feed([ELBOW], every=1)
        log = os.path.join(tmp, "controller.out")
        with open(log, "wb") as log_file:
            controller = subprocess.Popen(
                [caliper.binary("caliper-pd-controller"), "--nameservice", session.address,
                 "-o", "controller.model=model0", "-o", "controller.lockstep=true",
                 "-o", "exec.auto_activate=true", "-o", f"controller.target={TARGET}",
                 "-o", "exec.rate=1000", "-o", "log.service=none",
                 "-o", f"log.spool_dir={tmp}/spool"],
                stdout=log_file, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL)
        try:
            def far_enough():
                if controller.poll() is not None:
                    pytest.fail(f"caliper-pd-controller ended (exit {controller.returncode}): "
                                f"{open(log).read()}")
                return model0.status().sim_time_s > RUN_S
            wait_until(far_enough, 60, f"model0's simulated time to pass {RUN_S} s")
            out["state_while_controlled"] = model0.status().state
        finally:
            controller.send_signal(signal.SIGTERM)
            try:
                out["controller_exit"] = controller.wait(timeout=10)
            except subprocess.TimeoutExpired:
                controller.kill()
                controller.wait()
                out["controller_exit"] = "timeout"
        out["controller_log"] = open(log).read()
        out["steps0"] = model0.status().steps
        out["commands_after_stop"] = {a.name: a.command for a in model0.actuator_states()
                                      if a.name in (FLEXOR, EXTENSOR)}
        out["cpp"] = feed0.take(1.0)
        feed0.close()

        # the Python controller on model1, as many ticks as the component ran
        pd = PythonPd(model1)
        out["python_ids"] = (pd.position_id, pd.velocity_id)
        ticks = out["steps0"] // STEPS_PER_TICK
        with model1.feed([ELBOW], every=1) as feed1:
            for _ in range(ticks):
                pd.tick()
            out["py"] = feed1.take(1.0)
        out["py_commands"] = np.array(pd.commands)
        out["steps1"] = model1.status().steps
    return out


def test_python_pd_equals_the_cpp_component_bit_for_bit(runs):
    cpp, py = runs["cpp"], runs["py"]
    assert runs["python_ids"] == ("ecce_arm.elbow.position", "ecce_arm.elbow.velocity")
    assert runs["steps0"] % STEPS_PER_TICK == 0  # lock-step: whole ticks only
    assert runs["steps1"] == runs["steps0"]
    n = min(len(cpp), len(py))
    assert n >= 1000, (len(cpp), len(py), runs["controller_log"])
    # every step's sample, from the first step on
    assert np.array_equal(cpp.time[:n], py.time[:n])
    assert np.allclose(cpp.time[:n], np.arange(1, n + 1) * 1e-3, rtol=0, atol=1e-9)
    # the comparison covers the controller's unsaturated range: both motors between their
    # bounds for a while, so that every gain, the bias and the target shape the trajectory
    commands = runs["py_commands"][:n // STEPS_PER_TICK]
    inside = (commands > 0.0) & (commands < MAX)
    assert np.sum(inside[:, 0]) >= 100 and np.sum(inside[:, 1]) >= 20, np.sum(inside, axis=0)
    q_cpp, q_py = cpp[ELBOW][:n], py[ELBOW][:n]
    assert q_cpp.shape == (n,)
    assert np.array_equal(q_cpp, q_py), (
        f"first difference at sample {int(np.argmax(q_cpp != q_py))}: "
        f"max |diff| {np.max(np.abs(q_cpp - q_py))}")


def test_the_controller_bends_the_elbow_toward_its_target(runs):
    q = runs["cpp"][ELBOW]
    assert abs(runs["start_q"]) < 0.05  # hangs straight at first
    assert abs(q[-1] - TARGET) < 0.05, q[-1]  # 0.78 rad after 5 s
    assert np.all(np.diff(q[::100]) > 0), "rises steadily toward the target, no overshoot"
    assert runs["state_while_controlled"] != "RUNNING", "stepped by the controller only"


def test_stopping_the_component_switches_its_motors_off(runs):
    assert runs["controller_exit"] == 0, runs["controller_log"]
    assert runs["commands_after_stop"] == {FLEXOR: 0.0, EXTENSOR: 0.0}
    assert "controlling ecce_arm.elbow.position toward 0.800 rad" in runs["controller_log"]


def test_a_lossless_feed_takes_every_step_of_a_lockstep_loop():
    """Feed.take returns the samples of every step the Model ran (lossless), also when the
    loop stops between two of the Model's batches (every 50 steps at 1 ms)."""
    with caliper.LocalSession(models=1, scene=SCENE) as session:
        model = session.model("model0")
        pd = PythonPd(model)
        with model.feed([ELBOW], every=1) as feed:
            for _ in range(123):
                pd.tick()
            start = time.monotonic()
            data = feed.take(2.0)
            waited = time.monotonic() - start
        assert model.status().steps == 1230
        assert len(data) == 1230, (f"{len(data)} of 1230 samples (take waited {waited:.2f} s, "
                                   f"t = {data.time[0]:.3f} .. {data.time[-1]:.3f} s)")
