"""Experiments from Python: Model.run_experiment, caliper.run_batch over 2 Models (a mass sweep,
a Model killed mid-batch, bad files, a missing scene) and caliper.Calibration on measurements
made here with known parameters. A failed connection attempt leaves the sessions already open
working (test_a_failed_connect_leaves_the_open_sessions_usable)."""

import json
import os
import threading
import time

import numpy as np
import pytest
import scipy.optimize

import caliper
from caliper.experiments import experiments_of

ROOT = os.path.abspath(os.environ.get("CALIPER_SOURCE_DIR") or os.path.join(
    os.path.dirname(os.path.abspath(__file__)), "..", ".."))
SCENE = os.path.join(ROOT, "models", "ecce_arm.dae")
ELBOW = "ecce_arm.elbow.position"
HAND = "ecce_arm.hand.position"
TENSION = "ecce_arm.elbow_flexor.tendon.tension"
MASS = "ecce_arm.forearm.mass"
RESISTANCE = "ecce_arm.elbow_flexor.resistance"

# 1.5 s of the arm: the flexor lifts the forearm, then the extensor lowers it
EXPERIMENT = {
    "scene": SCENE, "duration_s": 1.5, "every_n_steps": 10,
    "record": [ELBOW, HAND, TENSION],
    "commands": [[0.0, "elbow_flexor", 6.0], [0.8, "elbow_flexor", 0.0],
                 [0.8, "elbow_extensor", 3.0]],
}
MASSES = [0.6, 0.9, 1.2, 1.5]


@pytest.fixture(scope="class")
def session():
    """A private session with 2 Models per class of tests."""
    with caliper.LocalSession(models=2, scene=SCENE) as s:
        yield s


def equal(a, b):
    return (a.ids() == b.ids() and np.array_equal(a.time, b.time) and
            np.array_equal(a.values, b.values))


SWEEP = dict(EXPERIMENT, experiments=[{"name": "mass", "sweep": {MASS: MASSES}}])


BAD = [
    ({"bogus": 1}, "bogus"),
    ({"duration_s": -1}, "duration_s"),
    ({"every_n_steps": 0.5}, "every_n_steps"),
    ({"commands": [[0.0, "elbow_flexor"]]}, "commands"),
    ({"record": []}, "record"),
    ({"set": {MASS: "heavy"}}, "set." + MASS),
    ({"sweep": {MASS: 1.0}}, "sweep"),
    ({"name": "a b"}, "name"),
]


class TestExperiments:
    """Model.run_experiment and caliper.run_batch on one session of 2 Models."""

    def test_run_experiment_returns_the_recorded_ids_and_every_sample(self, session):
        data = session.model("model0").run_experiment(EXPERIMENT)
        assert isinstance(data, caliper.Data)
        assert data.ids() == [ELBOW, HAND, TENSION]
        # 1500 steps, one sample every 10 from step 0: 151 samples at 0, 10 ms, ..., 1.5 s
        assert len(data) == 151
        assert data.time[0] == 0.0
        assert np.allclose(data.time, np.arange(151) * 0.01, rtol=0, atol=1e-9)
        assert data[ELBOW].shape == (151,) and data[HAND].shape == (151, 3)
        assert data[TENSION].shape == (151,)
        assert data.values.shape == (151, 5)
        assert data.units == {ELBOW: "rad", HAND: "m", TENSION: "N"}
        assert np.all(np.isfinite(data.values))
        # it did what the schedule says: lifted, then lowered
        elbow = data[ELBOW]
        assert elbow[0] == pytest.approx(0.0, abs=1e-6)
        peak = int(np.argmax(elbow))
        assert elbow[peak] > 0.1 and 70 <= peak <= 100  # the flexor stops at 0.8 s
        assert elbow[-1] < elbow[peak] - 0.02

        # sampling every step: duration / time step + 1 samples
        fine = session.model("model0").run_experiment(
            dict(EXPERIMENT, duration_s=0.25, every_n_steps=1, record=[ELBOW]))
        assert fine.ids() == [ELBOW] and len(fine) == 251
        # and the first samples of both agree (the same run, sampled differently)
        assert np.array_equal(fine[ELBOW][::10], elbow[:26])

    def test_the_same_experiment_on_two_models_is_identical(self, session):
        a = session.model("model0").run_experiment(EXPERIMENT)
        b = session.model("model1").run_experiment(EXPERIMENT)
        again = session.model("model0").run_experiment(EXPERIMENT)
        assert equal(a, b)
        assert equal(a, again)
        # an override changes the run (so equality above is not trivial)
        heavy = session.model("model1").run_experiment(dict(EXPERIMENT, set={MASS: 1.5}))
        assert not np.array_equal(heavy[ELBOW], a[ELBOW])

    def test_run_experiment_takes_one_experiment_only(self, session):
        with pytest.raises(ValueError):
            session.model("model0").run_experiment(
                dict(EXPERIMENT, experiments=[{"name": "a"}, {"name": "b"}]))

    def test_a_sweep_across_two_models_returns_every_run_as_single_runs_do(self, session):
        progress = []
        batch = caliper.run_batch(SWEEP, session, progress=lambda done, total:
                                  progress.append((done, total)))
        names = [f"mass-{k}" for k in range(len(MASSES))]
        assert list(batch.results) == names  # in the runs' order
        assert batch.failures == {} and batch.lost == []
        assert sorted(batch.models) == sorted(session.models("*")) and len(batch.models) == 2
        assert progress == [(k, len(MASSES)) for k in range(1, len(MASSES) + 1)]
        assert batch.wall_s > 0

        # the runs, one per mass, in the sweep's order
        runs = batch.runs
        assert [r.name for r in runs] == names
        assert [r.overrides for r in runs] == [{MASS: [m]} for m in MASSES]
        # each equals the same run on one Model, bit for bit
        model = session.model("model1")
        for run in runs:
            assert equal(batch[run.name], model.run_experiment(run)), run.name

        # physics: a heavier forearm rises slower and less high under the same motor
        peaks = [batch[n][ELBOW].max() for n in names]
        early = [batch[n][ELBOW][30] for n in names]  # at 0.3 s
        assert all(a > b for a, b in zip(peaks, peaks[1:])), peaks
        assert all(a > b for a, b in zip(early, early[1:])), early
        # and it is heavier: the flexor's tendon pulls harder while it holds the forearm up
        tension = [batch[n][TENSION][50:80].mean() for n in names]
        assert all(a < b for a, b in zip(tension, tension[1:])), tension

    @pytest.mark.parametrize("change,key", BAD, ids=[k for _, k in BAD])
    def test_a_bad_experiment_raises_format_error_naming_the_key(self, session, tmp_path, change,
                                                                 key):
        bad = dict(EXPERIMENT, **change)
        with pytest.raises(caliper.FormatError, match=key.replace(".", r"\.")):
            session.model("model0").run_experiment(bad)
        with pytest.raises(caliper.FormatError, match=key.replace(".", r"\.")):
            caliper.run_batch(bad, session, progress=False)
        # from a file, the message names the file too
        path = tmp_path / "bad.json"
        path.write_text(json.dumps(bad))
        with pytest.raises(caliper.FormatError) as e:
            caliper.load_experiments(path)
        assert key in str(e.value) and str(path) in str(e.value)
        assert isinstance(e.value, ValueError)

    def test_a_scene_that_does_not_exist_fails_the_run(self, session, tmp_path):
        missing = str(tmp_path / "no_such_arm.dae")
        spec = dict(EXPERIMENT, scene=missing)
        with pytest.raises(caliper.SetupError, match="no_such_arm.dae"):
            session.model("model0").run_experiment(spec)
        # a batch reports it as a failure of that run, without a lost Model
        batch = caliper.run_batch(dict(spec, experiments=[{"name": "gone"}, {"name": "gone2"}]),
                                  session, progress=False)
        assert batch.results == {}
        assert set(batch.failures) == {"gone", "gone2"}
        assert all("no_such_arm.dae" in why for why in batch.failures.values())
        assert batch.lost == []
        # the Models are fine afterwards
        assert len(session.model("model0").run_experiment(dict(EXPERIMENT, duration_s=0.1))) == 11

    def test_unknown_ids_fail_the_run_naming_the_id(self, session):
        with pytest.raises(caliper.UnknownId, match="ecce_arm.nope"):
            session.model("model0").run_experiment(
                dict(EXPERIMENT, record=[ELBOW, "ecce_arm.nope"]))
        batch = caliper.run_batch(dict(EXPERIMENT, name="bad", set={"ecce_arm.nope": 1.0}),
                                  session, progress=False)
        assert batch.results == {} and "ecce_arm.nope" in batch.failures["bad"]


# -- Models lost, sessions side by side --------------------------------------------------------

def test_a_batch_finishes_every_run_when_a_model_is_killed():
    runs = dict(EXPERIMENT, duration_s=6.0, every_n_steps=100, record=[ELBOW],
                experiments=[{"name": "m", "sweep": {MASS: [0.5, 0.7, 0.9, 1.1, 1.3, 1.5]}}])
    names = [f"m-{k}" for k in range(6)]
    local = caliper.LocalSession(models=2, scene=SCENE)
    with local as session:
        victim = session.model("model1")
        out = {}

        def run():
            try:
                out["batch"] = caliper.run_batch(runs, session, progress=False,
                                                  wait_for_model_s=20)
            except BaseException as e:  # shown by the assertion below
                out["error"] = e

        worker = threading.Thread(target=run, daemon=True)
        worker.start()
        # kill model1 in the middle of one of its runs (6000 steps each)
        deadline = time.monotonic() + 30
        while True:
            status = victim.status()
            if "(experiment" in status.scene and 0 < status.steps < 5000:
                break
            assert time.monotonic() < deadline, f"model1 never ran an experiment: {status}"
            assert worker.is_alive(), out
            time.sleep(0.002)
        interrupted = status.scene
        local.kill("model1")
        worker.join(60)
        assert not worker.is_alive(), "the batch did not finish within 60 s"
        assert "error" not in out, out.get("error")
        batch = out["batch"]
        assert list(batch.results) == names
        assert batch.failures == {}
        assert len(batch.lost) >= 1 and "model1" in batch.lost[0], batch.lost
        # the interrupted run was done again elsewhere, and every result is what a single
        # run gives
        assert interrupted.split("(experiment ")[1].rstrip(")") in names
        survivor = session.model("model0")
        for run in experiments_of(runs):
            assert equal(batch[run.name], survivor.run_experiment(run)), run.name


def test_a_failed_connect_leaves_the_open_sessions_usable():
    """A program may hold several sessions (a batch on one, a reference run on another). A
    connection attempt that fails (a session still starting: LocalSession polls its naming
    service until it answers; a wrong address) must not break the sessions already open, nor
    their Models."""
    with caliper.LocalSession(models=1, scene=SCENE) as first:
        model = first.model("model0")
        assert model.status().state != "FAULTED"
        with pytest.raises(caliper.ConnectionError):
            caliper.connect("corbaname::127.0.0.1:9", timeout_s=2)  # nothing listens there
        assert len(first.models()) == 1
        assert model.status().scene.endswith("ecce_arm.dae")
        with caliper.LocalSession(models=1, scene=SCENE) as second:
            assert second.model("model0").status().steps == 0
            model.step(5)
            assert model.status().steps == 5
            assert len(first.model("model0").run_experiment(dict(EXPERIMENT,
                                                                 duration_s=0.1))) == 11


# -- calibration ---------------------------------------------------------------------------------

TRUTH = {MASS: 1.3, RESISTANCE: 0.75}  # the scene has 1.0 kg and 0.516 ohm
RUNS = {
    "scene": SCENE, "every_n_steps": 10, "record": [ELBOW, HAND],
    "experiments": [
        {"name": "swing", "duration_s": 1.5,
         "commands": [[0.0, "elbow_flexor", 6.0], [0.8, "elbow_flexor", 0.0],
                      [0.8, "elbow_extensor", 3.0]]},
        {"name": "hold", "duration_s": 1.0,
         "commands": [[0.0, "elbow_flexor", 3.0], [0.0, "elbow_extensor", 1.0]]},
    ],
}
COLUMNS = [ELBOW, HAND + "[2]"]


@pytest.fixture(scope="class")
def calibration(session, tmp_path_factory):
    """A calibration file in the shape of examples/calibration/calibration.json: 2 experiments,
    measured CSVs made here by runs with the true parameters, 2 parameters to fit."""
    d = tmp_path_factory.mktemp("calibration")
    (d / "runs.json").write_text(json.dumps(RUNS))
    model = session.model("model0")
    measured = {}
    for e in RUNS["experiments"]:
        one = {k: v for k, v in RUNS.items() if k != "experiments"}
        one.update(e, set=TRUTH)
        data = model.run_experiment(one)
        measured[e["name"]] = data
        lines = [f"time [s],{ELBOW} [rad],{HAND}[2] [m]"]
        lines += [f"{t!r},{q!r},{z!r}" for t, q, z in
                  zip(data.time.tolist(), data[ELBOW].tolist(), data[HAND][:, 2].tolist())]
        (d / f"{e['name']}.csv").write_text("\n".join(lines) + "\n")
    spec = {
        "experiments": "runs.json",
        "measured": {"swing": "swing.csv", "hold": "hold.csv"},
        "parameters": [{"id": MASS, "lower": 0.5, "upper": 2.5, "scale": "linear"},
                       {"id": RESISTANCE, "lower": 0.3, "upper": 3.0, "scale": "log"}],
        "channels": [{"id": ELBOW, "weight": 2}, {"id": HAND + "[2]", "weight": 1}],
        "optimiser": {"algorithm": "cmaes", "generations": 10, "population": 6, "sigma0": 0.2},
        "seed": 7,
    }
    (d / "calibration.json").write_text(json.dumps(spec))
    cal = caliper.Calibration(d / "calibration.json", session)
    return cal, measured, d


class TestCalibration:
    """caliper.Calibration on measurements made with known parameters."""

    def test_calibration_reads_the_file(self, calibration, session):
        cal, _, _ = calibration
        assert [p.id for p in cal.parameters] == [MASS, RESISTANCE]
        assert cal.bounds == [(0.5, 2.5), (0.3, 3.0)]
        assert [p.log_scale for p in cal.parameters] == [False, True]
        assert cal.initial == pytest.approx([1.5, np.sqrt(0.3 * 3.0)])
        assert cal.models == 2

    def test_calibration_cost_is_zero_at_the_truth_and_larger_elsewhere(self, calibration):
        cal, _, _ = calibration
        truth = [TRUTH[MASS], TRUTH[RESISTANCE]]
        assert cal.cost(truth) < 1e-9
        for wrong in ([1.0, 0.75], [1.3, 0.6], [1.5, 1.0], list(cal.initial)):
            assert cal.cost(wrong) > 1e-3, wrong
        # farther is worse, along the mass
        assert cal.cost([1.0, 0.75]) > cal.cost([1.2, 0.75]) > cal.cost(truth)

    def test_calibration_costs_equal_cost_of_each_vector(self, calibration):
        cal, _, _ = calibration
        vectors = [[1.3, 0.75], [1.0, 0.75], [1.5, 1.0], [0.8, 2.0], [2.0, 0.4]]
        before = cal.evaluations
        costs = cal.costs(vectors)
        assert cal.evaluations == before + len(vectors)
        assert isinstance(costs, np.ndarray) and costs.shape == (len(vectors),)
        assert np.array_equal(costs, [cal.cost(v) for v in vectors])
        assert costs[0] < 1e-9 and np.all(costs[1:] > 1e-3)

    def test_calibration_evaluate_returns_recordings_and_parts_per_channel(self, calibration):
        cal, measured, _ = calibration
        truth = cal.evaluate([TRUTH[MASS], TRUTH[RESISTANCE]])
        assert not truth.faulted and truth.fault == ""
        assert truth.cost < 1e-9
        # per experiment, the simulated recording: with the true values it is the measurement
        assert len(truth.recordings) == 2
        for rec, name in zip(truth.recordings, ["swing", "hold"]):
            assert rec.ids() == [ELBOW, HAND]
            assert equal(rec, measured[name])
        assert [len(r) for r in truth.recordings] == [151, 101]
        # per experiment and measured column: weight, RMS error, measured range, samples
        assert [c.column for c in truth.channels] == COLUMNS * 2
        assert [c.weight for c in truth.channels] == [2.0, 1.0, 2.0, 1.0]
        assert [c.samples for c in truth.channels] == [151, 151, 101, 101]
        assert all(c.rms == 0.0 for c in truth.channels)
        swing_range = measured["swing"][ELBOW].max() - measured["swing"][ELBOW].min()
        assert truth.channels[0].range == pytest.approx(swing_range, rel=1e-12)

        wrong = cal.evaluate([1.0, 0.75])
        assert wrong.cost == cal.cost([1.0, 0.75])
        assert all(c.rms > 0 for c in wrong.channels)
        # the cost is sqrt(weighted mean of (rms / range)^2) over the channels
        parts = np.array([(c.weight, c.rms / c.range) for c in wrong.channels])
        assert wrong.cost == pytest.approx(np.sqrt(np.sum(parts[:, 0] * parts[:, 1] ** 2) /
                                                   np.sum(parts[:, 0])), rel=1e-12)
        # the recording differs where the cost says it does
        rms = np.sqrt(np.mean((wrong.recordings[0][ELBOW] - measured["swing"][ELBOW]) ** 2))
        assert rms == pytest.approx(wrong.channels[0].rms, rel=1e-9)

        bare = cal.evaluate([1.0, 0.75], keep_recordings=False)
        assert bare.recordings == [] and bare.cost == wrong.cost

        with pytest.raises(ValueError):
            cal.cost([1.3])  # one value per parameter
        with pytest.raises(ValueError):
            cal.cost([np.nan, 0.75])

    def test_a_bounded_search_over_the_mass_moves_to_the_truth(self, calibration):
        cal, _, _ = calibration
        resistance = TRUTH[RESISTANCE]
        start = cal.initial[0]
        result = scipy.optimize.minimize_scalar(
            lambda m: cal.cost([m, resistance]), bounds=cal.bounds[0], method="bounded",
            options={"maxiter": 15, "xatol": 1e-3})
        assert result.nfev <= 16
        assert abs(result.x - TRUTH[MASS]) < abs(start - TRUTH[MASS])
        assert abs(result.x - TRUTH[MASS]) < 0.01, result
        assert result.fun < cal.cost([start, resistance]) / 10

    def test_a_bad_calibration_file_raises_format_error(self, session, tmp_path, calibration):
        _, _, d = calibration
        spec = json.loads((d / "calibration.json").read_text())
        spec["experiments"] = str(d / "runs.json")
        spec["measured"] = {"swing": str(d / "swing.csv")}  # nothing for "hold"
        path = tmp_path / "calibration.json"
        path.write_text(json.dumps(spec))
        with pytest.raises(caliper.FormatError, match="hold"):
            caliper.Calibration(path, session)
