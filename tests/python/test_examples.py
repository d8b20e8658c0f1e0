"""The examples of examples/python run as a newcomer runs them: each script with its default
options (its own private session, figures into ./results), as a subprocess of this interpreter
in a fresh folder; the key figures they print are checked, and so are their PNGs. The notebook
runs in a Jupyter kernel (nbconvert's ExecutePreprocessor) without a cell error and shows its
plots."""

import os
import re
import subprocess
import sys
import time

import pytest

ROOT = os.path.abspath(os.environ.get("CALIPER_SOURCE_DIR")
                       or os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
EXAMPLES = os.path.join(ROOT, "examples", "python")
TIMEOUT_S = 240  # each takes a few seconds; this is for a loaded machine


def example_env():
    """This process's environment (ctest sets PYTHONPATH and CALIPER_BIN_DIR), else the build
    tree's; matplotlib without a display."""
    env = dict(os.environ)
    env.setdefault("PYTHONPATH", os.path.join(ROOT, "build", "python"))
    env.setdefault("CALIPER_BIN_DIR", os.path.join(ROOT, "build", "bin"))
    # absolute: the examples run in another folder
    env["PYTHONPATH"] = os.pathsep.join(os.path.abspath(p) for p in
                                        env["PYTHONPATH"].split(os.pathsep) if p)
    env["CALIPER_BIN_DIR"] = os.path.abspath(env["CALIPER_BIN_DIR"])
    env["MPLBACKEND"] = "Agg"
    env.pop("CALIPER_NAMESERVICE", None)  # the examples start their own sessions anyway
    return env


def run(script, cwd, *args):
    """Runs an example; returns its stdout after asserting exit 0."""
    started = time.monotonic()
    p = subprocess.run([sys.executable, os.path.join(EXAMPLES, script), *args], cwd=cwd,
                       env=example_env(), capture_output=True, text=True, timeout=TIMEOUT_S)
    wall_s = time.monotonic() - started
    assert p.returncode == 0, (f"{script} {' '.join(args)} exited {p.returncode} after "
                               f"{wall_s:.1f} s\n--- stdout\n{p.stdout}\n--- stderr\n{p.stderr}")
    print(f"{script} {' '.join(args)}: {wall_s:.1f} s")
    return p.stdout


def number(pattern, text):
    m = re.search(pattern, text, re.MULTILINE)
    assert m, f"no match of {pattern!r} in:\n{text}"
    return float(m.group(1))


def figures(out, cwd):
    """The figures an example printed (`figure: PATH`), each checked to be a real plot."""
    paths = re.findall(r"^figure: (.+)$", out, re.MULTILINE)
    assert paths, f"no figure printed:\n{out}"
    for path in paths:
        assert os.path.dirname(path) == os.path.join(str(cwd), "results"), path
        check_png(path)
    return paths


def check_png(path):
    from PIL import Image  # Debian's python3-pil
    with open(path, "rb") as f:
        head = f.read(8)
    assert head == b"\x89PNG\r\n\x1a\n", f"{path} is not a PNG"
    assert os.path.getsize(path) > 15_000, f"{path}: {os.path.getsize(path)} bytes"
    with Image.open(path) as image:
        image.verify()
    with Image.open(path) as image:
        width, height = image.size
        assert 500 <= width <= 3000 and 300 <= height <= 2000, (path, image.size)
        # a plot (lines, text, legends) has many colours; an empty or failed figure has few
        colours = image.convert("RGB").getcolors(maxcolors=1 << 20)
        assert colours is not None and len(colours) > 50, (path, len(colours or []))


def test_pd_elbow(tmp_path):
    out = run("pd_elbow.py", tmp_path)
    # the angle every 0.5 s: 13 rows from 0 to 6 s
    rows = re.findall(r"^\s+(\d+\.\d\d)\s+(-?\d+\.\d+)\s+(-?\d+\.\d+)\s+(\d+\.\d+)\s+(\d+\.\d+)$",
                      out, re.MULTILINE)
    assert [float(r[0]) for r in rows] == pytest.approx([0.5 * i for i in range(13)]), out
    assert all(0.0 <= float(v) <= 6.0 for r in rows for v in r[3:]), out  # clamped to 0..6 V
    assert float(rows[0][1]) == 0.0 and float(rows[-1][1]) > 0.7, out
    assert number(r"^final error: (\S+) rad$", out) < 0.1
    assert number(r"^final elbow angle: (\S+) rad", out) == pytest.approx(0.8, abs=0.1)
    figures(out, tmp_path)
    assert os.path.isfile(tmp_path / "results" / "pd_elbow.png")


def test_pd_elbow_options(tmp_path):
    png = tmp_path / "pd.png"
    out = run("pd_elbow.py", tmp_path, "--duration-s", "1", "--target-rad", "0.3",
              "--plot", str(png))
    assert re.search(r"target 0\.300 rad", out), out
    check_png(str(png))
    out = run("pd_elbow.py", tmp_path, "--help")
    assert "--nameservice" in out and "--latest" in out and "[V/rad]" in out


def test_mass_sweep(tmp_path):
    out = run("mass_sweep.py", tmp_path)
    assert re.search(r"6 runs done, 0 failed, on 2 Models", out), out
    rows = [tuple(map(float, r)) for r in re.findall(
        r"^\s+(\d+\.\d\d)\s+(-?\d+\.\d{4})\s+(-?\d+\.\d{4})\s+(\d+\.\d\d)$", out, re.MULTILINE)]
    assert [r[0] for r in rows] == [0.5, 1.0, 1.5, 2.0, 2.5, 3.0], out
    finals, peaks = [r[1] for r in rows], [r[2] for r in rows]
    # a heavier forearm ends lower and peaks lower
    assert all(a > b for a, b in zip(finals, finals[1:])), finals
    assert all(a > b for a, b in zip(peaks, peaks[1:])), peaks
    assert all(p > f > 0 for p, f in zip(peaks, finals)), rows
    figures(out, tmp_path)
    table = (tmp_path / "results" / "mass_sweep.csv").read_text().splitlines()
    assert table[0] == "mass [kg],final angle [rad],peak angle [rad],peak time [s]"
    assert len(table) == 7


def test_read_recording(tmp_path):
    out = run("read_recording.py", tmp_path)
    assert "channels (4):" in out, out
    for line in (r"ecce_arm\.elbow\.position\s+\[rad\]\s+scalar",
                 r"ecce_arm\.elbow_flexor\.tendon\.tension\s+\[N\]\s+scalar",
                 r"ecce_arm\.hand\.position\s+\[m\]\s+shape \(3,\)"):
        assert re.search(line, out), (line, out)
    assert re.search(r"^events by kind: command 6, end 1, keyframe 30, parameter 1$", out,
                     re.MULTILINE), out
    assert re.search(r"t =  1\.000 s \(step   1000\)  parameter ecce_arm\.forearm\.mass = 1\.5",
                     out), out
    assert re.search(r"^keyframes: 30 at 0\.0, 0\.1, .* every 0\.100 s$", out, re.MULTILINE), out
    assert "samples: 300 from 0.010 to 3.000 s" in out, out
    figures(out, tmp_path)
    copy = tmp_path / "results" / "read_recording.caliper"
    csv = (tmp_path / "results" / "read_recording.csv").read_text().splitlines()
    assert csv[0].startswith("time [s],ecce_arm.elbow.position [rad]"), csv[0]
    assert len(csv) == 301
    # a file given: read without a session, and verified bit for bit
    out = run("read_recording.py", tmp_path, str(copy), "--verify", "--channel",
              "ecce_arm.hand.position")
    assert "session:" not in out, out
    assert re.search(r"^verify \(.*\): IDENTICAL: identical: 3000 steps", out, re.MULTILINE), out
    figures(out, tmp_path)


def test_episodes(tmp_path):
    out = run("episodes.py", tmp_path)
    rows = re.findall(r"^\s+(random|PD)\s+(\d+)\s+(\d+\.\d+)\s+(-\d+\.\d+)\s+(\d+\.\d+)\s+"
                      r"(-?\d+\.\d+)$", out, re.MULTILINE)
    assert len(rows) == 6, out
    masses = {}
    for policy, seed, mass, ret, error, final in rows:
        assert 0.5 <= float(mass) <= 2.0
        assert float(ret) == pytest.approx(-500 * float(error), rel=1e-3)
        masses.setdefault(seed, set()).add(mass)
        if policy == "PD":
            assert abs(float(final) - 0.8) < 0.1, out
    assert all(len(m) == 1 for m in masses.values()), masses  # a seed draws the same mass
    random = number(r"^mean return: random (\S+) rad", out)
    pd = number(r"^mean return: random \S+ rad, PD (\S+) rad", out)
    assert pd > random + 100, out  # the PD policy's error is far smaller
    m = re.search(r"returns (\S+) and (\S+) rad, masses (\S+) and (\S+) kg, angles identical: "
                  r"(\w+)", out)
    assert m and m.group(1) == m.group(2) and m.group(3) == m.group(4) and m.group(5) == "True", out
    assert re.search(r"^VectorEnv of 2 on model0@\S+, model1@\S+: 500 steps", out,
                     re.MULTILINE), out
    vector = re.findall(r"env (\d) \(model\d@\S+\): mass (\S+) kg, PD return (\S+) rad, final "
                        r"angle (\S+) rad", out)
    assert len(vector) == 2 and vector[0][1] != vector[1][1], out  # seeds 10 and 11
    assert all(abs(float(v[3]) - 0.8) < 0.1 for v in vector), out
    figures(out, tmp_path)


def test_notebook(tmp_path, monkeypatch):
    import nbformat
    from nbconvert.preprocessors import CellExecutionError, ExecutePreprocessor

    path = os.path.join(EXAMPLES, "getting_started.ipynb")
    nb = nbformat.read(path, as_version=4)
    nbformat.validate(nb)
    code = [c for c in nb.cells if c.cell_type == "code"]
    assert code and all(not c.outputs and c.execution_count is None for c in code), \
        "the notebook is stored with outputs"
    assert sum(c.cell_type == "markdown" for c in nb.cells) >= len(code) // 2
    for key, value in example_env().items():  # the kernel inherits this process's environment
        if key in ("PYTHONPATH", "CALIPER_BIN_DIR", "MPLBACKEND"):
            monkeypatch.setenv(key, value)
    monkeypatch.setenv("PYDEVD_DISABLE_FILE_VALIDATION", "1")
    started = time.monotonic()
    try:
        ExecutePreprocessor(timeout=TIMEOUT_S, kernel_name="python3").preprocess(
            nb, {"metadata": {"path": str(tmp_path)}})
    except CellExecutionError as e:
        pytest.fail(f"a cell of the notebook failed:\n{e}")
    print(f"getting_started.ipynb: {time.monotonic() - started:.1f} s")
    outputs = [o for c in nb.cells if c.cell_type == "code" for o in c.outputs]
    assert not [o for o in outputs if o.output_type == "error"]
    images = [o for o in outputs if "image/png" in o.get("data", {})]
    assert len(images) >= 2, f"{len(images)} plots"
    text = "".join(o.get("text", "") for o in outputs if o.output_type == "stream")
    fitted = number(r"fitted forearm mass (\S+) kg", text)
    assert fitted == pytest.approx(1.4, rel=0.05), text
    assert "done in" in text, text


def test_co_contraction(tmp_path):
    out = run("co_contraction.py", tmp_path)
    # the windings heat toward the maximum; the driver derates before they reach it. The
    # figures docs/actuators.md quotes (121.50 degC, from 80 s, 4.124 A), within what a change
    # of the step's rounding could move
    highest = number(r"^highest winding temperature: ([0-9.]+) degC", out)
    assert abs(highest - 121.5) < 0.5, out
    derating_from = number(r"^the driver derated from ([0-9.]+) s", out)
    assert abs(derating_from - 80) < 2, out
    final = number(r"final current ([0-9.]+) A against a limit of 6 A", out)
    assert abs(final - 4.124) < 0.05, out
    figures(out, tmp_path)
