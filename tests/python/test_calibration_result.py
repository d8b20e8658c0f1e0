"""caliper.calibrate and caliper.CalibrationResult: a result folder read from a hand-written
result.json (nulls, an undetermined parameter, no intervals at all, bad files), and
caliper-calibrate run from Python on a private session of 2 Models against measurements made here
with known parameters (the fit, its intervals and progress; Ctrl-C keeps the best so far and
resume goes on; a file that does not exist)."""

import html
import json
import math
import time
from pathlib import Path

import numpy as np
import pytest

import caliper
from caliper.calibration import ChannelNoise, FittedParameter
from conftest import SCENE, start_session

ELBOW = "ecce_arm.elbow.position"
TENSION = "ecce_arm.elbow_flexor.tendon.tension"
MASS = "ecce_arm.forearm.mass"
STIFFNESS = "ecce_arm.elbow_flexor.stiffness"


# -- CalibrationResult.load on hand-written folders -------------------------------------------

def result_json(**changes):
    """A result.json in caliper-calibrate's shape: 3 parameters, the second not determined (its
    interval null), null correlation cells, no held-out experiments, texts that need escaping."""
    result = {
        "file": "/data/arm/calibration.json", "models": 4, "converged": False,
        "interrupted": False,
        "reason": "stopped: budget of 5 iterations spent & cost < 1 <still>",
        "global_search": {"reason": "converged: no improvement", "generations": 12,
                          "restarts": 1, "cost": 0.02},
        "refinement": {"reason": "stopped: budget of 5 iterations spent & cost < 1 <still>",
                       "iterations": 5, "evaluations": 31,
                       "history": [[7, 0.02], [14, 0.004], [21, 0.0011]]},
        "evaluations": 157, "wall_s": 12.5,
        "cost": {"initial": 0.25, "fitted": 0.0011, "noise_floor": 0.001},
        "held_out": {"experiments": [], "initial": None, "fitted": None},
        "parameters": [
            {"id": MASS, "unit": "kg", "initial": 1.0, "fitted": 1.31, "lower": 0.5,
             "upper": 2.0, "scale": "log", "sigma": 0.01, "lower95": 1.29, "upper95": 1.33,
             "determined": True, "most_sensitive_channel": "swing: " + ELBOW},
            {"id": "ecce_arm.elbow.spring_damping", "unit": "N m s/rad", "initial": 0.1,
             "fitted": 0.2, "lower": 0.05, "upper": 1.0, "scale": "log", "sigma": None,
             "lower95": None, "upper95": None, "determined": False,
             "most_sensitive_channel": ""},
            {"id": "odd<id>&", "unit": "N/m", "initial": 3000.0, "fitted": 4000.0,
             "lower": 1500.0, "upper": 8000.0, "scale": "linear", "sigma": 20.0,
             "lower95": 3960.0, "upper95": 4040.0, "determined": True,
             "most_sensitive_channel": "swing: " + TENSION},
        ],
        "correlation": [[1.0, None, 0.5], [None, None, None], [0.5, None, 1.0]],
        "noise": [{"experiment": "swing", "column": ELBOW, "unit": "rad", "sigma": 1e-3,
                   "samples": 151},
                  {"experiment": "swing", "column": TENSION, "unit": "N", "sigma": None,
                   "samples": 151}],
        "warnings": ["ecce_arm.elbow.spring_damping is not determined: <script>alert(1)</script>"],
    }
    result.update(changes)
    return result


def write(folder, result, tuned=False):
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "result.json").write_text(json.dumps(result, indent=2))
    if tuned:
        (folder / "tuned.dae").write_text("<COLLADA/>")
    return folder


def test_load_reads_every_attribute(tmp_path):
    out = write(tmp_path / "fit", result_json(), tuned=True)
    r = caliper.CalibrationResult.load(out)
    assert isinstance(r, caliper.CalibrationResult)
    assert r.converged is False and r.interrupted is False
    assert r.reason == "stopped: budget of 5 iterations spent & cost < 1 <still>"
    assert r.refinement_reason == r.reason
    assert r.global_reason == "converged: no improvement"
    assert r.file == Path("/data/arm/calibration.json")
    assert r.models == 4
    assert (r.generations, r.restarts, r.global_cost) == (12, 1, 0.02)
    assert (r.refinement_iterations, r.refinement_evaluations) == (5, 31)
    assert (r.evaluations, r.wall_s) == (157, 12.5)
    assert (r.cost_initial, r.cost, r.noise_floor) == (0.25, 0.0011, 0.001)
    assert r.held_out_cost is None and r.held_out_experiments == []
    assert isinstance(r.history, np.ndarray) and r.history.shape == (3, 2)
    assert r.history.tolist() == [[7, 0.02], [14, 0.004], [21, 0.0011]]

    # the parameters: the second is not determined, so its interval is unbounded
    assert all(isinstance(p, FittedParameter) for p in r.parameters)
    assert r.parameters[0] == FittedParameter(MASS, "kg", 1.0, 1.31, 0.01, 1.29, 1.33, True,
                                              0.5, 2.0)
    damping = r.parameters[1]
    assert damping.id == "ecce_arm.elbow.spring_damping" and damping.unit == "N m s/rad"
    assert (damping.initial, damping.fitted, damping.lower, damping.upper) == (0.1, 0.2, 0.05, 1.0)
    assert damping.determined is False
    assert damping.sigma == math.inf
    assert damping.lower95 == -math.inf and damping.upper95 == math.inf
    assert r.parameters[2].lower95 == 3960.0 and r.parameters[2].upper95 == 4040.0
    assert r.values == {MASS: 1.31, "ecce_arm.elbow.spring_damping": 0.2, "odd<id>&": 4000.0}
    assert r.intervals == {MASS: (1.29, 1.33),
                           "ecce_arm.elbow.spring_damping": (-math.inf, math.inf),
                           "odd<id>&": (3960.0, 4040.0)}

    # correlation: n x n, NaN where the program wrote null
    assert isinstance(r.correlation, np.ndarray) and r.correlation.shape == (3, 3)
    assert r.correlation.dtype == float
    nan = np.isnan(r.correlation)
    assert nan.tolist() == [[False, True, False], [True, True, True], [False, True, False]]
    assert r.correlation[0, 0] == 1.0 and r.correlation[0, 2] == 0.5 == r.correlation[2, 0]

    assert r.noise[0] == ChannelNoise("swing", ELBOW, "rad", 1e-3, 151)
    assert isinstance(r.noise[1], ChannelNoise) and math.isnan(r.noise[1].sigma)
    assert r.warnings == ["ecce_arm.elbow.spring_damping is not determined: "
                          "<script>alert(1)</script>"]

    # the files
    assert r.out == out.absolute() and r.out.is_absolute()
    assert r.report_html == out / "report.html"
    assert r.report_png == out / "report.png"
    assert r.tuned_scene == out / "tuned.dae"

    # a short repr, and a table for Jupyter with everything escaped
    text = repr(r)
    assert text.startswith("<caliper.CalibrationResult NOT converged") and "\n" not in text
    assert "0.25 -> 0.0011" in text and "3 parameters" in text and len(text) < 120
    page = r._repr_html_()
    assert "<table>" in page and page.count("<tr>") == 4  # a header, 3 parameters
    assert "<script>" not in page and "&lt;script&gt;alert(1)&lt;/script&gt;" in page
    assert html.escape(r.reason) in page and "<still>" not in page
    assert "<code>odd&lt;id&gt;&amp;</code>" in page and "odd<id>" not in page
    assert "not determined" in page and "[1.29, 1.33]" in page and "N m s/rad" in page


def test_load_without_intervals_or_tuned_scene(tmp_path):
    # an interrupted run: no uncertainty at all, a held-out experiment, no tuned scene
    result = result_json(interrupted=True, correlation=[], noise=[],
                         warnings=["no uncertainty: interrupted before the uncertainty was "
                                   "computed"],
                         held_out={"experiments": ["gentle"], "initial": 0.3, "fitted": 0.01})
    result["refinement"]["history"] = []
    for p in result["parameters"]:
        for key in ("sigma", "lower95", "upper95", "determined", "most_sensitive_channel"):
            del p[key]
    r = caliper.CalibrationResult.load(write(tmp_path / "fit", result))
    assert r.interrupted is True and r.tuned_scene is None
    assert all(not p.determined and p.sigma == math.inf and p.lower95 == -math.inf
               and p.upper95 == math.inf for p in r.parameters)
    assert r.correlation.shape == (3, 3) and np.all(np.isnan(r.correlation))
    assert r.noise == [] and r.history.shape == (0, 2)
    assert r.held_out_cost == (0.3, 0.01) and r.held_out_experiments == ["gentle"]
    assert "interrupted" in repr(r)
    assert "held-out 0.3 &rarr; 0.01" in r._repr_html_()


def test_load_of_a_folder_that_is_not_a_result(tmp_path):
    with pytest.raises(FileNotFoundError):
        caliper.CalibrationResult.load(tmp_path / "nothing")
    (tmp_path / "broken").mkdir()
    (tmp_path / "broken" / "result.json").write_text("{")
    with pytest.raises(caliper.FormatError, match="result.json"):
        caliper.CalibrationResult.load(tmp_path / "broken")
    result = result_json()
    del result["cost"]
    with pytest.raises(caliper.FormatError, match="cost"):
        caliper.CalibrationResult.load(write(tmp_path / "short", result))
    with pytest.raises(caliper.FormatError, match="correlation"):
        caliper.CalibrationResult.load(write(tmp_path / "square", result_json(
            correlation=[[1.0]])))


@pytest.mark.parametrize("argument", [{"generations": -1}, {"iterations": 1.5},
                                      {"islands": 0}, {"run_timeout_s": 0}])
def test_calibrate_refuses_bad_arguments_before_it_starts(tmp_path, argument):
    with pytest.raises(ValueError, match=list(argument)[0]):
        caliper.calibrate(tmp_path / "calibration.json", session="corbaname::127.0.0.1:9",
                          **argument)


# -- caliper-calibrate from Python -------------------------------------------------------------

TRUTH = {MASS: 1.3, STIFFNESS: 4000.0}  # the scene has 1.0 kg and 3000 N/m
EXPERIMENT = {
    "scene": SCENE, "duration_s": 1.5, "every_n_steps": 10, "record": [ELBOW, TENSION],
    "commands": [[0, "elbow_flexor", 6], [0.7, "elbow_flexor", 1], [0.7, "elbow_extensor", 5]],
}


@pytest.fixture(scope="module")
def fit(tmp_path_factory):
    """A private session of 2 Models, and a calibration file of 2 parameters whose measurements
    were made here with TRUTH."""
    local = start_session(models=2)
    try:
        d = tmp_path_factory.mktemp("fit")
        data = local.model("model0").run_experiment(dict(EXPERIMENT, set=TRUTH))
        lines = [f"time [s],{ELBOW} [rad],{TENSION} [N]"]
        lines += [f"{t!r},{q!r},{f!r}" for t, q, f in
                  zip(data.time.tolist(), data[ELBOW].tolist(), data[TENSION].tolist())]
        (d / "swing.csv").write_text("\n".join(lines) + "\n")
        (d / "runs.json").write_text(json.dumps(dict(EXPERIMENT, experiments=[{"name": "swing"}])))
        local.model("model0").load(SCENE)  # the scene's own values again
        spec = {
            "experiments": "runs.json",
            "measured": {"swing": "swing.csv"},
            "parameters": [{"id": MASS, "lower": 0.5, "upper": 2, "scale": "log"},
                           {"id": STIFFNESS, "lower": 1500, "upper": 8000, "scale": "log"}],
            "optimiser": {"algorithm": "cmaes", "generations": 3, "population": 6},
            "refinement": {"iterations": 15},
            "seed": 7,
        }
        (d / "calibration.json").write_text(json.dumps(spec))
        yield local, d
    finally:
        local.close()


def test_calibrate_fits_the_truth_with_intervals(fit, tmp_path, monkeypatch):
    local, d = fit
    monkeypatch.chdir(tmp_path)  # the default result folder goes here
    lines = []
    started = time.monotonic()
    r = caliper.calibrate(d / "calibration.json", session=local, progress=lines.append)
    wall = time.monotonic() - started
    print(f"caliper.calibrate: {wall:.2f} s, {r.evaluations} evaluations ({r.wall_s:.2f} s in "
          f"the program)")
    assert r.out == tmp_path / "calibration-calibration"  # the program's default
    assert (r.out / "result.json").is_file()
    assert isinstance(r.converged, bool) and r.reason
    assert r.interrupted is False and r.models == 2
    assert r.file == d / "calibration.json"

    assert [p.id for p in r.parameters] == [MASS, STIFFNESS]
    assert [p.initial for p in r.parameters] == [1.0, 3000.0]
    assert r.values[MASS] == pytest.approx(TRUTH[MASS], rel=0.01)
    assert r.values[STIFFNESS] == pytest.approx(TRUTH[STIFFNESS], rel=0.01)
    for p in r.parameters:
        assert p.determined, p
        assert math.isfinite(p.lower95) and math.isfinite(p.upper95), p
        assert p.lower95 < p.fitted < p.upper95, p
        assert 0 < p.sigma < math.inf
        assert r.intervals[p.id] == (p.lower95, p.upper95)
    assert r.correlation.shape == (2, 2)
    assert np.all(np.diag(r.correlation) == 1.0)
    assert r.correlation[0, 1] == r.correlation[1, 0] and abs(r.correlation[0, 1]) <= 1

    assert r.cost < r.cost_initial / 100
    assert r.generations == 3 and 1 <= r.refinement_iterations <= 15
    assert r.history.shape == (len(r.history), 2) and len(r.history) >= 1
    assert r.evaluations > 0 and r.wall_s > 0
    assert [n.column for n in r.noise] == [ELBOW, TENSION]
    assert r.held_out_cost is None

    # the progress lines came to the callable as they were written
    assert any(line.startswith("gen 1/3") for line in lines), lines
    assert any(line.startswith("refine ") for line in lines), lines
    assert r.report_html.is_file() and r.report_png.is_file()
    assert r.tuned_scene is not None and r.tuned_scene.is_file()
    assert f"{TRUTH[MASS]:.3g}" in r._repr_html_()
    assert wall < 40, wall


def test_an_interrupted_calibration_keeps_its_best_and_resumes(fit, tmp_path):
    local, d = fit
    out = tmp_path / "interrupted"
    lines, pressed = [], []

    def ctrl_c_after_the_first_generation(line):
        lines.append(line)
        if line.startswith("gen 1/") and not pressed:
            pressed.append(line)
            raise KeyboardInterrupt  # as Ctrl-C would, once

    with pytest.raises(KeyboardInterrupt):
        caliper.calibrate(d / "calibration.json", out, session=local.session, generations=40,
                          progress=ctrl_c_after_the_first_generation)
    # caliper-calibrate ended, having written its best so far; its last words came too
    assert any(line.startswith("interrupted: keeping the best so far") for line in lines), lines
    r = caliper.CalibrationResult.load(out)
    assert r.interrupted is True and r.converged is False
    assert 1 <= r.generations < 40 and r.refinement_iterations == 0
    assert r.cost <= r.cost_initial
    assert all(not p.determined and p.sigma == math.inf for p in r.parameters)
    assert any(w.startswith("no uncertainty") for w in r.warnings), r.warnings

    # --resume goes on from the checkpoint: one generation more, no refinement
    lines.clear()
    again = caliper.calibrate(d / "calibration.json", out, session=local.address,
                              generations=r.generations + 1, iterations=0, resume=True,
                              progress=lines.append)
    assert any(line.startswith("resuming at generation") for line in lines), lines
    assert again.interrupted is False and again.generations == r.generations + 1
    assert again.refinement_iterations == 0 and again.cost <= r.cost


def test_a_calibration_that_fails_raises_error_with_the_program_s_words(fit, tmp_path):
    local, _ = fit
    missing = tmp_path / "no_such_calibration.json"
    with pytest.raises(caliper.Error, match="no_such_calibration.json") as e:
        caliper.calibrate(missing, tmp_path / "out", session=local, progress=False)
    assert "exit 1" in str(e.value)
