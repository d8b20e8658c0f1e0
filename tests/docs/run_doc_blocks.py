#!/usr/bin/python3
"""Runs the fenced blocks of documentation pages as a newcomer would, and fails when one fails.

    /usr/bin/python3 tests/docs/run_doc_blocks.py [--list] [--keep] PAGE.md [PAGE.md...]

The convention (docs/tests.md, "Documentation tests"): ```sh blocks run with bash, in order, the
working directory and the exported environment carried from one to the next; ```python blocks run
in one Python interpreter per page, sharing one namespace; every other fence is not run. An HTML
comment on the line right before a fence changes how the block runs:

    <!-- doc-test: skip: REASON | background | ready: REGEX | host: a|b|c | expect: REGEX |
                   fails | timeout: S -->   (several, separated by "; ")

Each page starts from nothing: a new empty HOME and XDG_RUNTIME_DIR, the working directory the
root of the checkout, CALIPER_NO_BUILD=1, the package `caliper` importable (as `launch/caliper
python --env` exports), no CALIPER_NAMESERVICE or other setting of the caller. After the page,
every process it started is stopped (background blocks get SIGINT, then TERM after 15 s, then
KILL), and the page fails when `git status --porcelain` of the checkout changed.

--list prints the blocks and their options without running them; --keep keeps each page's
temporary HOME and the blocks' output files and prints where they are. Exit status: 0 when every
page passed, 1 when a block failed, 2 on bad usage.
"""

import json
import os
import pwd
import re
import select
import shlex
import shutil
import signal
import subprocess
import sys
import tempfile
import time

ROOT = os.path.abspath(os.environ.get("CALIPER_SOURCE_DIR") or
                       os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
PYTHON = "/usr/bin/python3"
RUN_LANGUAGES = ("sh", "python")
#: fences that look runnable but are not: refused, so that no command hides from the test
#: (```py stays allowed: snippets that need the reader's own session, shown, never run)
SHELL_LOOKALIKES = ("bash", "shell", "zsh", "console", "shell-session")
DEFAULT_TIMEOUT_S = 300.0
READY_TIMEOUT_S = 120.0      # the longest wait for a background block's `ready:`
STOP_GRACE_S = 15.0          # SIGINT -> TERM of background blocks at the end of a page
KILL_GRACE_S = 5.0           # TERM -> KILL
FINISH_TIMEOUT_S = 60.0      # closing the page's Python interpreter (and its LocalSessions)
TAIL_LINES = 60
HOSTS = ("a", "b", "c")  # 198.51.100.1, .2, .3 (tests/integration/support/netns_hosts.sh)
OPTION_NAMES = ("skip", "background", "ready", "host", "expect", "fails", "timeout")
#: what a page keeps of the caller's environment (everything else, CALIPER_NAMESERVICE,
#: CALIPER_SOCKET_DIR, PYTHONPATH, ..., is left out so that a page starts from nothing)
KEEP_ENV = ("PATH", "DISPLAY", "XAUTHORITY", "LANG", "LANGUAGE", "TZ", "USER", "LOGNAME", "SHELL",
            "TERM", "TMPDIR", "LIBGL_ALWAYS_SOFTWARE", "http_proxy", "https_proxy", "no_proxy",
            "HTTP_PROXY", "HTTPS_PROXY", "NO_PROXY", "CALIPER_BIN_DIR", "CALIPER_BUILD_DIR")
#: variables bash sets by itself, not carried from one sh block to the next
SHELL_OWN = ("_", "SHLVL", "PWD")
MARKER_RE = re.compile(r"^\s*<!--\s*doc-test:\s*(.*?)\s*-->\s*$")
FENCE_RE = re.compile(r"^(\s*)(`{3,}|~{3,})\s*([^`\s]*)[^`]*$")
OPTION_SPLIT_RE = re.compile(r";\s*(?=(?:%s)\b)" % "|".join(OPTION_NAMES))

# The page's Python interpreter: reads one JSON request a line on fd CMD, runs the block with its
# stdout and stderr (fds 1 and 2, so also its child processes') in the request's output file,
# answers {"ok": bool} on fd RES. Line numbers in tracebacks are the page's.
PYTHON_SERVER = r"""
import json, os, sys, traceback
requests = os.fdopen(int(sys.argv[1]), "rb")
answers = os.fdopen(int(sys.argv[2]), "wb", buffering=0)
namespace = {"__name__": "__main__", "__builtins__": __builtins__}

def output_to(path):
    sys.stdout.flush(); sys.stderr.flush()
    fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_APPEND, 0o644)
    os.dup2(fd, 1); os.dup2(fd, 2); os.close(fd)

def run(request):
    try:
        code = compile("\n" * request["line"] + request["code"], request["file"], "exec")
        exec(code, namespace)
        return True
    except BaseException as e:  # also SystemExit and KeyboardInterrupt: the block failed
        traceback.print_exception(type(e), e, e.__traceback__.tb_next)
        return False
    finally:
        sys.stdout.flush(); sys.stderr.flush()

def finish():
    caliper = sys.modules.get("caliper")
    local = getattr(caliper, "LocalSession", None)
    for value in list(namespace.values()):
        if local is not None and isinstance(value, local):
            try:
                value.close()
            except BaseException:
                traceback.print_exc()

for line in requests:
    request = json.loads(line)
    output_to(request["out"])
    if request["op"] == "run":
        answers.write((json.dumps({"ok": run(request)}) + "\n").encode())
    else:
        finish()
        answers.write(b'{"ok": true}\n')
        break
"""


class PageError(Exception):
    """A page that cannot be run as written (a bad marker, a missing file, no root for host:)."""


class Block:
    def __init__(self, page, line, language, code, options):
        self.page, self.line, self.language, self.code = page, line, language, code
        self.options = options
        self.path = page         # the file (set by main to its absolute path)
        self.process = None      # a running sh block (background)
        self.out = None          # its output file
        self.started = 0.0

    @property
    def where(self):
        return f"{self.page}:{self.line} [{self.language}]"

    def timeout_s(self):
        return float(self.options.get("timeout", DEFAULT_TIMEOUT_S))

    def describe_options(self):
        return "; ".join(k if v is True else f"{k}: {v}" for k, v in self.options.items())


def parse_options(text, where):
    options = {}
    for part in OPTION_SPLIT_RE.split(text):
        part = part.strip()
        if not part:
            continue
        name, _, value = part.partition(":")
        name, value = name.strip(), value.strip()
        if name not in OPTION_NAMES:
            raise PageError(f"{where}: unknown doc-test option '{name}' "
                            f"(known: {', '.join(OPTION_NAMES)})")
        if name in ("background", "fails"):
            if value:
                raise PageError(f"{where}: '{name}' takes no value")
            options[name] = True
            continue
        if not value:
            raise PageError(f"{where}: '{name}' needs a value ('{name}: ...')")
        if name in ("ready", "expect"):
            try:
                re.compile(value, re.M)
            except re.error as e:
                raise PageError(f"{where}: '{name}: {value}' is not a regular expression: {e}")
        if name == "host" and value not in HOSTS:
            raise PageError(f"{where}: 'host: {value}': the hosts are a, b and c")
        if name == "timeout":
            try:
                if float(value) <= 0:
                    raise ValueError
            except ValueError:
                raise PageError(f"{where}: 'timeout: {value}' is not a positive number of seconds")
        options[name] = value
    return options


def extract(page, display):
    """The page's sh and python blocks, in order, with their options. Raises PageError."""
    try:
        lines = open(page, encoding="utf-8").read().split("\n")
    except OSError as e:
        raise PageError(f"{display}: {e.strerror}")
    blocks, i, pending = [], 0, None
    while i < len(lines):
        marker = MARKER_RE.match(lines[i])
        if marker:
            if pending is not None:
                raise PageError(f"{display}:{pending[0]}: a doc-test marker not right before "
                                "a fence")
            pending = (i + 1, marker.group(1))
            i += 1
            continue
        fence = FENCE_RE.match(lines[i])
        if not fence:
            if pending is not None:
                raise PageError(f"{display}:{pending[0]}: a doc-test marker must be on the line "
                                "right before a fence")
            i += 1
            continue
        indent, ticks, language = len(fence.group(1)), fence.group(2), fence.group(3)
        start = i + 1
        body, i = [], i + 1
        close_re = re.compile(r"^\s*%s%s*\s*$" % (re.escape(ticks), re.escape(ticks[0])))
        while i < len(lines) and not close_re.match(lines[i]):
            line = lines[i]
            body.append(line[min(indent, len(line) - len(line.lstrip(" "))):])
            i += 1
        if i == len(lines):
            raise PageError(f"{display}:{start}: a fence that is never closed")
        i += 1
        where = f"{display}:{start}"
        options = parse_options(pending[1], where) if pending else {}
        if pending and language not in RUN_LANGUAGES:
            raise PageError(f"{where}: a doc-test marker on a ```{language or '(no language)'} "
                            "block, which is never run")
        pending = None
        if language in SHELL_LOOKALIKES:
            # a shell block under another name would silently never run
            raise PageError(f"{where}: a ```{language} block is never run: write ```sh (run) or "
                            "```text (output)")
        if language not in RUN_LANGUAGES:
            continue
        if "ready" in options and "background" not in options:
            raise PageError(f"{where}: 'ready' needs 'background'")
        if "background" in options and "fails" in options:
            raise PageError(f"{where}: a background block cannot be 'fails'")
        if "fails" in options and "expect" not in options:
            raise PageError(f"{where}: 'fails' needs 'expect' (the error the page shows: any "
                            "failure, even a command not found, would pass otherwise)")
        if language == "python" and ("background" in options or "host" in options):
            raise PageError(f"{where}: python blocks run in the page's interpreter: no "
                            "'background' or 'host' (use a sh block)")
        blocks.append(Block(display, start, language, "\n".join(body) + "\n", options))
    if pending is not None:
        raise PageError(f"{display}:{pending[0]}: a doc-test marker at the end of the page")
    return blocks


def tail(path, n=TAIL_LINES):
    try:
        with open(path, "rb") as f:
            text = f.read().decode("utf-8", "replace")
    except OSError:
        return ""
    lines = text.rstrip("\n").split("\n")
    return "\n".join(lines[-n:])


def read_text(path):
    try:
        with open(path, "rb") as f:
            return f.read().decode("utf-8", "replace")
    except OSError:
        return ""


def kill_group(process, sig):
    try:
        os.killpg(process.pid, sig)
    except (ProcessLookupError, PermissionError):
        pass


def wait(process, timeout):
    try:
        return process.wait(timeout=max(timeout, 0.0))
    except subprocess.TimeoutExpired:
        return None


def stop_group(process, first=signal.SIGTERM, grace=KILL_GRACE_S):
    """Signals the block's process group, then TERM and KILL, each after its grace. Returns the
    signal that stopped the leader."""
    kill_group(process, first)
    if wait(process, grace) is not None:
        return first
    if first != signal.SIGTERM:
        kill_group(process, signal.SIGTERM)
        if wait(process, KILL_GRACE_S) is not None:
            return signal.SIGTERM
    kill_group(process, signal.SIGKILL)
    wait(process, KILL_GRACE_S)
    return signal.SIGKILL


#: ignored folders of the build and of tools' caches (others may write them meanwhile, e.g. a
#: pytest run elsewhere in the checkout): not checked
BUILD_OUTPUT_RE = re.compile(r"^(build([-_][^/]*)?|\.cache)/|(^|/)(\.pytest_cache|__pycache__)/")


def fingerprint(path):
    """(mtime, size) of a file; of a folder (an ignored one: git shows it whole), the number of
    files, their total size and the newest mtime in it."""
    try:
        st = os.lstat(path)
    except OSError:
        return None
    if not os.path.isdir(path) or os.path.islink(path):
        return (st.st_mtime_ns, st.st_size)
    files = size = newest = 0
    for folder, dirs, names in os.walk(path):
        for name in names + dirs:
            try:
                st = os.lstat(os.path.join(folder, name))
            except OSError:
                continue
            files, size, newest = files + 1, size + st.st_size, max(newest, st.st_mtime_ns)
        if files > 100000:
            break
    return (files, size, newest)


def checkout_state():
    """{path: (status, fingerprint)} of `git status --porcelain`, also of the files and folders
    that .gitignore hides (results/, ...) except the build's: None when ROOT is not a git
    checkout."""
    try:
        result = subprocess.run(["git", "--no-optional-locks", "-C", ROOT, "status", "--porcelain",
                                 "-z", "--untracked-files=all", "--ignored=matching"],
                                capture_output=True, timeout=60)
    except (OSError, subprocess.TimeoutExpired):
        return None
    if result.returncode != 0:
        return None
    state, entries = {}, result.stdout.decode("utf-8", "surrogateescape").split("\0")
    i = 0
    while i < len(entries):
        entry = entries[i]
        i += 1
        if len(entry) < 4:
            continue
        code, path = entry[:2], entry[3:]
        if code[0] in "RC":
            i += 1  # the rename's source
        if code == "!!" and BUILD_OUTPUT_RE.search(path):
            continue
        state[path] = (code, fingerprint(os.path.join(ROOT, path)))
    return state


class Namespaces:
    """Network namespaces "host a/b/c" (198.51.100.1-3/24, lo up) joined by a bridge in a
    namespace of its own, named with a prefix unique to this run: made and removed by
    tests/integration/support/netns_hosts.sh, the network tests' own definition."""

    SCRIPT = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
                          "integration", "support", "netns_hosts.sh")

    def __init__(self):
        self.prefix = f"cdt{os.getpid()}"
        self.made = False

    def ns(self, host):
        return f"{self.prefix}-{host}"

    def make(self):
        if os.geteuid() != 0:
            raise PageError("the page has host: blocks, which run in network namespaces: that "
                            "needs root (run the documentation tests as root, as CI does)")
        if shutil.which("ip") is None:
            raise PageError("the page has host: blocks and there is no 'ip' command "
                            "(apt-get install iproute2)")
        self.made = True  # whatever part was made goes in cleanup
        result = subprocess.run(["bash", self.SCRIPT, "make", self.prefix], capture_output=True,
                                text=True, timeout=60)
        if result.returncode != 0:
            raise PageError(f"the network namespaces: {result.stderr.strip()}")

    def cleanup(self):
        if not self.made:
            return
        try:
            subprocess.run(["bash", self.SCRIPT, "remove", self.prefix], capture_output=True,
                           timeout=60)
        except (OSError, subprocess.TimeoutExpired):
            pass
        self.made = False


class PageRun:
    """Runs one page's blocks in a fresh environment."""

    def __init__(self, display, blocks, keep):
        self.display, self.blocks, self.keep = display, blocks, keep
        self.tmp = tempfile.mkdtemp(prefix="caliper-doc-test-")
        self.home = os.path.join(self.tmp, "home")
        self.work = os.path.join(self.tmp, "runner")  # the runner's files, outside HOME
        for d in (self.home, self.work):
            os.makedirs(d, mode=0o700)
        self.tag = f"{os.getpid()}-{os.path.basename(self.tmp)}"
        self.env = self.base_env()
        self.cwd = ROOT
        self.python = None           # the page's interpreter: (process, requests, answers)
        self.python_dead = None      # why it is gone
        self.background = []
        self.namespaces = None
        self.failed = False
        self.counter = 0

    def runtime_dir(self, host=None):
        path = os.path.join(self.tmp, f"run-{host}" if host else "run")
        os.makedirs(path, mode=0o700, exist_ok=True)
        return path

    def base_env(self):
        env = {k: os.environ[k] for k in KEEP_ENV if k in os.environ}
        env.update({k: v for k, v in os.environ.items() if k.startswith("LC_")})
        if "XAUTHORITY" not in env and os.path.exists(os.path.expanduser("~/.Xauthority")):
            env["XAUTHORITY"] = os.path.expanduser("~/.Xauthority")
        build = env.get("CALIPER_BUILD_DIR")
        if not build and env.get("CALIPER_BIN_DIR"):
            build = os.path.dirname(os.path.abspath(env["CALIPER_BIN_DIR"]))
            env["CALIPER_BUILD_DIR"] = build
        build = build or os.path.join(ROOT, "build")
        env.setdefault("PATH", "/usr/local/bin:/usr/bin:/bin")
        try:  # a reader's login shell always has them, a test runner's environment not always
            user = pwd.getpwuid(os.getuid())
            env.setdefault("USER", user.pw_name)
            env.setdefault("LOGNAME", user.pw_name)
            env.setdefault("SHELL", user.pw_shell or "/bin/bash")
        except KeyError:
            pass
        env.update({
            "HOME": self.home,
            "XDG_RUNTIME_DIR": self.runtime_dir(),
            "CALIPER_NO_BUILD": "1",
            "PYTHONPATH": os.path.join(build, "python"),  # as `launch/caliper python --env`
            "CALIPER_BIN_DIR": env.get("CALIPER_BIN_DIR") or os.path.join(build, "bin"),
            "PYTHONDONTWRITEBYTECODE": "1",
            "CALIPER_DOC_TEST_RUN": self.tag,  # finds every process of the page at its end
        })
        return env

    def new_file(self, block, kind):
        self.counter += 1
        return os.path.join(self.work, f"{self.counter:03d}-line{block.line}.{kind}")

    # ------------------------------------------------------------------ reporting
    def report_ok(self, block, seconds, note=""):
        print(f"{block.where} ok ({note}{seconds:.1f} s)", flush=True)

    def report_failed(self, block, reason, out=None, seconds=None):
        self.failed = True
        took = f", {seconds:.1f} s" if seconds is not None else ""
        print(f"{block.where} FAILED ({reason}{took})", flush=True)
        print("  the block:")
        for line in block.code.rstrip("\n").split("\n"):
            print("    " + line)
        if out is not None:
            text = tail(out)
            print(f"  its last {TAIL_LINES} lines of output:" if text else "  its output: (none)")
            for line in text.split("\n") if text else []:
                print("    | " + line)
        sys.stdout.flush()

    def check_output(self, block, out, code_ok):
        """The reason the finished block failed, or None."""
        if not code_ok:
            return None
        expect = block.options.get("expect")
        if expect and not re.search(expect, read_text(out), re.M):
            return f"its output does not match expect: {expect}"
        return None

    # ------------------------------------------------------------------ sh
    def sh_command(self, block, script):
        command = ["bash", "-c", script]
        host = block.options.get("host")
        if host:
            command = ["ip", "netns", "exec", self.namespaces.ns(host)] + command
        return command

    def sh_env(self, block):
        env = dict(self.env)
        host = block.options.get("host")
        # each "host" has its own runtime directory, as separate machines would
        if env.get("XDG_RUNTIME_DIR", "").startswith(self.tmp):
            env["XDG_RUNTIME_DIR"] = self.runtime_dir(host)
        return env

    def start_sh(self, block, state_prefix=None):
        out = self.new_file(block, "out")
        header = "set -euo pipefail; set -a"
        if state_prefix:
            header += (f"; trap '__doc_test_rc=$?; env -0 >{shlex.quote(state_prefix)}.env; "
                       f"pwd >{shlex.quote(state_prefix)}.pwd; exit $__doc_test_rc' EXIT")
        cwd = self.cwd if os.path.isdir(self.cwd) else ROOT
        with open(out, "wb") as f:
            process = subprocess.Popen(self.sh_command(block, header + "\n" + block.code),
                                       stdin=subprocess.DEVNULL, stdout=f, stderr=subprocess.STDOUT,
                                       cwd=cwd, env=self.sh_env(block), start_new_session=True)
        block.process, block.out, block.started = process, out, time.monotonic()
        return process, out

    def load_state(self, prefix):
        try:
            with open(prefix + ".env", "rb") as f:
                entries = f.read().decode("utf-8", "surrogateescape").split("\0")
            with open(prefix + ".pwd", encoding="utf-8", errors="surrogateescape") as f:
                cwd = f.read().rstrip("\n")
        except OSError:
            return
        env = {}
        for entry in entries:
            name, sep, value = entry.partition("=")
            if sep and name not in SHELL_OWN and not name.startswith("__doc_test"):
                env[name] = value
        env["CALIPER_DOC_TEST_RUN"] = self.tag
        self.env, self.cwd = env, cwd

    def run_sh(self, block):
        prefix = self.new_file(block, "state")
        process, out = self.start_sh(block, prefix)
        code = wait(process, block.timeout_s())
        seconds = time.monotonic() - block.started
        if code is None:
            stop_group(process)
            self.report_failed(block, f"timed out after {block.timeout_s():g} s", out, seconds)
            return False
        return self.judge(block, code == 0, f"exit status {code}", out, seconds,
                          lambda: self.load_state(prefix))

    def judge(self, block, succeeded, failure, out, seconds, on_pass=None):
        if "fails" in block.options and succeeded:
            self.report_failed(block, "it succeeded but is marked 'fails'", out, seconds)
            return False
        if "fails" not in block.options and not succeeded:
            self.report_failed(block, failure, out, seconds)
            return False
        reason = self.check_output(block, out, True)
        if reason:
            self.report_failed(block, reason, out, seconds)
            return False
        if on_pass:
            on_pass()
        self.report_ok(block, seconds, "failed as expected, " if not succeeded else "")
        return True

    def start_background(self, block):
        process, out = self.start_sh(block)
        self.background.append(block)
        ready = block.options.get("ready")
        if not ready:
            print(f"{block.where} started in the background", flush=True)
            return True
        limit = float(block.options.get("timeout", READY_TIMEOUT_S))
        deadline = block.started + limit
        while True:
            if re.search(ready, read_text(out), re.M):
                seconds = time.monotonic() - block.started
                print(f"{block.where} started in the background (ready in {seconds:.1f} s)",
                      flush=True)
                return True
            code = process.poll()
            if code is not None:
                self.background.remove(block)
                self.report_failed(block, f"exited (status {code}) before its output matched "
                                   f"ready: {ready}", out, time.monotonic() - block.started)
                return False
            if time.monotonic() > deadline:
                self.background.remove(block)
                stop_group(process, signal.SIGINT, STOP_GRACE_S)
                self.report_failed(block, f"its output did not match ready: {ready} within "
                                   f"{limit:g} s", out, time.monotonic() - block.started)
                return False
            time.sleep(0.1)

    def stop_background(self):
        """Ctrl-C to every background block, as a user would in each terminal; TERM after 15 s,
        KILL 5 s later. A block that needed them, exited with an error before, or whose output
        does not match its expect fails."""
        ended_before = {id(b): b.process.poll() for b in self.background}
        for block in self.background:
            if ended_before[id(block)] is None:
                kill_group(block.process, signal.SIGINT)
        deadline = time.monotonic() + STOP_GRACE_S
        for block in self.background:
            wait(block.process, deadline - time.monotonic())
        stubborn = [b for b in self.background if b.process.poll() is None]
        for block in stubborn:
            kill_group(block.process, signal.SIGTERM)
        deadline = time.monotonic() + KILL_GRACE_S
        for block in stubborn:
            if wait(block.process, deadline - time.monotonic()) is None:
                kill_group(block.process, signal.SIGKILL)
                wait(block.process, KILL_GRACE_S)
        for block in self.background:
            seconds = time.monotonic() - block.started
            code = ended_before[id(block)]
            if block in stubborn:
                self.report_failed(block, f"still running {STOP_GRACE_S:g} s after SIGINT "
                                   "(Ctrl-C) at the end of the page", block.out, seconds)
            elif code not in (None, 0):
                self.report_failed(block, f"exited with status {code} before the end of the "
                                   "page", block.out, seconds)
            elif self.check_output(block, block.out, True):
                self.report_failed(block, self.check_output(block, block.out, True), block.out,
                                   seconds)
            else:
                self.report_ok(block, seconds, "background, stopped at the end of the page, ")
        self.background = []

    # ------------------------------------------------------------------ python
    def start_python(self):
        requests_r, requests_w = os.pipe()
        answers_r, answers_w = os.pipe()
        log = os.path.join(self.work, "python.out")
        with open(log, "wb") as f:
            process = subprocess.Popen(
                [PYTHON, "-u", "-c", PYTHON_SERVER, str(requests_r), str(answers_w)],
                stdin=subprocess.DEVNULL, stdout=f, stderr=subprocess.STDOUT,
                cwd=self.cwd if os.path.isdir(self.cwd) else ROOT, env=dict(self.env),
                pass_fds=(requests_r, answers_w), start_new_session=True)
        os.close(requests_r)
        os.close(answers_w)
        self.python = (process, os.fdopen(requests_w, "wb", buffering=0), answers_r)

    def ask_python(self, request, timeout):
        """Sends a request; returns True/False (the block's result) or a string (why there is no
        answer)."""
        process, requests, answers = self.python
        try:
            requests.write((json.dumps(request) + "\n").encode())
        except BrokenPipeError:
            return f"the page's Python interpreter exited (status {process.poll()})"
        deadline, received = time.monotonic() + timeout, b""
        while True:
            left = deadline - time.monotonic()
            if left <= 0:
                return f"timed out after {timeout:g} s"
            ready, _, _ = select.select([answers], [], [], min(left, 0.5))
            if ready:
                chunk = os.read(answers, 4096)
                if not chunk:
                    wait(process, 5)
                    return f"the page's Python interpreter exited (status {process.poll()})"
                received += chunk
                if received.endswith(b"\n"):
                    return bool(json.loads(received)["ok"])

    def kill_python(self, why):
        process, requests, answers = self.python
        requests.close()  # after the KeyboardInterrupt, the interpreter reads the end and exits
        kill_group(process, signal.SIGINT)
        if wait(process, KILL_GRACE_S) is None:
            stop_group(process)
        os.close(answers)
        self.python, self.python_dead = None, why

    def run_python(self, block):
        out = self.new_file(block, "out")
        started = time.monotonic()
        if self.python_dead:
            self.report_failed(block, f"not run: {self.python_dead}")
            return False
        if self.python is None:
            self.start_python()
        answer = self.ask_python({"op": "run", "code": block.code, "line": block.line,
                                  "file": block.path,
                                  "out": out}, block.timeout_s())
        seconds = time.monotonic() - started
        if isinstance(answer, str):
            self.kill_python(f"the interpreter was stopped after {block.where}: {answer}")
            self.report_failed(block, answer, out, seconds)
            return False
        return self.judge(block, answer, "it raised an exception", out, seconds)

    def finish_python(self):
        if self.python is None:
            return True
        out = os.path.join(self.work, "python-finish.out")
        answer = self.ask_python({"op": "finish", "out": out}, FINISH_TIMEOUT_S)
        process = self.python[0]
        if answer is True and wait(process, 10) is not None:
            self.python[1].close()
            os.close(self.python[2])
            self.python = None
            return True
        self.kill_python("finished")
        print(f"{self.display}: FAILED (closing the page's Python interpreter and its "
              f"LocalSessions: {answer if isinstance(answer, str) else 'it did not exit'})")
        text = tail(out)
        for line in text.split("\n") if text else []:
            print("    | " + line)
        self.failed = True
        return False

    # ------------------------------------------------------------------ the page
    def leftovers(self):
        """Every process that carries this page's tag in its environment."""
        needle = f"CALIPER_DOC_TEST_RUN={self.tag}".encode() + b"\0"
        found = []
        for entry in os.listdir("/proc"):
            if not entry.isdigit() or int(entry) == os.getpid():
                continue
            try:
                with open(f"/proc/{entry}/environ", "rb") as f:
                    if needle in f.read():
                        found.append(int(entry))
            except OSError:
                pass
        return found

    def stop_leftovers(self):
        pids = self.leftovers()
        if not pids:
            return
        names = []
        for pid in pids:
            try:
                names.append(open(f"/proc/{pid}/comm").read().strip())
            except OSError:
                pass
            try:
                os.kill(pid, signal.SIGTERM)
            except ProcessLookupError:
                pass
        deadline = time.monotonic() + KILL_GRACE_S
        while time.monotonic() < deadline and self.leftovers():
            time.sleep(0.1)
        for pid in self.leftovers():
            try:
                os.kill(pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
        print(f"{self.display}: stopped {len(pids)} process(es) the page left running: "
              f"{', '.join(sorted(set(names)))}", flush=True)

    def run(self):
        before = checkout_state()
        print(f"{self.display}: {len(self.blocks)} blocks, HOME={self.home}", flush=True)
        try:
            if any("host" in b.options for b in self.blocks):
                self.namespaces = Namespaces()
                try:
                    self.namespaces.make()
                except (PageError, OSError, subprocess.TimeoutExpired) as e:
                    print(f"{self.display}: FAILED: {e}", flush=True)
                    self.failed = True
                    return False
            for index, block in enumerate(self.blocks):
                if "skip" in block.options:
                    print(f"{block.where} skipped: {block.options['skip']}", flush=True)
                    continue
                if block.language == "python":
                    passed = self.run_python(block)
                elif "background" in block.options:
                    passed = self.start_background(block)
                else:
                    passed = self.run_sh(block)
                if not passed:
                    rest = [b for b in self.blocks[index + 1:] if "skip" not in b.options]
                    if rest:
                        print(f"{self.display}: {len(rest)} later block(s) not run after the "
                              "failure", flush=True)
                    break
        finally:
            self.finish_python()
            self.stop_background()
            self.stop_leftovers()
            if self.namespaces:
                self.namespaces.cleanup()
            self.check_checkout(before)
            if self.keep:
                print(f"{self.display}: kept {self.tmp} (home/, runner/ has each block's output)")
            else:
                shutil.rmtree(self.tmp, ignore_errors=True)
        return not self.failed

    def check_checkout(self, before):
        after = checkout_state()
        if before is None or after is None:
            return
        changed = sorted(p for p in set(before) | set(after) if before.get(p) != after.get(p))
        if changed:
            self.failed = True
            print(f"{self.display}: FAILED: the page changed the checkout (write under ~ or a "
                  "session's folder instead):", flush=True)
            for path in changed:
                code = (after.get(path) or before[path])[0]
                if path not in after or "D" in code:
                    what = "removed or restored"
                elif path not in before and code in ("??", "!!"):
                    what = "new"
                else:
                    what = "changed"
                hidden = " (hidden by .gitignore)" if code == "!!" else ""
                print(f"    {what}: {path}{hidden}")
            sys.stdout.flush()


def list_blocks(display, blocks):
    print(f"{display}: {len(blocks)} blocks")
    for block in blocks:
        options = block.describe_options()
        lines = block.code.rstrip("\n").split("\n")
        print(f"{block.where}{'  ' + options if options else ''}")
        for line in lines[:3]:
            print("    " + line)
        if len(lines) > 3:
            print(f"    ... ({len(lines) - 3} more lines)")


def usage(message=None):
    if message:
        print(f"run_doc_blocks.py: {message}", file=sys.stderr)
    print("usage: run_doc_blocks.py [--list] [--keep] PAGE.md [PAGE.md...]", file=sys.stderr)
    return 2


def main(argv):
    listing = keep = False
    pages = []
    for arg in argv:
        if arg == "--list":
            listing = True
        elif arg == "--keep":
            keep = True
        elif arg in ("-h", "--help"):
            print(__doc__.strip())
            return 0
        elif arg.startswith("-"):
            return usage(f"unknown option {arg}")
        else:
            pages.append(arg)
    if not pages:
        return usage("no page given")
    resolved = []
    for page in pages:
        path = page if os.path.exists(page) else os.path.join(ROOT, page)
        if not os.path.isfile(path):
            return usage(f"{page}: no such file")
        resolved.append((page, os.path.abspath(path)))
    status = 0
    for display, path in resolved:
        try:
            blocks = extract(path, display)
        except PageError as e:
            print(f"FAILED: {e}", flush=True)
            status = 1
            continue
        if listing:
            list_blocks(display, blocks)
            continue
        for block in blocks:
            block.path = path
        started = time.monotonic()
        passed = PageRun(display, blocks, keep).run()
        seconds = time.monotonic() - started
        print(f"{display}: {'passed' if passed else 'FAILED'} in {seconds:.1f} s", flush=True)
        if not passed:
            status = 1
    return status


def terminated(signum, frame):
    raise KeyboardInterrupt(f"signal {signum}")  # the pages' clean-up runs on the way out


if __name__ == "__main__":
    signal.signal(signal.SIGTERM, terminated)
    try:
        sys.exit(main(sys.argv[1:]))
    except KeyboardInterrupt as e:
        print(f"run_doc_blocks.py: interrupted ({e or 'SIGINT'}); stopped the pages' processes",
              file=sys.stderr)
        sys.exit(1)
