#!/usr/bin/python3
"""Checks a self-contained HTML report in headless Chromium: its pictures load and it renders.

    check_html_report.py REPORT.html SCREENSHOT.png [--min-images N]

A copy of the page, with a small test-side script appended, is loaded with --dump-dom: on load
the script writes the number of images, how many loaded, the title and the number of tables
into the DOM as JSON (<pre id="caliper-check">). Then the original page is screenshotted to
SCREENSHOT.png, which must not be blank. One line per check; exit 0 when all pass, 1 naming the
failing check, 77 (skip) when chromium is not installed.
"""

import argparse
import html
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
from pathlib import Path

TIMEOUT_S = 60
# chromium puts a unix socket (at most 107 bytes) ~45 bytes deep in its TMPDIR, here our temporary
# folder: under a deeper TMPDIR than this, that folder goes in /tmp
MAX_TEMPORARY_PARENT = 40
# a page is blank when at most this fraction of the screenshot's pixels is not white
MIN_INK = 0.01

PROBE = """<script>
window.addEventListener("load", function () {
  var images = Array.prototype.slice.call(document.images);
  var result = {
    images: images.length,
    loaded: images.filter(function (i) { return i.complete && i.naturalWidth > 0; }).length,
    title: document.title,
    tables: document.getElementsByTagName("table").length
  };
  var pre = document.createElement("pre");
  pre.id = "caliper-check";
  pre.textContent = JSON.stringify(result);
  document.body.appendChild(pre);
});
</script>
"""


class CheckFailed(Exception):
    pass


def run_chromium(chromium, args, home, profile):
    """Runs chromium headless with a private profile, HOME and TMPDIR (HOME's parent); returns
    its stdout (text)."""
    env = dict(os.environ, HOME=str(home), XDG_CONFIG_HOME=str(home / ".config"),
               XDG_CACHE_HOME=str(home / ".cache"), TMPDIR=str(home.parent))
    command = [chromium, "--headless=new", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
               "--no-first-run", "--no-default-browser-check", f"--user-data-dir={profile}"] + args
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=env,
                               start_new_session=True)
    try:
        out, err = process.communicate(timeout=TIMEOUT_S)
    except subprocess.TimeoutExpired:
        os.killpg(process.pid, signal.SIGKILL)
        process.communicate()
        raise CheckFailed(f"chromium did not finish within {TIMEOUT_S} s")
    finally:
        # helpers chromium left behind in its own session (the group we started)
        try:
            os.killpg(process.pid, signal.SIGKILL)
        except (ProcessLookupError, PermissionError):
            pass
    if process.returncode != 0:
        tail = err.decode(errors="replace").strip().splitlines()[-5:]
        raise CheckFailed(f"chromium exited with {process.returncode}: " + " | ".join(tail))
    return out.decode(errors="replace")


def with_probe(page):
    """The page with PROBE before its last </body> (at its end when it has none)."""
    at = page.lower().rfind("</body>")
    return page + PROBE if at < 0 else page[:at] + PROBE + page[at:]


def ink(screenshot):
    """The fraction of the picture's pixels that are not white."""
    from PIL import Image, ImageChops

    with Image.open(screenshot) as picture:
        rgb = picture.convert("RGB")
    difference = ImageChops.difference(rgb, Image.new("RGB", rgb.size, "white")).convert("L")
    histogram = difference.histogram()
    total = rgb.size[0] * rgb.size[1]
    return (total - histogram[0]) / total if total else 0.0, rgb.size


def check(report, screenshot, min_images, chromium, work):
    home = work / "home"
    home.mkdir()
    # the probe runs in a copy: the report itself stays as written
    copy = work / "page" / report.name
    copy.parent.mkdir()
    copy.write_text(with_probe(report.read_text(encoding="utf-8", errors="replace")),
                    encoding="utf-8")
    dom = run_chromium(chromium, ["--dump-dom", "--virtual-time-budget=5000", copy.as_uri()],
                       home, work / "profile-dom")
    found = re.search(r'<pre id="caliper-check">(.*?)</pre>', dom, re.S)
    if not found:
        raise CheckFailed("page load: the probe did not report (the page never loaded)")
    result = json.loads(html.unescape(found.group(1)))
    print(f"ok   page load: title {result['title']!r}, {result['tables']} tables")

    if result["images"] < min_images:
        raise CheckFailed(f"images: {result['images']} on the page, expected at least {min_images}")
    print(f"ok   images: {result['images']} (at least {min_images})")
    if result["loaded"] != result["images"]:
        raise CheckFailed(f"images loaded: {result['images'] - result['loaded']} of "
                          f"{result['images']} did not load")
    print(f"ok   images loaded: {result['loaded']} of {result['images']}")

    if screenshot.exists():
        screenshot.unlink()
    run_chromium(chromium, [f"--screenshot={screenshot}", "--window-size=1200,3000",
                            report.as_uri()], home, work / "profile-screenshot")
    if not screenshot.is_file() or screenshot.stat().st_size == 0:
        raise CheckFailed(f"screenshot: {screenshot} was not written")
    print(f"ok   screenshot: {screenshot}")
    fraction, size = ink(screenshot)
    if fraction <= MIN_INK:
        raise CheckFailed(f"screenshot not blank: only {100 * fraction:.2f} % of "
                          f"{size[0]}x{size[1]} pixels are not white")
    print(f"ok   screenshot not blank: {100 * fraction:.1f} % of {size[0]}x{size[1]} pixels "
          "are not white")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("report", type=Path, help="the HTML page to check")
    parser.add_argument("screenshot", type=Path, help="where to write the page's screenshot (PNG)")
    parser.add_argument("--min-images", type=int, default=1, metavar="N",
                        help="the page must have at least N images (default 1)")
    args = parser.parse_args()

    chromium = shutil.which("chromium")
    if chromium is None:
        print("SKIP: chromium not installed (apt install chromium)")
        return 77
    report = args.report.resolve()
    if not report.is_file():
        print(f"FAIL report: {args.report} is not a file")
        return 1
    screenshot = args.screenshot.resolve()
    parent = tempfile.gettempdir()
    if len(parent) > MAX_TEMPORARY_PARENT:
        parent = "/tmp"
    with tempfile.TemporaryDirectory(prefix="caliper-check-", dir=parent) as work:
        try:
            check(report, screenshot, args.min_images, chromium, Path(work))
        except CheckFailed as e:
            print(f"FAIL {e}")
            return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
