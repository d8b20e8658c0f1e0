"""Sessions: :func:`connect` to a running one, or :class:`LocalSession` to start a private one
(a naming service and N Models on this machine) for a script, a notebook or a test."""

from __future__ import annotations

import ctypes
import os
import shutil
import signal
import subprocess
import tempfile
import time
import weakref
from typing import List, NamedTuple, Optional, Sequence

from . import _caliper
from .errors import ConnectionError, Error

__all__ = ["Component", "Session", "connect", "LocalSession", "binary"]

Session = _caliper.Session


class Component(NamedTuple):
    """A component bound in a session's naming service."""
    name: str        #: INSTANCE@HOST, e.g. model1@hostb
    host: str
    instance: str    #: model0, renderer0, ...
    path: str        #: HOST.host_cxt/INSTANCE.rtc
    kind: str        #: the interface it serves: Model, Renderer, HostManager, ...


def connect(nameservice: Optional[str] = None, timeout_s: float = 5.0) -> Session:
    """Connects to a Caliper session.

    `nameservice` is its naming service, ``corbaname::HOST:PORT``; without it, as caliper-ctl:
    ``$CALIPER_NAMESERVICE`` (unless it names a local session that has ended and one runs: then that,
    with a note on stderr), else the newest session ``launch/caliper session`` (or ``demo``)
    started on this host, else the naming service of ``launch/caliper nameserver start``, else
    ``corbaname::127.0.0.1:2809``. A naming service on another host
    means network mode: TLS with the certificates of ``launch/caliper certs`` (see
    docs/cluster.md). `timeout_s` is the deadline of ordinary calls [s]; loads, steps and
    experiments take as long as their work.

    Raises :class:`caliper.ConnectionError` naming the address when nothing answers there.
    """
    return Session(nameservice or "", timeout_s)


def binary(name: str) -> str:
    """The path of a Caliper program (caliper-model, caliper-ctl, ...): in $CALIPER_BIN_DIR, else
    beside this package in a build tree (<build>/bin), else on PATH."""
    here = os.path.dirname(os.path.abspath(__file__))
    places = [os.environ.get("CALIPER_BIN_DIR", ""),
              os.path.join(os.path.dirname(os.path.dirname(here)), "bin")]
    for place in places:
        if place and os.access(os.path.join(place, name), os.X_OK):
            return os.path.abspath(os.path.join(place, name))
    found = shutil.which(name)
    if found:
        return found
    raise FileNotFoundError(f"{name} is not in $CALIPER_BIN_DIR, the build tree or PATH "
                            "(build Caliper with `launch/caliper build`)")


def _die_with_parent() -> None:
    """In a child before exec: SIGTERM when the Python process that started it ends, however it
    ends (prctl PR_SET_PDEATHSIG), so that no session outlives its program."""
    libc = ctypes.CDLL(None, use_errno=True)
    libc.prctl(1, signal.SIGTERM, 0, 0, 0)  # PR_SET_PDEATHSIG


def _stop(processes: List[subprocess.Popen], directory: str, keep: bool) -> None:
    for p in reversed(processes):
        if p.poll() is None:
            p.terminate()
    for p in reversed(processes):
        try:
            p.wait(timeout=10)
        except subprocess.TimeoutExpired:
            p.kill()
            p.wait()
    processes.clear()
    if not keep:
        shutil.rmtree(directory, ignore_errors=True)


class LocalSession:
    """A private session on this machine, reachable only by this user (unix sockets in a private
    directory): a naming service and `models`
    Models (model0, model1, ...), each loading `scene` when given; everything stops when the
    ``with`` block ends (or at :meth:`close`)::

        with caliper.LocalSession(models=2, scene="models/ecce_arm.dae") as session:
            arm = session.model("model0")
            arm.step(1000)

    The Models write recordings and saved scenes below :attr:`files_dir`; the processes' output
    goes to files in :attr:`directory` (kept when `keep` is true). `options` are further
    ``KEY=VALUE`` settings of the Models (``caliper-model --help`` lists them). The processes end
    with the program at the latest, also when it is killed (they get SIGTERM when the thread that
    started them ends: start a LocalSession from a thread that lives as long as you use it).
    """

    def __init__(self, models: int = 1, scene: Optional[str] = None, timeout_s: float = 5.0,
                 options: Sequence[str] = (), keep: bool = False, start_timeout_s: float = 30.0):
        if not isinstance(models, int) or models < 0 or models > 64:
            raise ValueError(f"models must be 0 to 64, not {models!r}")
        self.directory = tempfile.mkdtemp(prefix="caliper-session-")
        self._keep = keep
        self._processes: List[subprocess.Popen] = []
        self.session: Optional[Session] = None
        # stopped at the latest when the program ends (or this object goes), and the processes
        # get SIGTERM from the kernel if the program dies without a word
        self._finalizer = weakref.finalize(self, _stop, self._processes, self.directory, keep)
        try:
            self._start(models, scene, timeout_s, list(options), start_timeout_s)
        except BaseException:
            self.close()
            raise

    def _spawn(self, argv: List[str], log: str) -> subprocess.Popen:
        with open(os.path.join(self.directory, log), "ab") as out:
            p = subprocess.Popen(argv, stdout=out, stderr=subprocess.STDOUT,
                                 stdin=subprocess.DEVNULL, cwd=self.directory,
                                 env=getattr(self, "_env", None), preexec_fn=_die_with_parent)
        self._processes.append(p)
        return p

    def _start(self, models: int, scene: Optional[str], timeout_s: float, options: List[str],
               start_timeout_s: float) -> None:
        # unix sockets in a directory only this user can enter (mkdtemp makes it 0700): no other
        # user of the machine reaches the session
        sockets = os.path.join(self.directory, "sock")
        os.mkdir(sockets, 0o700)
        self._env = dict(os.environ, CALIPER_SOCKET_DIR=sockets)
        naming = os.path.join(sockets, "naming.sock")
        self.address = f"corbaname:omniunix:{naming}"
        data = os.path.join(self.directory, "omninames")
        os.mkdir(data)
        self._spawn([shutil.which("omniNames") or "/usr/bin/omniNames", "-start", "-always",
                     "-nohostname", "-datadir", data, "-ORBendPoint", f"giop:unix:{naming}",
                     "-ORBunixTransportPermission", "0600"], "omninames.log")
        deadline = time.monotonic() + start_timeout_s
        while True:
            try:
                self.session = Session(self.address, timeout_s)
                break
            except ConnectionError:
                if time.monotonic() > deadline:
                    raise Error(f"the naming service did not start: see {self.directory}")
                time.sleep(0.05)
        self.files_dir = os.path.join(self.directory, "files")
        os.mkdir(self.files_dir)
        common = ["--nameservice", self.address, "-o", "log.service=none",
                  "-o", f"log.spool_dir={self.directory}/spool", "-o", "log.level=warn",
                  "-o", f"model.write_dir={self.files_dir}", "-o", "exec.auto_activate=true"]
        if scene:
            common += ["-o", f"model.scene={os.path.abspath(scene)}"]
        for o in options:
            common += ["-o", o]
        # one after the other, so that model<i> is the i-th process (Models bind as the first
        # free model<N>)
        for i in range(models):
            self._spawn([binary("caliper-model")] + common, f"model{i}.out")
            self._wait_for(f"model{i}", deadline, scene is not None)

    def _wait_for(self, name: str, deadline: float, loaded: bool) -> None:
        assert self.session is not None
        while True:
            for p in self._processes:
                if p.poll() is not None:
                    raise Error(f"a process of the session ended (exit {p.returncode}): "
                                f"{' '.join(map(str, p.args))}; see {self.directory}")
            try:
                m = self.session.model(name)
                if not loaded or m.status().state != "EMPTY":
                    return
            except Error:
                pass
            if time.monotonic() > deadline:
                raise Error(f"{name} did not come up; see {self.directory}")
            time.sleep(0.05)

    def model(self, name: str = "model0"):
        """The Model `name` of this session."""
        assert self.session is not None
        return self.session.model(name)

    def kill(self, name: str) -> None:
        """Kills a Model of this session with SIGKILL (for tests of lost Models)."""
        index = int(name.replace("model", "")) + 1
        self._processes[index].kill()
        self._processes[index].wait()

    def close(self) -> None:
        """Stops the Models and the naming service (TERM, then KILL after 10 s) and removes
        the directory unless `keep`. Also done when the program ends."""
        self._finalizer()

    def __enter__(self) -> Session:
        assert self.session is not None
        return self.session

    def __exit__(self, *exc) -> None:
        self.close()
