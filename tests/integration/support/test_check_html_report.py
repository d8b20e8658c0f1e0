"""check_html_report.py on hand-made pages: one whose embedded PNG loads passes, one with a broken
data: URI fails naming the check, too few images fail, nothing is left in HOME or the temporary
folder (however deep TMPDIR is), and without chromium it skips (77).
Skipped when chromium is not installed."""

import base64
import io
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import pytest
from PIL import Image, ImageDraw

CHECKER = Path(__file__).resolve().parent / "check_html_report.py"


def png_base64():
    """A plot-sized picture, a band of ink across it (a page must have more than 1 % ink)."""
    picture = Image.new("RGB", (900, 300), "white")
    ImageDraw.Draw(picture).rectangle((40, 100, 860, 200), fill=(200, 40, 40))
    data = io.BytesIO()
    picture.save(data, "PNG")
    return base64.b64encode(data.getvalue()).decode("ascii")


def page(folder, images):
    """A report-like page with the given image sources."""
    figures = "\n".join(f'<figure><img src="{src}" alt="plot {i}"></figure>'
                        for i, src in enumerate(images))
    path = folder / "report.html"
    path.write_text(f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>Calibration report: fixture</title>
<style>body {{ font-family: sans-serif; }} td {{ border: 1px solid #888; }}</style></head>
<body><h1>Calibration report: fixture</h1>
<table><tr><th>parameter</th><th>fitted</th></tr><tr><td>k</td><td>1.5</td></tr></table>
{figures}
</body></html>
""", encoding="utf-8")
    return path


def check(report, screenshot, *options, env=None):
    return subprocess.run([sys.executable, str(CHECKER), str(report), str(screenshot), *options],
                          capture_output=True, text=True, timeout=300, env=env)


@pytest.fixture
def chromium():
    if shutil.which("chromium") is None:
        pytest.skip("chromium not installed (apt install chromium)")


def test_a_page_whose_png_loads_passes_and_leaves_nothing_behind(tmp_path, chromium):
    report = page(tmp_path, [f"data:image/png;base64,{png_base64()}"])
    screenshot = tmp_path / "screenshot.png"
    home = tmp_path / "home"
    home.mkdir()
    # a short TMPDIR (chromium puts a unix socket in it): the checker's folder goes there
    with tempfile.TemporaryDirectory(dir="/tmp") as temporary:
        result = check(report, screenshot, env=dict(os.environ, HOME=str(home), TMPDIR=temporary))
        assert result.returncode == 0, result.stdout + result.stderr
        assert os.listdir(temporary) == [], "the temporary folder was left behind"
    assert list(home.iterdir()) == [], "chromium wrote into HOME"
    assert "ok   images loaded: 1 of 1" in result.stdout
    assert "'Calibration report: fixture', 1 tables" in result.stdout
    assert "screenshot not blank" in result.stdout
    with Image.open(screenshot) as shot:
        assert shot.size == (1200, 3000)


def test_a_deep_tmpdir_works(tmp_path, chromium):
    report = page(tmp_path, [f"data:image/png;base64,{png_base64()}"])
    deep = tmp_path / ("deep" * 10) / ("deeper" * 10)
    deep.mkdir(parents=True)
    result = check(report, tmp_path / "screenshot.png", env=dict(os.environ, TMPDIR=str(deep)))
    assert result.returncode == 0, result.stdout + result.stderr


def test_a_broken_data_uri_fails_the_loaded_check(tmp_path, chromium):
    broken = "data:image/png;base64," + png_base64()[:40] + "!!not-base64!!"
    report = page(tmp_path, [f"data:image/png;base64,{png_base64()}", broken])
    result = check(report, tmp_path / "screenshot.png")
    assert result.returncode == 1, result.stdout + result.stderr
    assert "FAIL images loaded: 1 of 2 did not load" in result.stdout


def test_too_few_images_fail(tmp_path, chromium):
    report = page(tmp_path, [f"data:image/png;base64,{png_base64()}"])
    result = check(report, tmp_path / "screenshot.png", "--min-images", "3")
    assert result.returncode == 1, result.stdout + result.stderr
    assert "FAIL images: 1 on the page, expected at least 3" in result.stdout


def test_without_chromium_it_skips(tmp_path):
    report = page(tmp_path, [])
    empty = tmp_path / "bin"
    empty.mkdir()
    result = check(report, tmp_path / "screenshot.png", env=dict(os.environ, PATH=str(empty)))
    assert result.returncode == 77, result.stdout + result.stderr
    assert result.stdout.strip() == "SKIP: chromium not installed (apt install chromium)"
    assert not (tmp_path / "screenshot.png").exists()
