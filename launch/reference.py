#!/usr/bin/python3
"""Writes the reference pages of docs/reference/ from the code, or checks that they agree with it.

  launch/reference.py --bin-dir build/bin --out docs/reference    write the pages
  launch/reference.py --bin-dir build/bin --check [--pages DIR]   compare; exit 1 on a difference

The pages come from the programs' --help (launcher, caliper-ctl, every program in the build's bin/
and their "Configuration keys:"), from the environment variables the sources read, and from the
JSON keys the experiment and calibration parsers accept. What cannot come from the code (the
meaning of an environment variable, of a file-format key) is written here, in ENVIRONMENT and
FILE_FORMATS, and --check fails when the code and these tables disagree.

Python 3 standard library only; Debian's /usr/bin/python3.
"""

import argparse
import concurrent.futures
import difflib
import getpass
import json
import os
import re
import shutil
import socket
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
REGENERATE = "launch/caliper docs"
PAGES = ["launcher.md", "ctl.md", "actuators.md", "calibrate.md", "config.md", "environment.md", "file-formats.md"]


class Problem(Exception):
    """The code and the hand-written tables here disagree, or a program's help could not be read."""


# ---------------------------------------------------------------- hand-written data

# Every verb of `launch/caliper help`, and how its options are documented: ("help",) runs
# `launch/caliper VERB --help`; ("link", TARGET, TEXT) points elsewhere; ("none", WHY) says why
# there is no help (running VERB --help would do the verb's work, or it has no options).
LAUNCHER_VERBS = {
    "demo": ("none", "`--duration S`, `--headless`; `demo --help` prints its entry above"),
    "session": ("help",),
    "calibrate": ("link", "calibrate.md#caliper-calibrate", "options of caliper-calibrate"),
    "node": ("help",),
    "test": ("help",),
    "build": ("none", "no options"),
    "deps": ("none", "`--check`, `slurm`: see its entry above"),
    "bench": ("none", "the suite to run: see its entry above"),
    "faults": ("help",),
    "soak": ("help",),
    "fuzz": ("help",),
    "ctl": ("link", "ctl.md", "every verb of caliper-ctl"),
    "python": ("none", "ARGS go to Debian's python3; `--env` prints the export lines"),
    "open": ("link", "calibrate.md", "options of caliper-main, caliper-renderer, caliper-plotter "
                                     "and caliper-logviewer"),
    "slurm": ("help",),
    "nameserver": ("none", "start, stop or status; no options"),
    "certs": ("help",),
    "docs": ("none", "`--check`: compare the pages with the code instead of writing them"),
    "help": ("none", "this text; `VERB --help` for one verb"),
}

# launch/caliper open TOOL -> program (for the links of calibrate.md)
OPEN_TOOLS = {"main": "caliper-main", "renderer": "caliper-renderer",
              "plotter": "caliper-plotter", "logviewer": "caliper-logviewer"}

# Every environment variable the sources read: name -> (group, meaning). Groups: "user" (you may
# set it), "dev" (build, tests, benchmarks, fuzzing), "internal" (Caliper sets it for its own
# processes; you rarely need to), "other" (not Caliper's, but it matters).
ENVIRONMENT = {
    "CALIPER_NAMESERVICE": (
        "user", "the naming service, `corbaname::HOST:PORT` (or `corbaname::unix:PATH`): every "
        "client and component uses it when `--nameservice` / `naming.service` is not given. "
        "Unset: the newest running session `launch/caliper session` started, else "
        "`corbaname::127.0.0.1:2809`. `launch/caliper nameserver start` prints an export line"),
    "CALIPER_NO_BUILD": (
        "user", "`1`: the launcher's `session`, `demo`, `node`, `faults` and `soak` neither run "
        "apt-get nor build; they use `build/` as it is (and build only when `caliper-model` is "
        "missing)"),
    "CALIPER_BUILD_DIR": (
        "user", "the build directory the launcher and the Slurm job scripts use (default "
        "`build/` of the checkout)"),
    "CALIPER_JOBS": ("user", "parallel build jobs of `launch/caliper build` (default: all cores)"),
    "CALIPER_SESSIONS_DIR": (
        "user", "where `launch/caliper session` and `demo` make a folder per session (logs, "
        "files/, sockets; default `~/.local/state/caliper/sessions`)"),
    "CALIPER_NODE_DIR": (
        "user", "where `launch/caliper node` keeps its manager's output and log spool (default "
        "`~/.local/state/caliper/node-HOST`)"),
    "CALIPER_LISTEN": (
        "user", "network mode: the address of this host that components listen on (as "
        "`--listen ADDR`); set by `launch/caliper session --listen` and `node --listen`"),
    "CALIPER_NAMING_PORT": (
        "internal", "network mode: the naming service's TCP port; set by `launch/caliper session "
        "--port N` (default: a free port of 20000-39999)"),
    "CALIPER_INSECURE": (
        "user", "`1`: network mode without TLS, plain GIOP, no authentication (as `--insecure`; "
        "warns)"),
    "CALIPER_LOOPBACK_TCP": (
        "user", "`1`: a local component also listens on loopback TCP (127.0.0.1), for clients of "
        "other ORBs such as Tcl; every user of this host can reach it then (as "
        "`session --loopback-tcp`)"),
    "CALIPER_HOST": (
        "user", "the host name components bind under (`HOST.host_cxt/...`) and the default TLS "
        "identity `hosts/HOST` (default: `hostname -s`)"),
    "CALIPER_PKI": (
        "user", "network mode: the directory of `launch/caliper certs` (ca.pem, hosts/, users/; "
        "default `~/.config/caliper/pki`)"),
    "CALIPER_TLS_IDENTITY": (
        "user", "network mode: the certificate a process shows, `hosts/NAME`, `users/NAME` or a "
        "`.pem` path (default `hosts/<host>` for components, `users/$USER` for clients)"),
    "CALIPER_CONFIG_DIR": (
        "user", "the directory of the components' default configuration files `NAME.conf` "
        "(default: `config/` of the source tree the programs were built from)"),
    "CALIPER_PACKAGE_PATH": (
        "user", "folders, separated by `:`, where a URDF's `package://NAME/...` meshes are "
        "looked for (before `$ROS_PACKAGE_PATH`)"),
    "CALIPER_BIN_DIR": (
        "user", "where the Caliper programs are, for those that start others (the Python "
        "package, caliper-main, `caliper-ctl replay` with `--render`); `launch/caliper python` "
        "sets it"),
    "CALIPER_MAIN_SETTINGS": (
        "user", "the Main Window's session file (INI: open tools, geometry, plotter layout; "
        "default `~/.config/caliper/caliper-main.ini`); the launcher gives each session its own"),
    "CALIPER_SOCKET_DIR": (
        "internal", "the directory of the unix sockets of local components; the launcher sets a "
        "session's `sock/` (default `${XDG_RUNTIME_DIR:-/tmp}/caliper-UID`)"),
    "CALIPER_FILES_DIR": (
        "internal", "a session's `files/` directory: where the Model's `save_scene` and the "
        "renderer's screenshots write when `model.write_dir` / `renderer.write_dir` is ''; the "
        "launcher sets it"),
    "CALIPER_SIGINT_RESET": (
        "internal", "set by the launcher while it restarts itself with SIGINT at its default "
        "(when started in the background by a script); never set it yourself"),
    "CALIPER_ROOT": (
        "user", "the Slurm job scripts (launch/slurm/): the checkout on the shared filesystem "
        "(default: the directory sbatch was run from)"),
    "CALIPER_BATCH_ARGS": (
        "user", "the Slurm job scripts: further arguments of `caliper-ctl batch` (`launch/caliper "
        "slurm batch --batch-args` sets it)"),
    "CALIPER_CALIBRATE_ARGS": (
        "user", "the Slurm job script: further arguments of `caliper-calibrate` (`launch/caliper "
        "slurm calibrate --calibrate-args` sets it)"),
    "CALIPER_LISTEN_CMD": (
        "user", "the Slurm job script: a shell command that prints a node's address (default "
        "`hostname -i`, first address)"),
    "CALIPER_CTL": (
        "user", "examples/calibration: the caliper-ctl program the example scripts run"),
    "CALIPER_IR": (
        "user", "examples/controllers/tcl: the Tcl interface repository file of Caliper's IDL "
        "(default `build/idl/caliper/caliper_ir.tcl`)"),
    "CALIPER_SOURCE_DIR": (
        "dev", "the Caliper source tree, for tests and the Python notebook "
        "(examples/python/getting_started.ipynb); ctest sets it"),
    "CALIPER_CI_SANITIZE": (
        "dev", "with `CI=true`, `launch/caliper test` runs the unit tests again under these "
        "sanitizers (default `address,undefined`; `none` leaves them out)"),
    "CALIPER_CORPUS": (
        "dev", "`launch/caliper fuzz`: the shared seed corpus (default `../shared/corpus` beside "
        "the checkout)"),
    "CALIPER_FUZZ_BUILD_DIR": ("dev", "`launch/caliper fuzz`: its build directory (default "
                                      "`build-fuzz/`)"),
    "XDG_RUNTIME_DIR": (
        "other", "the launcher's state (`caliper-UID/latest-session`, the private naming "
        "service) and the default socket directory live in `${XDG_RUNTIME_DIR:-/tmp}/caliper-UID`"),
    "XDG_STATE_HOME": (
        "other", "sessions, nodes and Slurm jobs are kept under `${XDG_STATE_HOME:-~/.local/state}"
        "/caliper/`"),
    "DISPLAY": (
        "other", "the X display: without it `session` and `demo` run headless and "
        "caliper-renderer refuses to start (it needs GLX; use Xvfb)"),
    "CI": (
        "other", "`true`: `demo` runs headless; `launch/caliper test` also runs the unit tests "
        "under sanitizers and fails on a skipped test not listed in tests/ci_allowed_skips.txt"),
    "ROS_PACKAGE_PATH": ("other", "searched for URDF `package://` meshes after "
                                  "`$CALIPER_PACKAGE_PATH`"),
}

ENV_GROUPS = [
    ("user", "Caliper's variables"),
    ("dev", "For developers (tests, fuzzing, CI)"),
    ("internal", "Set by Caliper for its own processes"),
    ("other", "Other variables that matter"),
]

# Where the scan for environment reads looks (paths relative to the checkout). tests/, bench/ and
# fuzz/ are left out: they are not what a user runs.
ENV_SCAN = ["components", "libs", "launch", "python/caliper", "python/src", "examples"]

# "read by": a program's name for its component folder; a library's readers
COMPONENT_PROGRAMS = {
    "calibrate": "caliper-calibrate", "ctl": "caliper-ctl", "log_viewer": "caliper-logviewer",
    "logger": "caliper-logger", "main_window": "caliper-main", "manager": "caliper-manager",
    "model": "caliper-model", "pd_controller": "caliper-pd-controller",
    "plotter": "caliper-plotter", "renderer": "caliper-renderer", "sample": "caliper-sample",
}
LIBRARY_READERS = {
    "rtc": "every component and client (libs/rtc)",
    "core": "every program (libs/core)",
    "client": "clients: caliper-ctl, caliper-calibrate, GUI tools, Python (libs/client)",
    "simulation": "caliper-model (libs/simulation)",
    "urdf": "URDF import: caliper-model, caliper-ctl (libs/urdf)",
}

# The JSON files. Per format: the parser sources (the check reads the keys they accept), what the
# file is, its keys (path, type, required or default, unit, meaning), notes and a minimal example.
# A path's last part is the JSON key; `[]` marks a list's entries.
FILE_FORMATS = [
    {
        "anchor": "experiment-file",
        "title": "Experiment file (`caliper-ctl batch FILE`)",
        "sources": ["libs/experiment/src/experiment.cc"],
        "intro": (
            "JSON. Read by `caliper-ctl batch FILE`, `launch/caliper slurm batch FILE` and, "
            "named by a calibration file, `caliper-calibrate`. The top level holds defaults; each "
            "entry of `experiments` starts from them and adds to or replaces them. Without "
            "`experiments` the file is one run (or one per combination of a `sweep`). Paths are "
            "relative to the file. An unknown key, or a key given twice, is an error that names "
            "the file, the experiment and the key. At most 10,000 runs per file. "
            "`caliper-ctl batch FILE --list` reads the file and prints the runs' names, without "
            "a session."),
        "keys": [
            ("name", "string", "default: the file's name without `.json` (top level), `runN` "
             "for the N-th entry of `experiments`", "",
             "the run's name: letters, digits, `.`, `_`, `-` (it names the output files "
             "`runs/NAME.csv`); unique in the file. A sweep appends `-K` (`NAME-0`, `NAME-1`, "
             "...)"),
            ("scene", "string (path)", "required", "",
             "the scene: COLLADA `.dae`, `.zae` or URDF `.urdf`, relative to the file; sent to "
             "the Models by content"),
            ("duration_s", "number", "required", "s",
             "simulated time of the run, in (0, 1e6]"),
            ("every_n_steps", "integer", "default 1", "steps",
             "one sample every N steps of the Model (N >= 1)"),
            ("record", "list of strings (or one string)", "required", "",
             "the ids sampled, as `caliper-ctl params` lists them; at least one"),
            ("set", "object `{\"ID\": value}`", "default: none", "the parameter's unit",
             "parameters written before the run, in this order; a list of numbers for a vector "
             "or matrix parameter (row-major). An experiment's `set` adds to the top level's "
             "(the same id: the experiment's value)"),
            ("commands", "list of `[time_s, \"ACTUATOR\", value]`", "default: none",
             "s; the actuator's command unit",
             "from `time_s` on, the actuator's command is `value`; sorted by time. An "
             "experiment's `commands` replace the top level's"),
            ("commands_csv", "string (path)", "default: none", "s; the actuator's command unit",
             "the commands from a CSV file instead: a header line, then `time [s],actuator,value` "
             "per line; replaces `commands`"),
            ("sweep", "object `{\"ID\": [value, value, ...]}`", "default: none",
             "the parameter's unit",
             "one run per combination of the values (the first id varies slowest), each a "
             "`set` of those values; a value may be a list (vector parameter). An "
             "experiment's `sweep` replaces the top level's"),
            ("experiments", "list of objects", "default: one run",
             "", "the runs: each an object of the keys above (not `experiments`: they do not "
             "nest), starting from the top level's values"),
        ],
        "example_name": "runs.json",
        "example": {
            "scene": "../../models/ecce_arm.dae",
            "duration_s": 2.0,
            "every_n_steps": 10,
            "record": ["ecce_arm.elbow.position", "ecce_arm.elbow_flexor.tendon.tension"],
            "commands": [[0.0, "elbow_flexor", 6], [1.0, "elbow_flexor", 2]],
            "experiments": [
                {"name": "light", "set": {"ecce_arm.forearm.mass": 0.4}},
                {"name": "heavy", "set": {"ecce_arm.forearm.mass": 1.2}},
            ],
        },
        "example_note": ("`scene` is relative to the file: this one as if it were beside the "
                         "shipped example, `examples/calibration/runs.json`; put your scene's "
                         "path. `caliper-ctl batch runs.json --list` prints `light` and "
                         "`heavy`."),
    },
    {
        "anchor": "calibration-file",
        "title": "Calibration file (`caliper-calibrate FILE`)",
        "sources": ["libs/calibration/src/calibration.cc"],
        "intro": (
            "JSON. Read by `caliper-calibrate FILE` (and `launch/caliper calibrate`, "
            "`launch/caliper slurm calibrate`). Names an experiment file, a measured CSV per "
            "experiment and the parameters to fit with their bounds. Paths are relative to the "
            "file. An unknown key is an error, at the top level and inside `parameters`, "
            "`channels`, `optimiser`, `refinement` and `uncertainty` (a typo is never taken for "
            "a default)."),
        "keys": [
            ("experiments", "string (path)", "required", "",
             "the experiment file (format above): scene, schedules, recorded ids, durations"),
            ("measured", "object `{\"EXPERIMENT\": \"FILE.csv\"}`", "required", "",
             "per experiment (by its name, after sweeps), the CSV of what the real robot "
             "measured (format below)"),
            ("parameters", "list of objects", "required (at least one)", "",
             "the parameters to fit"),
            ("parameters[].id", "string", "required", "", "the parameter's id "
             "(`caliper-ctl params`); each once. Or a timing parameter [s]: `time_shift` (the "
             "measurements' clock minus the simulation's), `sensor_delay:CHANNEL` (that measured "
             "column lags), `command_delay:ACTUATOR` (that actuator acts late)"),
            ("parameters[].lower", "number", "required", "the parameter's unit",
             "lower bound of the search"),
            ("parameters[].upper", "number", "required", "the parameter's unit",
             "upper bound, above `lower`"),
            ("parameters[].scale", "`linear` or `log`", "default `linear`", "",
             "search the value (linear) or its logarithm (log; needs `lower` > 0)"),
            ("channels", "list of objects", "default: every channel, weight 1, all times", "",
             "weights and time windows of the compared channels"),
            ("channels[].id", "string", "required", "",
             "a recorded column: an id, or `ID[k]` for an element of a vector"),
            ("channels[].weight", "number", "default 1", "", "its weight in the cost (>= 0)"),
            ("channels[].window_s", "`[from, to]`", "default: all times", "s",
             "compare only between these times (from < to)"),
            ("optimiser", "object", "default: the values below", "", "the search"),
            ("optimiser.algorithm", "`cmaes` or `xnes`", "default `cmaes`", "",
             "pagmo's evolution strategy"),
            ("optimiser.generations", "integer", "default 40", "",
             "the budget of generations (>= 0; 0: no global search); `--generations N` "
             "overrides it"),
            ("optimiser.population", "integer", "default 10", "",
             "candidates per island and generation (>= 5)"),
            ("optimiser.sigma0", "number", "default 0.25", "",
             "initial step in the search space scaled to [0, 1], in (0, 1]"),
            ("optimiser.window", "integer", "default 20", "generations",
             "the window over which the cost's change is judged (>= 2)"),
            ("optimiser.cost_tolerance", "number", "default 1e-6", "",
             "converged when the best cost changed less than this, relatively, over the window"),
            ("optimiser.step_tolerance", "number", "default 1e-4", "",
             "converged when the populations' spread in the unit box is below this"),
            ("optimiser.target_cost", "number", "default 0 (none)", "",
             "converged when the best cost is this low"),
            ("optimiser.restarts", "integer", "default 2", "",
             "IPOP restarts (populations doubled) when the search stalls above twice the "
             "measurements' noise floor (0 to 20)"),
            ("refinement", "object", "default: the values below", "",
             "the Levenberg-Marquardt refinement (Ceres) after the global search"),
            ("refinement.iterations", "integer", "default 30", "",
             "its budget (0: no refinement); `--iterations N` overrides it"),
            ("refinement.jacobian", "`central` or `forward`", "default `central`", "",
             "finite differences: 2 or 1 runs per parameter, one batch over every Model"),
            ("refinement.step", "number", "default 1e-3", "",
             "the finite-difference step in the unit box, in (0, 0.1]"),
            ("uncertainty", "object", "default: the values below", "",
             "when the fit's intervals and correlations are warned about"),
            ("uncertainty.max_relative_interval", "number", "default 0.1", "",
             "warn when a 95 % half-width exceeds this fraction of the value (of the search "
             "range for a timing parameter)"),
            ("uncertainty.max_correlation", "number", "default 0.95", "",
             "warn when two parameters' |correlation| exceeds this, in (0, 1]"),
            ("held_out", "list of experiment names", "default: none", "",
             "experiments not fitted: their cost before and after is reported (not all)"),
            ("seed", "integer", "default 1", "", "random seed, a whole number in [0, 2^53]"),
        ],
        "example_name": "calibration.json",
        "example": {
            "experiments": "runs.json",
            "measured": {"light": "measured/light.csv", "heavy": "measured/heavy.csv"},
            "parameters": [
                {"id": "ecce_arm.elbow_flexor.stiffness", "lower": 1000, "upper": 10000,
                 "scale": "log"},
            ],
            "optimiser": {"generations": 20},
        },
        "example_note": (
            "With the experiment file above as `runs.json`. Each measured CSV has a header "
            "`time [s],ID [unit],...` (columns named like the recorded ids; `ID[k]` for an "
            "element of a vector), then rows with increasing times, at least two, at any rate; "
            "lines starting with `#` are comments:"),
        "csv_example": ("time [s],ecce_arm.elbow.position [rad]\n"
                        "0.00,0.000\n0.01,0.012\n0.02,0.047\n"),
    },
]


# ---------------------------------------------------------------- running programs

class Runner:
    """Runs programs with a clean environment (a temporary HOME, no CALIPER_* of the caller) and
    makes their output machine-independent."""

    def __init__(self, bin_dir):
        self.bin_dir = Path(bin_dir).resolve()
        self.build_dir = self.bin_dir.parent
        self.tmp = Path(tempfile.mkdtemp(prefix="caliper-reference-"))
        self.home = self.tmp / "home"
        self.runtime = self.tmp / "run"
        self.home.mkdir()
        self.runtime.mkdir(mode=0o700)
        self.xvfb = None
        self.display = None
        env = {k: v for k, v in os.environ.items()
               if not k.startswith("CALIPER_") and k not in ("DISPLAY", "WAYLAND_DISPLAY", "CI")
               and not k.startswith("XDG_")}
        env.update(HOME=str(self.home), XDG_RUNTIME_DIR=str(self.runtime), LC_ALL="C.UTF-8",
                   LANG="C.UTF-8", COLUMNS="100", CALIPER_NO_BUILD="1",
                   CALIPER_BUILD_DIR=str(self.build_dir), QT_QPA_PLATFORM="offscreen")
        self.env = env
        self.replacements = self._replacements()

    def _replacements(self):
        pairs = [(str(self.home), "~"), (str(self.runtime), "<runtime-dir>"), (str(self.tmp), "<tmp>")]
        sources = {str(ROOT), os.path.realpath(ROOT)}
        cache = self.build_dir / "CMakeCache.txt"
        if cache.is_file():
            m = re.search(r"^CMAKE_HOME_DIRECTORY:INTERNAL=(.*)$", cache.read_text(errors="replace"),
                          re.M)
            if m:
                sources.add(m.group(1).strip())
        build = str(self.build_dir)
        if not any(build.startswith(s + "/") for s in sources):
            pairs.append((build, "<build>"))
        pairs += [(s, "<checkout>") for s in sources if s]
        home = os.path.expanduser("~")
        if home not in ("", "/"):
            pairs.append((home, "~"))
        pairs.sort(key=lambda p: -len(p[0]))
        return pairs

    def clean(self, text):
        for old, new in self.replacements:
            text = text.replace(old, new)
        for host in {socket.gethostname(), socket.gethostname().split(".")[0]}:
            if len(host) >= 3:
                text = re.sub(r"(?<![\w.-])" + re.escape(host) + r"(?![\w-])", "<host>", text)
        user = getpass.getuser()
        if user:
            text = re.sub(r"(?<=/)" + re.escape(user) + r"(?![\w.-])", "<user>", text)
        return "\n".join(line.rstrip() for line in text.splitlines()).strip("\n") + "\n"

    def _start_xvfb(self):
        if self.display or not shutil.which("Xvfb"):
            return bool(self.display)
        r, w = os.pipe()
        self.xvfb = subprocess.Popen(
            ["Xvfb", "-displayfd", str(w), "-screen", "0", "1280x800x24", "-nolisten", "tcp"],
            pass_fds=(w,), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        os.close(w)
        with os.fdopen(r) as pipe:
            number = pipe.readline().strip()
        if number:
            self.display = ":" + number
        return bool(self.display)

    def run(self, argv, display=False):
        env = dict(self.env)
        if display and self._start_xvfb():
            env["DISPLAY"] = self.display
        try:
            p = subprocess.run(argv, cwd=str(ROOT), env=env, stdin=subprocess.DEVNULL,
                               capture_output=True, text=True, timeout=60)
        except (OSError, subprocess.TimeoutExpired) as e:
            raise Problem("`%s`: %s" % (" ".join(argv), e)) from None
        return p.returncode, self.clean(p.stdout), self.clean(p.stderr)

    def help(self, argv):
        """The help text of argv (stdout; stderr when stdout is empty). A program that needs a
        display gets Xvfb."""
        rc, out, err = self.run(argv)
        if rc != 0 and "DISPLAY" in err:
            rc, out, err = self.run(argv, display=True)
        if rc != 0:
            raise Problem("`%s` exited %d: %s" % (" ".join(argv), rc, (err or out).strip()))
        return out if out.strip() else err

    def close(self):
        if self.xvfb:
            self.xvfb.terminate()
            try:
                self.xvfb.wait(10)
            except subprocess.TimeoutExpired:
                self.xvfb.kill()
                self.xvfb.wait()
        shutil.rmtree(self.tmp, ignore_errors=True)


def parallel(function, items):
    with concurrent.futures.ThreadPoolExecutor(max_workers=8) as pool:
        return list(pool.map(function, items))


# ---------------------------------------------------------------- Markdown helpers

def header(sources, title):
    return ("<!-- Generated by launch/reference.py from %s. Do not edit by hand: run `%s` to "
            "regenerate (the check `launch/reference.py --check` fails on a difference). -->\n\n"
            "# %s\n\n" % (sources, REGENERATE, title))


def fence(text):
    return "```text\n" + text.rstrip("\n") + "\n```\n"


def cell(text):
    """Plain text for a table cell: `|`, `<`, `>` and `*` escaped, code spans kept."""
    out = []
    for i, part in enumerate(re.split(r"(`[^`]*`)", text)):
        if i % 2:
            out.append(part.replace("|", "\\|"))
        else:
            out.append(part.replace("\\", "\\\\").replace("|", "\\|").replace("*", "\\*")
                       .replace("<", "&lt;").replace(">", "&gt;"))
    return "".join(out).replace("\n", " ")


def code(text):
    return "`%s`" % text.replace("|", "\\|") if text != "" else "''"


def table(head, rows):
    lines = ["| " + " | ".join(head) + " |", "|" + " --- |" * len(head)]
    lines += ["| " + " | ".join(row) + " |" for row in rows]
    return "\n".join(lines) + "\n"


# ---------------------------------------------------------------- launcher.md

def launcher_verbs(usage):
    """The verbs of `launch/caliper help`: lines indented by two spaces that start with a word."""
    verbs = []
    for line in usage.splitlines():
        m = re.match(r"^  ([a-z][a-z-]*)(?:\s|$)", line)
        if m and m.group(1) not in verbs:
            verbs.append(m.group(1))
    return verbs


def dispatched_verbs():
    """The verbs launch/caliper's main() dispatches."""
    text = (ROOT / "launch/caliper").read_text()
    body = text[text.index("\nmain() {"):]
    return {v for m in re.finditer(r"^\s+([a-z|-]+)\)\s+(?:cmd_|usage)", body, re.M)
            for v in m.group(1).split("|") if not v.startswith("-")}


def page_launcher(runner):
    usage = runner.help([str(ROOT / "launch/caliper"), "help"])
    verbs = launcher_verbs(usage)
    missing = (set(verbs) | dispatched_verbs()) - set(LAUNCHER_VERBS)
    if missing:
        raise Problem("launcher verb(s) %s: not in LAUNCHER_VERBS of launch/reference.py (say how "
                      "their options are documented)" % ", ".join(sorted(missing)))
    gone = set(LAUNCHER_VERBS) - set(verbs) - dispatched_verbs()
    if gone:
        raise Problem("LAUNCHER_VERBS of launch/reference.py names %s, which launch/caliper no "
                      "longer has" % ", ".join(sorted(gone)))
    own = [v for v in verbs if LAUNCHER_VERBS[v][0] == "help"]
    texts = dict(zip(own, parallel(
        lambda v: runner.help([str(ROOT / "launch/caliper"), v, "--help"]), own)))
    out = [header("`launch/caliper help` and `launch/caliper VERB --help`", "Launcher reference"),
           "Every verb of `launch/caliper`, as its help prints it (run from the root of the "
           "checkout). For what runs before a verb and how to stop one, see "
           "[the launcher](../launcher.md).\n\n",
           "| verb | options |\n| --- | --- |\n"]
    for v in verbs:
        kind = LAUNCHER_VERBS[v]
        if kind[0] == "help":
            where = "[`%s --help`](#%s)" % (v, v)
        elif kind[0] == "link":
            where = "[%s](%s)" % (kind[2], kind[1])
        else:
            where = cell(kind[1])
        out.append("| `%s` | %s |\n" % (v, where))
    out.append("\n## help\n\n`launch/caliper help`:\n\n" + fence(usage))
    for v in own:
        out.append("\n## %s\n\n`launch/caliper %s --help`:\n\n%s" % (v, v, fence(texts[v])))
    return "".join(out)


# ---------------------------------------------------------------- ctl.md

def ctl_sections(usage):
    """[(section title, [(verb, summary)])] from `caliper-ctl --help`."""
    sections = []
    for line in usage.splitlines():
        m = re.match(r"^(\S.*):$", line)
        if m and not line.startswith("Usage"):
            sections.append((m.group(1), []))
            continue
        m = re.match(r"^  ([a-z][a-z-]*)\s{2,}(.*)$", line)
        if m and sections:
            sections[-1][1].append((m.group(1), m.group(2)))
    return [s for s in sections if s[1]]


def page_ctl(runner):
    ctl = str(runner.bin_dir / "caliper-ctl")
    usage = runner.help([ctl, "--help"])
    sections = ctl_sections(usage)
    verbs = [v for _, vs in sections for v, _ in vs]
    if not verbs:
        raise Problem("no verbs found in `caliper-ctl --help`")
    texts = dict(zip(verbs, parallel(lambda v: runner.help([ctl, v, "--help"]), verbs)))
    out = [header("`caliper-ctl --help` and `caliper-ctl VERB --help`", "caliper-ctl reference"),
           "Every verb of `caliper-ctl`, as its help prints it. `launch/caliper ctl VERB ...` "
           "runs it on the most recent running session. A task-oriented introduction is "
           "[caliper-ctl](../ctl.md).\n\n"]
    for title, vs in sections:
        out.append("- %s: %s\n" % (title, ", ".join("[%s](#%s)" % (v, v) for v, _ in vs)))
    out.append("\n## caliper-ctl\n\n`caliper-ctl --help`:\n\n" + fence(usage))
    for title, vs in sections:
        out.append("\n## %s\n" % title.split(" (")[0])
        for v, _ in vs:
            out.append("\n### %s\n\n`caliper-ctl %s --help`:\n\n%s" % (v, v, fence(texts[v])))
    return "".join(out)


def page_actuators(runner):
    ctl = str(runner.bin_dir / "caliper-ctl")
    tables = runner.help([ctl, "kinds", "--markdown"])
    if "| parameter |" not in tables:
        raise Problem("`caliper-ctl kinds --markdown` printed no table")
    return (header("`caliper-ctl kinds --markdown`", "Actuator kinds and their parameters") +
            "Every parameter an actuator of each registered kind takes: in a model file's "
            "`<param name=...>` (any unit of the same dimension, [collada-extension.md]"
            "(../collada-extension.md#units)), and on a Model as `ACTUATOR.PARAMETER` "
            "(`launch/caliper ctl set`). A parameter a file leaves out has its default. What the "
            "DC motor's heat, friction, cogging and driver parameters do: "
            "[actuators.md](../actuators.md).\n\n" + tables)


# ---------------------------------------------------------------- programs and configuration

def programs(bin_dir):
    return sorted(p.name for p in Path(bin_dir).iterdir()
                  if p.is_file() and os.access(p, os.X_OK) and not p.name.startswith("."))


def split_config(text):
    """(help without the "Configuration keys:" section, the section's lines)."""
    lines = text.splitlines()
    if "Configuration keys:" not in lines:
        return text, []
    i = lines.index("Configuration keys:")
    j = i + 1
    while j < len(lines) and lines[j].strip():
        j += 1
    return "\n".join(lines[:i] + lines[j + 1:]) + "\n", lines[i + 1:j]


ENTRY_END = re.compile(r"^(?P<help>.*?)\s*\((?P<spec>[^()]*?),\s*default\s+'(?P<default>.*)'\)\s*$")


def parse_spec(spec):
    """(type, range or choices) from "number", "integer in [0, 10]", "one of a|b", "true|false"."""
    spec = spec.strip()
    if spec == "true|false":
        return "boolean", ""
    m = re.match(r"^(number|integer|string)\s+in\s+(.+)$", spec)
    if m:
        return m.group(1), m.group(2)
    m = re.match(r"^(?:(string|number|integer),?\s+)?one of\s+(.+)$", spec)
    if m:
        return m.group(1) or "string", m.group(2)
    return spec, ""


def parse_config(lines):
    """[(key, type, default, range, meaning)] from the lines of "Configuration keys:". An entry
    starts with two spaces and a key; deeper-indented lines continue it."""
    entries = []
    for line in lines:
        m = re.match(r"^  ([A-Za-z_][\w.]*)\s+(\S.*)$", line)
        if m and not line.startswith("   "):
            entries.append([m.group(1), m.group(2)])
        elif entries and line.startswith("   "):
            entries[-1][1] += " " + line.strip()
        else:
            raise Problem("cannot read configuration line %r" % line)
    out = []
    for key, rest in entries:
        m = ENTRY_END.match(rest)
        if not m:
            raise Problem("configuration key %s: no '(TYPE, default ...)' at the end of %r"
                          % (key, rest))
        kind, bounds = parse_spec(m.group("spec"))
        out.append((key, kind, m.group("default"), bounds, m.group("help")))
    return out


def component_of(text, program):
    m = re.search(r"\(after (\S+)/([\w-]+)\.conf\)", text)
    return (m.group(2), m.group(1)) if m else (program.replace("caliper-", ""), None)


def shipped_config(component):
    path = ROOT / "config" / (component + ".conf")
    values = {}
    if path.is_file():
        for line in path.read_text().splitlines():
            line = line.split("#", 1)[0].strip()
            if "=" in line:
                k, v = line.split("=", 1)
                values[k.strip()] = v.strip()
    return values


def program_helps(runner):
    names = programs(runner.bin_dir)
    return dict(zip(names, parallel(lambda n: runner.help([str(runner.bin_dir / n), "--help"]),
                                    names)))


def page_programs(runner, helps):
    order = ["caliper-calibrate"] + [n for n in helps if n not in ("caliper-calibrate", "caliper-ctl")]
    order = [n for n in order if n in helps]
    out = [header("each program's `--help` in the build's bin/",
                  "caliper-calibrate and the other programs"),
           "The options of every Caliper program, as `PROGRAM --help` prints it (with the "
           "checkout's `build/bin/` in front, or through the launcher: `launch/caliper calibrate "
           "FILE`, `launch/caliper open main|renderer|plotter|logviewer`). caliper-ctl has "
           "[a page of its own](ctl.md); the configuration keys of the components are in "
           "[config.md](config.md). Formats of the files caliper-calibrate reads: "
           "[file-formats.md](file-formats.md).\n\n"]
    out.append("".join("- [%s](#%s)\n" % (n, n) for n in order))
    for n in order:
        text, keys = split_config(helps[n])
        out.append("\n## %s\n\n`%s --help`:\n\n%s" % (n, n, fence(text)))
        if keys:
            component, _ = component_of(helps[n], n)
            out.append("\nIts configuration keys: [config.md](config.md#%s).\n"
                       % anchor(component))
    return "".join(out)


def anchor(text):
    return re.sub(r"[^a-z0-9_ -]", "", text.lower()).replace(" ", "-")


def page_config(runner, helps):
    components = []
    for n, text in helps.items():
        _, lines = split_config(text)
        if lines:
            component, _ = component_of(text, n)
            components.append((component, n, parse_config(lines)))
    if not components:
        raise Problem("no program printed \"Configuration keys:\"")
    # the keys every component has, alike everywhere
    common = None
    for _, _, keys in components:
        rows = {k[0]: k for k in keys}
        common = rows if common is None else {k: v for k, v in common.items() if rows.get(k) == v}
    common_order = [k[0] for k in components[0][2] if k[0] in common]
    out = [header("the \"Configuration keys:\" of each component's `--help`",
                  "Configuration keys"),
           "Every component reads, in this order: its configuration file `NAME.conf` in "
           "`$CALIPER_CONFIG_DIR` (when set and not empty), else in `config/` of the source "
           "tree it was built from (here `<checkout>/config/`; a missing file is skipped); then "
           "each `-f FILE`, in order; then what the environment says (`$CALIPER_LISTEN`, "
           "`$CALIPER_INSECURE`, `$CALIPER_LOOPBACK_TCP`, see [environment.md](environment.md)); "
           "last the command line's `-o KEY=VALUE`, `--nameservice`, `--instance`, `--listen` "
           "and `--insecure`, in their order. A file holds `key = value` lines and `#` "
           "comments. Unknown keys warn; a malformed value stops the program with exit status 2 "
           "and a message naming the file and line. The default below is the program's own; "
           "the last column is what the shipped `config/NAME.conf` sets instead.\n\n"
           "| component | program | file |\n| --- | --- | --- |\n"]
    for component, program, _ in components:
        out.append("| [%s](#%s) | `%s` | `config/%s.conf` |\n"
                   % (component, anchor(component), program, component))
    head = ["key", "type", "default", "range / choices", "meaning"]

    def rows(keys, shipped):
        result = []
        for key, kind, default, bounds, meaning in keys:
            row = [code(key), cell(kind), code(default), cell(bounds), cell(meaning)]
            if shipped is not None:
                row.append(code(shipped[key]) if key in shipped else "")
            result.append(row)
        return result

    out.append("\n## Common keys\n\nEvery component has these, with the same defaults.\n\n")
    out.append(table(head, rows([common[k] for k in common_order], None)))
    for component, program, keys in components:
        shipped = shipped_config(component)
        own = [k for k in keys if k[0] not in common]
        out.append("\n## %s\n\n`%s`; file `config/%s.conf`. Besides the [common keys]"
                   "(#common-keys):\n\n" % (component, program, component))
        out.append(table(head + ["config/%s.conf" % component], rows(own, shipped)))
        set_common = [(k, v) for k, v in shipped.items() if k in common]
        if set_common:
            out.append("\n`config/%s.conf` also sets: %s.\n" % (
                component, ", ".join("%s = %s" % (code(k), code(v)) for k, v in set_common)))
        unknown = sorted(set(shipped) - {k[0] for k in keys})
        if unknown:
            raise Problem("config/%s.conf sets %s, which %s --help does not list"
                          % (component, ", ".join(unknown), program))
    return "".join(out)


# ---------------------------------------------------------------- environment.md

C_READ = re.compile(r"\b(?:getenv|secure_getenv|qgetenv|qEnvironmentVariable(?:IsSet|IsEmpty)?)"
                    r"\(\s*\"([A-Z_][A-Z0-9_]*)\"")
PY_READ = [re.compile(r"os\.environ(?:\.get)?\s*[\[(]\s*[\"']([A-Z_][A-Z0-9_]*)[\"']"),
           re.compile(r"os\.getenv\(\s*[\"']([A-Z_][A-Z0-9_]*)[\"']"),
           re.compile(r"[\"']([A-Z_][A-Z0-9_]*)[\"']\s+(?:not\s+)?in\s+os\.environ")]
SH_READ = re.compile(r"(?<!\\)\$\{?([A-Z_][A-Z0-9_]*)")
TCL_READ = re.compile(r"\benv\(([A-Z_][A-Z0-9_]*)\)")
CMAKE_READ = re.compile(r"\$ENV\{([A-Z_][A-Z0-9_]*)\}")


def shell_code(text):
    """A shell script without its comment lines and quoted here-documents (no expansion there)."""
    out, end = [], None
    for line in text.splitlines():
        if end is not None:
            if line.strip() == end:
                end = None
            continue
        if line.lstrip().startswith("#"):
            continue
        m = re.search(r"<<-?\s*(['\"])(\w+)\1", line)
        if m:
            end = m.group(2)
        out.append(line)
    return "\n".join(out)


def is_shell(path, text):
    return path.suffix in (".sh", ".sbatch", ".bash") or re.match(r"#!.*\b(ba)?sh\b", text) is not None


def env_reads():
    """{variable: {file, ...}} of the variables the sources read."""
    reads = {}
    for top in ENV_SCAN:
        for path in sorted((ROOT / top).rglob("*")):
            if not path.is_file() or "__pycache__" in path.parts or path == Path(__file__).resolve():
                continue
            try:
                text = path.read_text()
            except (UnicodeDecodeError, OSError):
                continue
            found = set()
            if path.suffix in (".cc", ".h", ".cpp", ".hpp", ".c"):
                found = set(C_READ.findall(text))
            elif path.suffix == ".py":
                found = {m for r in PY_READ for m in r.findall(text)}
            elif path.suffix == ".ipynb":
                cells = json.loads(text).get("cells", [])
                source = "\n".join("".join(c.get("source", [])) for c in cells
                                   if c.get("cell_type") == "code")
                found = {m for r in PY_READ for m in r.findall(source)}
            elif path.suffix == ".tcl":
                found = set(TCL_READ.findall(text))
            elif path.name == "CMakeLists.txt" or path.suffix == ".cmake":
                found = set(CMAKE_READ.findall(text))
            elif is_shell(path, text):
                found = set(SH_READ.findall(shell_code(text)))
            for name in found:
                reads.setdefault(name, set()).add(str(path.relative_to(ROOT)))
    return reads


def reader(path):
    parts = path.split("/")
    if parts[0] == "components" and len(parts) > 1:
        return COMPONENT_PROGRAMS.get(parts[1], "components/" + parts[1])
    if parts[0] == "libs" and len(parts) > 1:
        return LIBRARY_READERS.get(parts[1], "libs/" + parts[1])
    if parts[0] == "python":
        return "the Python package (python/)"
    if parts[0] == "launch" and len(parts) == 2 and parts[1] != "reference.py":
        return "launch/caliper" if parts[1] in ("caliper", "certs.sh", "naming.sh",
                                                "session_lib.sh", "slurm.sh", "dev_verbs.sh") \
            else path
    return path


def page_environment():
    reads = env_reads()
    code_vars = {v for v in reads if v.startswith("CALIPER_")}
    problems = []
    for v in sorted(code_vars - set(ENVIRONMENT)):
        problems.append("%s is read by %s but has no meaning in ENVIRONMENT of launch/reference.py"
                        % (v, ", ".join(sorted(reads[v]))))
    for v in sorted(set(ENVIRONMENT) - set(reads)):
        problems.append("ENVIRONMENT of launch/reference.py names %s, which no source in %s reads"
                        % (v, ", ".join(ENV_SCAN)))
    if problems:
        raise Problem("\n".join(problems))
    out = [header("the environment variables the sources read (getenv, $VAR, os.environ) and "
                  "the meanings in launch/reference.py", "Environment variables"),
           "Every environment variable Caliper reads. \"Read by\" comes from a scan of "
           "components/, libs/, launch/, python/ and examples/; a variable added to the code "
           "without a line here fails the docs check.\n"]
    for group, title in ENV_GROUPS:
        names = sorted(v for v, (g, _) in ENVIRONMENT.items() if g == group)
        if not names:
            continue
        out.append("\n## %s\n\n" % title)
        rows = []
        for v in names:
            by = sorted({reader(p) for p in reads[v]})
            rows.append([code(v), cell(", ".join(by)), cell(ENVIRONMENT[v][1])])
        out.append(table(["variable", "read by", "meaning"], rows))
    return "".join(out)


# ---------------------------------------------------------------- file-formats.md

ACCESSOR = re.compile(r"\b(?:get_child_optional|get_child|get_optional\s*<[^>]*>|get\s*<[^>]*>|"
                      r"count)\(\s*\"([^\"]+)\"")
KEY_SET = re.compile(r"\bkKeys\s*=\s*\{([^;]*)\};", re.S)


def parser_keys(sources):
    """The JSON keys the parser sources accept: the string literals passed to Boost.PropertyTree's
    accessors and those of their kKeys sets."""
    keys = set()
    for source in sources:
        text = (ROOT / source).read_text()
        keys |= set(ACCESSOR.findall(text))
        for block in KEY_SET.findall(text):
            keys |= set(re.findall(r"\"([^\"]+)\"", block))
    return keys


def check_example(runner, fmt, directory):
    """The experiment example must read (`caliper-ctl batch FILE --list`)."""
    path = directory / fmt["example_name"]
    path.write_text(json.dumps(fmt["example"], indent=2) + "\n")
    if fmt["anchor"] != "experiment-file":
        return
    rc, out, err = runner.run([str(runner.bin_dir / "caliper-ctl"), "batch", str(path), "--list"])
    if rc != 0:
        raise Problem("the experiment example of FILE_FORMATS does not read: " + err.strip())


def page_file_formats(runner):
    problems = []
    for fmt in FILE_FORMATS:
        in_code = parser_keys(fmt["sources"])
        documented = {re.split(r"\.|\[\]\.", path)[-1] for path, *_ in fmt["keys"]}
        for k in sorted(in_code - documented):
            problems.append("%s accepts the key \"%s\", which FILE_FORMATS (%s) of "
                            "launch/reference.py does not describe" % (", ".join(fmt["sources"]),
                                                                      k, fmt["anchor"]))
        for k in sorted(documented - in_code):
            problems.append("FILE_FORMATS (%s) of launch/reference.py describes \"%s\", which %s "
                            "does not read" % (fmt["anchor"], k, ", ".join(fmt["sources"])))
    if problems:
        raise Problem("\n".join(problems))
    # examples: the scene path relative to a file in examples/calibration/
    work = runner.tmp / "examples" / "calibration"
    work.mkdir(parents=True, exist_ok=True)
    (runner.tmp / "models").mkdir(exist_ok=True)
    for fmt in FILE_FORMATS:
        check_example(runner, fmt, work)
    out = [header("the JSON parsers (%s) and the key descriptions in launch/reference.py"
                  % ", ".join(s for f in FILE_FORMATS for s in f["sources"]), "File formats"),
           "The JSON files Caliper reads. The keys below are exactly those the parsers accept: "
           "the docs check compares them with the string literals the parser sources read.\n\n"]
    out.append("".join("- [%s](#%s)\n" % (f["title"], f["anchor"]) for f in FILE_FORMATS))
    for fmt in FILE_FORMATS:
        out.append("\n<a id=\"%s\"></a>\n\n## %s\n\n%s\n\nParser: %s.\n\n" % (
            fmt["anchor"], fmt["title"], fmt["intro"],
            ", ".join("`%s`" % s for s in fmt["sources"])))
        out.append(table(["key", "type", "required / default", "unit", "meaning"],
                         [[code(p), cell(t), cell(d), cell(u), cell(m)]
                          for p, t, d, u, m in fmt["keys"]]))
        out.append("\nA complete minimal example, `%s`:\n\n```json\n%s\n```\n" % (
            fmt["example_name"], json.dumps(fmt["example"], indent=2)))
        out.append("\n%s\n" % fmt["example_note"])
        if "csv_example" in fmt:
            out.append("\n```text\n%s```\n" % fmt["csv_example"])
    return "".join(out)


# ---------------------------------------------------------------- main

def generate(bin_dir, only=None):
    """{page name: text} of every page, or of those in `only`."""
    runner = Runner(bin_dir)
    helps = {}

    def program_pages(function):
        def page():
            if not helps:
                helps.update(program_helps(runner))
            return function(runner, helps)
        return page

    makers = {
        "launcher.md": lambda: page_launcher(runner),
        "ctl.md": lambda: page_ctl(runner),
        "actuators.md": lambda: page_actuators(runner),
        "calibrate.md": program_pages(page_programs),
        "config.md": program_pages(page_config),
        "environment.md": page_environment,
        "file-formats.md": lambda: page_file_formats(runner),
    }
    try:
        return {name: makers[name]() for name in PAGES if not only or name in only}
    finally:
        runner.close()


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--bin-dir", default=os.environ.get("CALIPER_BIN_DIR",
                                                            str(ROOT / "build" / "bin")),
                        help="the build's bin/ (default $CALIPER_BIN_DIR, else build/bin)")
    parser.add_argument("--out", help="write the pages into this directory")
    parser.add_argument("--check", action="store_true",
                        help="compare with the pages in --pages (default docs/reference)")
    parser.add_argument("--pages", default=str(ROOT / "docs" / "reference"),
                        help="the committed pages --check compares with")
    parser.add_argument("--only", action="append", choices=PAGES,
                        help="only this page (repeatable; default all)")
    args = parser.parse_args()
    if bool(args.out) == bool(args.check):
        parser.error("give --out DIR or --check")
    if not (Path(args.bin_dir) / "caliper-ctl").is_file():
        parser.error("no caliper-ctl in %s (build first, or give --bin-dir)" % args.bin_dir)
    try:
        pages = generate(args.bin_dir, args.only)
    except Problem as e:
        print("reference: %s" % e, file=sys.stderr)
        print("docs/reference cannot be generated: fix the code or launch/reference.py, then run "
              "`%s`" % REGENERATE, file=sys.stderr)
        return 1
    if args.out:
        out = Path(args.out)
        out.mkdir(parents=True, exist_ok=True)
        for name, text in pages.items():
            (out / name).write_text(text)
        print("reference: wrote %s" % ", ".join(str(out / n) for n in pages), file=sys.stderr)
        return 0
    stale = []
    for name, text in pages.items():
        path = Path(args.pages) / name
        old = path.read_text() if path.is_file() else ""
        if old != text:
            sys.stdout.writelines(difflib.unified_diff(
                old.splitlines(True), text.splitlines(True), "docs/reference/%s (committed)" % name,
                "docs/reference/%s (from the code)" % name))
            stale.append(name)
    for name in stale:
        print("docs/reference/%s is stale: run `%s` to regenerate" % (name, REGENERATE),
              file=sys.stderr)
    return 1 if stale else 0


if __name__ == "__main__":
    sys.exit(main())
