"""tests/docs/run_doc_blocks.py passes the pages it should and fails the ones it should, naming
why, on the small pages in tests/docs/fixtures/. Each run takes seconds.

The runner checks that a page leaves the checkout as it was; here its checkout is a new empty git
repository (CALIPER_SOURCE_DIR), so that a fixture that writes into "the checkout" does not touch
this one and the edits of others do not fail the fixtures."""

import os
import re
import subprocess
import time

import pytest

ROOT = os.path.abspath(os.environ.get("CALIPER_SOURCE_DIR")
                       or os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
RUNNER = os.path.join(ROOT, "tests", "docs", "run_doc_blocks.py")
FIXTURES = os.path.join(ROOT, "tests", "docs", "fixtures")
BIN = os.environ.get("CALIPER_BIN_DIR") or os.path.join(ROOT, "build", "bin")


@pytest.fixture
def checkout(tmp_path):
    """A git repository standing in for the checkout."""
    root = tmp_path / "checkout"
    root.mkdir()
    subprocess.run(["git", "init", "-q", str(root)], check=True, timeout=30)
    return root


def run(checkout, *args, timeout=60, **env):
    environment = dict(os.environ, CALIPER_SOURCE_DIR=str(checkout), CALIPER_BIN_DIR=BIN, **env)
    pages = [os.path.join(FIXTURES, a) if a.endswith(".md") else a for a in args]
    started = time.monotonic()
    with subprocess.Popen(["/usr/bin/python3", RUNNER, *pages], stdout=subprocess.PIPE,
                          stderr=subprocess.PIPE, text=True, env=environment) as p:
        try:
            stdout, stderr = p.communicate(timeout=timeout)
        except subprocess.TimeoutExpired:
            p.kill()
            raise
    result = subprocess.CompletedProcess(p.args, p.returncode, stdout, stderr)
    result.seconds = time.monotonic() - started
    result.pid = p.pid  # the runner's: its network namespaces are named cdt<pid>-...
    return result


def test_usage_errors_exit_2(checkout):
    assert run(checkout).returncode == 2
    assert run(checkout, "--frobnicate", "pass.md").returncode == 2
    result = run(checkout, "no-such-page.md")
    assert result.returncode == 2 and "no such file" in result.stderr


def test_list_prints_blocks_and_options_without_running(checkout):
    result = run(checkout, "--list", "pass.md")
    assert result.returncode == 0, result.stdout + result.stderr
    out = result.stdout
    assert "pass.md: 9 blocks" in out  # the ```text and ```py blocks are not counted
    assert re.search(r"pass\.md:\d+ \[sh\]  background; ready: server \.\* is up", out)
    assert re.search(r"pass\.md:\d+ \[sh\]  skip: needs another machine", out)
    assert re.search(r"pass\.md:\d+ \[python\]  fails; expect: ValueError: boom", out)
    assert "HOME=" not in out and " ok (" not in out


def test_a_page_whose_blocks_pass(checkout):
    # the caller's session must not reach the page
    result = run(checkout, "pass.md", CALIPER_NAMESERVICE="corbaname::127.0.0.1:1",
                 CALIPER_SOCKET_DIR="/nonexistent")
    out = result.stdout
    assert result.returncode == 0, out + result.stderr
    assert len(re.findall(r"^\S+pass\.md:\d+ \[sh\] ok \(\d+\.\d s\)$", out, re.M)) == 3
    assert re.search(r"\[sh\] started in the background \(ready in \d+\.\d s\)", out)
    assert re.search(r"\[sh\] ok \(failed as expected, \d+\.\d s\)", out)
    assert re.search(r"\[sh\] skipped: needs another machine", out)
    assert len(re.findall(r"\[python\] ok \(\d+\.\d s\)", out)) == 2
    assert re.search(r"\[python\] ok \(failed as expected", out)
    assert re.search(r"\[sh\] ok \(background, stopped at the end of the page", out)
    assert "pass.md: passed in" in out
    assert result.seconds < 20


FAILING = [
    ("fail_sh.md", r"fail_sh\.md:3 \[sh\] FAILED \(exit status 1, .*\n  the block:\n"
                   r"    echo \"before the failure\"\n(.*\n)*    \| before the failure\n"
                   r"(.*\n)*.*1 later block\(s\) not run after the failure"),
    ("fail_expect.md", r"FAILED \(its output does not match expect: \^goodbye\$"),
    ("fail_fails.md", r"FAILED \(it succeeded but is marked 'fails'"),
    ("fail_timeout.md", r"fail_timeout\.md:4 \[sh\] FAILED \(timed out after 1 s"),
    ("fail_python.md", r"FAILED \(it raised an exception(.*\n)*"
                       r".*fail_python\.md\", line 5, in divide\n(.*\n)*.*ZeroDivisionError"),
    ("fail_python_timeout.md", r"\[python\] FAILED \(timed out after 1 s(.*\n)*"
                               r".*1 later block\(s\) not run"),
    ("fail_background.md", r"FAILED \(exited \(status 3\) before its output matched ready: is up"),
    ("bad_marker.md", r"bad_marker\.md:4: unknown doc-test option 'retry'"),
    ("bad_fails.md", r"bad_fails\.md:\d+: 'fails' needs 'expect'"),
    ("bad_fence.md", r"bad_fence\.md:\d+: a ```bash block is never run"),
]


@pytest.mark.parametrize("page,message", FAILING, ids=[p for p, _ in FAILING])
def test_a_page_that_must_fail(checkout, page, message):
    result = run(checkout, page)
    assert result.returncode == 1, result.stdout + result.stderr
    assert re.search(message, result.stdout), result.stdout
    assert result.seconds < 20


def test_a_page_that_writes_into_the_checkout_fails(checkout):
    result = run(checkout, "fail_litter.md")
    assert result.returncode == 1, result.stdout + result.stderr
    assert re.search(r"\[sh\] ok \(", result.stdout)  # the block itself passed
    assert "FAILED: the page changed the checkout" in result.stdout
    assert "    new: litter.tmp" in result.stdout
    assert (checkout / "litter.tmp").exists()


def test_one_failing_page_fails_the_run(checkout):
    result = run(checkout, "pass.md", "fail_expect.md")
    assert result.returncode == 1
    assert "pass.md: passed" in result.stdout and "fail_expect.md: FAILED" in result.stdout


def test_processes_a_page_left_running_are_stopped(checkout):
    result = run(checkout, "leftover.md")
    assert result.returncode == 0, result.stdout + result.stderr
    assert "stopped 1 process(es) the page left running: sleep" in result.stdout
    for pid in filter(str.isdigit, os.listdir("/proc")):
        try:
            with open(f"/proc/{pid}/cmdline", "rb") as f:
                assert f.read() != b"sleep\x007771\x00", f"pid {pid} still runs"
        except OSError:
            pass


@pytest.mark.skipif(os.geteuid() != 0, reason="host: blocks run in network namespaces: root only")
def test_blocks_on_hosts_a_b_c(checkout):
    result = run(checkout, "host.md")
    assert result.returncode == 0, result.stdout + result.stderr
    assert re.search(r"host\.md:\d+ \[sh\] started in the background", result.stdout)
    assert re.search(r"host\.md:\d+ \[sh\] ok \(background, stopped", result.stdout)
    names = subprocess.run(["ip", "netns", "list"], capture_output=True, text=True,
                           timeout=30).stdout
    # this run's namespaces are removed (other tests' may exist meanwhile: ctest runs in
    # parallel, and the doc pages with host: blocks make their own)
    assert not re.search(rf"^cdt{result.pid}-", names, re.M), names
