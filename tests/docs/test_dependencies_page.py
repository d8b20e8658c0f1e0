"""docs/dependencies.md lists every package of launch/deps.txt and launch/deps-slurm.txt.

A package counts as listed when its name appears as a code span (`name`) in the first column of a
table row of the page, the Debian package column.
"""

import pathlib
import re

ROOT = pathlib.Path(__file__).resolve().parents[2]
PAGE = ROOT / "docs" / "dependencies.md"
DEPS = [ROOT / "launch" / "deps.txt", ROOT / "launch" / "deps-slurm.txt"]


def packages(path):
    """The package names of a deps file: one per line, text after '#' a comment."""
    names = []
    for line in path.read_text(encoding="utf-8").splitlines():
        line = line.split("#", 1)[0].strip()
        if line:
            names.extend(line.split())
    return names


def listed():
    names = set()
    for line in PAGE.read_text(encoding="utf-8").splitlines():
        if line.startswith("|"):
            first = line.strip().strip("|").split("|")[0]
            names.update(re.findall(r"`([^`]+)`", first))
    return names


def test_deps_files_have_packages():
    for path in DEPS:
        assert packages(path), f"{path.relative_to(ROOT)} lists no package"


def test_every_package_is_on_the_page():
    on_page = listed()
    missing = [f"{p}  ({path.relative_to(ROOT)})" for path in DEPS for p in packages(path)
               if p not in on_page]
    assert not missing, "missing from docs/dependencies.md:\n  " + "\n  ".join(missing)
