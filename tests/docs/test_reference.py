"""The generated reference pages (docs/reference/) agree with the code, and the check that says so
can fail: launch/reference.py --check.

Needs CALIPER_BIN_DIR (the build's bin/; ctest sets it). Run from the root of the checkout:
  CALIPER_BIN_DIR=build/bin /usr/bin/python3 -m pytest -q tests/docs/test_reference.py
"""

import os
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
REFERENCE = ROOT / "launch" / "reference.py"


def bin_dir():
    directory = os.environ.get("CALIPER_BIN_DIR")
    if not directory:
        pytest.skip("CALIPER_BIN_DIR is not set (ctest sets it)")
    return directory


def reference(*args):
    return subprocess.run(["/usr/bin/python3", str(REFERENCE), "--bin-dir", bin_dir(), *args],
                          cwd=ROOT, capture_output=True, text=True, timeout=120)


def test_committed_pages_agree_with_the_code():
    result = reference("--check")
    assert result.returncode == 0, result.stdout[-4000:] + result.stderr


def test_check_names_a_page_that_differs(tmp_path):
    # ctl.md only: a page from --help output, and quick to make
    made = reference("--out", str(tmp_path), "--only", "ctl.md")
    assert made.returncode == 0, made.stderr
    page = tmp_path / "ctl.md"
    lines = page.read_text().splitlines(True)
    index = next(i for i, line in enumerate(lines) if line.startswith("Usage: caliper-ctl batch"))
    lines[index] = lines[index].replace("batch", "batches", 1)
    page.write_text("".join(lines))

    result = reference("--check", "--pages", str(tmp_path), "--only", "ctl.md")
    assert result.returncode == 1, result.stdout + result.stderr
    assert "docs/reference/ctl.md is stale: run `launch/caliper docs` to regenerate" in result.stderr
    assert "-Usage: caliper-ctl batches" in result.stdout
    assert "+Usage: caliper-ctl batch" in result.stdout


def test_check_passes_on_pages_just_made(tmp_path):
    # the pages do not depend on the machine or the moment: made twice, they are equal
    made = reference("--out", str(tmp_path), "--only", "environment.md", "--only", "file-formats.md")
    assert made.returncode == 0, made.stderr
    result = reference("--check", "--pages", str(tmp_path), "--only", "environment.md",
                       "--only", "file-formats.md")
    assert result.returncode == 0, result.stdout + result.stderr
