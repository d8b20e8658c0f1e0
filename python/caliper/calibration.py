"""A calibration file's cost for parameter vectors, evaluated on the Models of a session or
cluster, so that any optimiser (scipy.optimize, your own) can drive it::

    cal = caliper.Calibration("examples/calibration/calibration.json")
    result = scipy.optimize.minimize(cal.cost, cal.initial, bounds=cal.bounds,
                                     method="Nelder-Mead")

The cost is caliper-calibrate's (docs/calibration.md): the weighted RMS of simulated minus
measured over each measured column's range, 0 for a perfect fit.

:func:`calibrate` runs the whole of caliper-calibrate instead (a global search, then a
Levenberg-Marquardt refinement, then the intervals at the optimum) and returns its result folder
read as a :class:`CalibrationResult`::

    result = caliper.calibrate("examples/calibration/calibration.json", session=session)
    print(result.values, result.intervals, result.warnings)
"""

from __future__ import annotations

import html
import json
import math
import os
import queue
import signal
import subprocess
import sys
import threading
from collections import deque
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any, Callable, Dict, List, NamedTuple, Optional, Sequence, Tuple, Union

import numpy as np

from . import _caliper
from .errors import Error, FormatError
from .model import Data
from .session import Session, _die_with_parent, binary, connect

__all__ = ["Calibration", "Evaluation", "Parameter", "ChannelCost", "calibrate",
           "CalibrationResult", "FittedParameter", "ChannelNoise"]


class Parameter(NamedTuple):
    id: str
    lower: float          #: in the parameter's unit
    upper: float
    log_scale: bool


class ChannelCost(NamedTuple):
    column: str
    weight: float
    rms: float            #: [column unit]
    range: float          #: measured max - min [column unit]
    samples: int


class Evaluation(NamedTuple):
    cost: float
    faulted: bool         #: the physics faulted: cost is caliper.calibration's fault cost
    fault: str
    channels: List[ChannelCost]
    recordings: List[Data]  #: per experiment, when asked for


class Calibration:
    """A calibration file (its experiments, measured CSVs, parameters with bounds, channel
    weights) evaluated on the Models matching `models` in `session` (the latest session when
    None). Thread-safe: :meth:`costs` evaluates several vectors at once, one per Model."""

    def __init__(self, path: "str | os.PathLike[str]", session: Optional[Session] = None,
                 models: str = "*", attempts: int = 5, run_timeout_s: float = 3600,
                 wait_for_model_s: float = 60):
        self.session = session or connect()
        self._pool = _caliper._Pool(self.session, models, run_timeout_s, attempts,
                                    wait_for_model_s)
        if self._pool.size == 0:
            raise Error(f"no Model matching {models!r} in the session at {self.session.address}")
        self._spec = _caliper._Calibration(os.path.abspath(os.fspath(path)), self._pool)
        self.parameters: List[Parameter] = [Parameter(*p) for p in self._spec.parameters()]

    @property
    def bounds(self) -> List[Tuple[float, float]]:
        """(lower, upper) per parameter, in its unit (scipy.optimize's `bounds`)."""
        return [(p.lower, p.upper) for p in self.parameters]

    @property
    def initial(self) -> np.ndarray:
        """The middle of each range (geometric for log-scale parameters)."""
        return np.array([np.sqrt(p.lower * p.upper) if p.log_scale else (p.lower + p.upper) / 2
                         for p in self.parameters])

    @property
    def models(self) -> int:
        """Models in the pool."""
        return self._pool.size

    @property
    def evaluations(self) -> int:
        return self._spec.evaluations

    def cost(self, values: Sequence[float]) -> float:
        """The cost of one parameter vector (in the parameters' units)."""
        return float(self._spec.evaluate(np.asarray(values, dtype=float).tolist(), False)["cost"])

    def costs(self, vectors: Sequence[Sequence[float]]) -> np.ndarray:
        """The costs of several vectors, evaluated in parallel over the Models."""
        vectors = [np.asarray(v, dtype=float).tolist() for v in vectors]
        with ThreadPoolExecutor(max_workers=max(1, self._pool.size)) as ex:
            return np.array(list(ex.map(self.cost, vectors)))

    def evaluate(self, values: Sequence[float], keep_recordings: bool = True) -> Evaluation:
        """The cost with its parts per channel and, with `keep_recordings`, the simulated
        recordings (one caliper.Data per experiment, to plot against the measurements)."""
        e = self._spec.evaluate(np.asarray(values, dtype=float).tolist(), keep_recordings)
        return Evaluation(e["cost"], e["faulted"], e["fault"],
                          [ChannelCost(*c) for c in e["channels"]],
                          [Data(*r) for r in e["recordings"]])


# -- caliper-calibrate's results ----------------------------------------------------------------

class FittedParameter(NamedTuple):
    """A parameter of a :class:`CalibrationResult`, in its unit. An interval the experiments do
    not determine (or that could not be computed) is unbounded: ``sigma`` inf, ``lower95`` -inf,
    ``upper95`` +inf, ``determined`` False."""
    id: str
    unit: str
    initial: float        #: the scene's value, where the search started
    fitted: float
    sigma: float          #: standard deviation of the fitted value
    lower95: float        #: the 95 % interval
    upper95: float
    determined: bool      #: the experiments pin it down (a finite interval)
    lower: float          #: the calibration file's bounds
    upper: float


class ChannelNoise(NamedTuple):
    """The noise of one measured column at the optimum, estimated from the residuals."""
    experiment: str
    column: str
    unit: str
    sigma: float          #: [unit]
    samples: int


def _number(value: Any, null: float = math.nan) -> float:
    """A JSON number as a float; `null` for JSON's null (caliper-calibrate's not-finite)."""
    return null if value is None else float(value)


class CalibrationResult:
    """A caliper-calibrate result folder (``--out DIR``), read from its ``result.json``: what
    :func:`calibrate` returns, and what :meth:`load` reads of an earlier run.

    - ``converged``, ``interrupted``, ``reason`` (why it stopped: the refinement's reason, else
      the global search's), ``global_reason``, ``refinement_reason``;
    - ``parameters`` (:class:`FittedParameter` each), ``values`` (id to the fitted value),
      ``intervals`` (id to the 95 % interval (lower95, upper95)), ``correlation`` (n x n, NaN
      where it could not be computed), ``noise`` (:class:`ChannelNoise` per measured column),
      ``warnings`` (what the experiments cannot determine, and why there are no intervals);
    - ``cost_initial``, ``cost`` (fitted), ``noise_floor``, ``global_cost`` (after the global
      search), ``held_out_cost`` ((initial, fitted) on the held-out experiments, else None),
      ``held_out_experiments``;
    - ``evaluations``, ``wall_s`` [s], ``generations``, ``restarts``, ``refinement_iterations``,
      ``refinement_evaluations``, ``history`` (the refinement's (evaluations, cost) rows),
      ``models``;
    - ``file`` (the calibration file), ``out`` (the folder), ``report_html`` (its report page),
      ``report_png``, ``tuned_scene`` (the scene with the fitted values, None when it could not
      be written).

    Numbers the program could not compute (JSON null) are NaN. In Jupyter it shows as a table.
    """

    def __init__(self, result: Dict[str, Any], out: "str | os.PathLike[str]"):
        self.out = Path(os.path.abspath(os.fspath(out)))
        where = str(self.out / "result.json")
        try:
            self._read(result)
        except (KeyError, TypeError, ValueError, IndexError) as e:
            raise FormatError(f"{where}: not a caliper-calibrate result ({type(e).__name__}: "
                              f"{e})") from None

    def _read(self, r: Dict[str, Any]) -> None:
        self.file = Path(r["file"])
        self.models = int(r["models"])
        self.converged = bool(r["converged"])
        self.interrupted = bool(r["interrupted"])
        self.reason = str(r["reason"])
        g, refinement, cost, held = r["global_search"], r["refinement"], r["cost"], r["held_out"]
        self.global_reason = str(g["reason"])
        self.generations = int(g["generations"])
        self.restarts = int(g["restarts"])
        self.global_cost = _number(g["cost"])
        self.refinement_reason = str(refinement["reason"])
        self.refinement_iterations = int(refinement["iterations"])
        self.refinement_evaluations = int(refinement["evaluations"])
        self.history = np.array([[_number(n), _number(c)] for n, c in refinement["history"]],
                                dtype=float).reshape(-1, 2)
        self.evaluations = int(r["evaluations"])
        self.wall_s = _number(r["wall_s"])
        self.cost_initial = _number(cost["initial"])
        self.cost = _number(cost["fitted"])
        self.noise_floor = _number(cost["noise_floor"])
        self.held_out_experiments: List[str] = [str(n) for n in held["experiments"]]
        self.held_out_cost: Optional[Tuple[float, float]] = None
        if held["initial"] is not None or held["fitted"] is not None:
            self.held_out_cost = (_number(held["initial"]), _number(held["fitted"]))
        self.parameters: List[FittedParameter] = []
        for p in r["parameters"]:
            determined = bool(p.get("determined", False))
            self.parameters.append(FittedParameter(
                str(p["id"]), str(p["unit"]), _number(p["initial"]), _number(p["fitted"]),
                _number(p.get("sigma"), math.inf), _number(p.get("lower95"), -math.inf),
                _number(p.get("upper95"), math.inf), determined, _number(p["lower"]),
                _number(p["upper"])))
        n = len(self.parameters)
        rows = r["correlation"]
        self.correlation = np.full((n, n), np.nan)
        if rows:
            if len(rows) != n or any(len(row) != n for row in rows):
                raise ValueError(f"correlation is not {n} x {n}")
            self.correlation = np.array([[_number(c) for c in row] for row in rows], dtype=float)
        self.noise: List[ChannelNoise] = [
            ChannelNoise(str(c["experiment"]), str(c["column"]), str(c["unit"]),
                         _number(c["sigma"]), int(c["samples"])) for c in r["noise"]]
        self.warnings: List[str] = [str(w) for w in r["warnings"]]

    @classmethod
    def load(cls, out: "str | os.PathLike[str]") -> "CalibrationResult":
        """The result in the folder `out` (caliper-calibrate's ``--out``). FileNotFoundError
        when it has no result.json; FormatError when that is not a result."""
        path = Path(os.fspath(out)) / "result.json"
        with open(path, encoding="utf-8") as f:
            try:
                result = json.load(f)
            except ValueError as e:
                raise FormatError(f"{os.path.abspath(path)}: not JSON: {e}") from None
        if not isinstance(result, dict):
            raise FormatError(f"{os.path.abspath(path)}: not a caliper-calibrate result")
        return cls(result, out)

    @property
    def values(self) -> Dict[str, float]:
        """Parameter id to its fitted value."""
        return {p.id: p.fitted for p in self.parameters}

    @property
    def intervals(self) -> Dict[str, Tuple[float, float]]:
        """Parameter id to its 95 % interval (lower95, upper95); (-inf, inf) when the
        experiments do not determine it."""
        return {p.id: (p.lower95, p.upper95) for p in self.parameters}

    @property
    def report_html(self) -> Path:
        """The report page (cost curve, fit per channel, intervals) in :attr:`out`."""
        return self.out / "report.html"

    @property
    def report_png(self) -> Path:
        """The report's plots as one image in :attr:`out`."""
        return self.out / "report.png"

    @property
    def tuned_scene(self) -> Optional[Path]:
        """The scene with the fitted values (tuned.dae in :attr:`out`), None when there is
        none."""
        path = self.out / "tuned.dae"
        return path if path.is_file() else None

    def _summary(self) -> str:
        state = "converged" if self.converged else "NOT converged"
        if self.interrupted:
            state = "interrupted"
        return (f"{state}, cost {self.cost_initial:.4g} -> {self.cost:.4g}, "
                f"{len(self.parameters)} parameters, {self.evaluations} evaluations in "
                f"{self.wall_s:.3g} s")

    def __repr__(self) -> str:
        return f"<caliper.CalibrationResult {self._summary()}>"

    def _repr_html_(self) -> str:
        e = html.escape

        def number(v: float) -> str:
            return e(f"{v:.6g}")

        rows = []
        for p in self.parameters:
            interval = (f"[{number(p.lower95)}, {number(p.upper95)}]" if p.determined
                        else "not determined")
            rows.append(f"<tr><td><code>{e(p.id)}</code></td><td>{e(p.unit)}</td>"
                        f"<td>{number(p.initial)}</td><td><b>{number(p.fitted)}</b></td>"
                        f"<td>{interval}</td><td>[{number(p.lower)}, {number(p.upper)}]</td></tr>")
        line = (f"<b>{'converged' if self.converged else 'NOT converged'}</b>"
                f"{' (interrupted)' if self.interrupted else ''}: {e(self.reason)}<br>"
                f"cost {number(self.cost_initial)} &rarr; {number(self.cost)} (noise floor "
                f"{number(self.noise_floor)})")
        if self.held_out_cost is not None:
            line += (f", held-out {number(self.held_out_cost[0])} &rarr; "
                     f"{number(self.held_out_cost[1])}")
        line += (f"; {self.evaluations} evaluations in {number(self.wall_s)} s "
                 f"({self.generations} generations, {self.refinement_iterations} refinement "
                 f"iterations)")
        warnings = "".join(f"<li>{e(w)}</li>" for w in self.warnings)
        return ("<div class=\"caliper-calibration\">"
                f"<p>{line}</p>"
                "<table><thead><tr><th>parameter</th><th>unit</th><th>initial</th>"
                "<th>fitted</th><th>95 % interval</th><th>bounds</th></tr></thead>"
                f"<tbody>{''.join(rows)}</tbody></table>"
                + (f"<p>warnings:</p><ul>{warnings}</ul>" if warnings else "")
                + f"<p><code>{e(str(self.out))}</code></p></div>")


# -- running caliper-calibrate ------------------------------------------------------------------

def _whole(name: str, value: Any, least: int) -> str:
    if isinstance(value, bool) or not isinstance(value, int) or not least <= value <= 1000000:
        raise ValueError(f"{name} must be a whole number from {least} to 1000000, not {value!r}")
    return str(value)


def _read_lines(stream, sink: Callable[[str], None]) -> None:
    """In a thread: each line of `stream` (without its newline) to `sink`, then None."""
    try:
        for line in stream:
            sink(line.rstrip("\n"))
    finally:
        sink(None)  # type: ignore[arg-type]


def _finish(process: subprocess.Popen, drain: Callable[[Optional[Callable[[str], None]]], None],
            emit: Optional[Callable[[str], None]]) -> None:
    """After an interruption: SIGINT to caliper-calibrate (it stops after the current generation
    or step and writes its best so far) and its output to the end; a second interruption kills
    it."""
    if process.poll() is None:
        process.send_signal(signal.SIGINT)
    try:
        drain(emit)
        process.wait()
    except BaseException:
        process.kill()
        process.wait()
        raise


def calibrate(path: "str | os.PathLike[str]", out: "str | os.PathLike[str] | None" = None, *,
              session: "Session | str | None" = None, models: str = "model*",
              generations: Optional[int] = None, iterations: Optional[int] = None,
              islands: Optional[int] = None, resume: bool = False,
              run_timeout_s: Optional[float] = None,
              progress: Union[bool, Callable[[str], Any]] = True) -> CalibrationResult:
    """Runs caliper-calibrate on the calibration file `path` (docs/calibration.md) with the
    Models of `session` whose name matches `models` (a glob), and returns its result.

    The session is a :class:`Session`, a :class:`LocalSession` or a naming service address;
    None: the newest session, as :func:`connect` finds it. `out` is the result folder (default,
    as the program's: the file's name without its extension + ``-calibration``, in the working
    directory). `generations` and `iterations` replace the file's ``optimiser.generations`` and
    ``refinement.iterations`` (0: no global search, no refinement); `islands` the number of
    populations (default one per Model); `resume` goes on from the folder's checkpoint;
    `run_timeout_s` bounds one run (the program's default 300 s).

    The program's progress (a line per generation and per refinement step) goes to stderr while
    it runs; `progress=False` silences it, a callable gets each line instead. Ctrl-C
    (KeyboardInterrupt) stops it after the current generation or step: it writes the best so
    far into `out` (:meth:`CalibrationResult.load` reads it, ``resume=True`` goes on), then the
    KeyboardInterrupt goes on; a second Ctrl-C kills it. An exception from the `progress`
    callable stops it the same way. A run that fails (exit status other than 0 and 130, the
    program's Ctrl-C) raises :class:`caliper.Error` with the end of the program's messages.
    """
    path = os.path.abspath(os.fspath(path))
    if out is None:
        out = os.path.join(os.getcwd(), Path(path).stem + "-calibration")
    out = os.path.abspath(os.fspath(out))
    if session is None:
        session = connect()
    address = session if isinstance(session, str) else session.address
    argv = [binary("caliper-calibrate"), path, "--out", out, "--nameservice", address,
            "--models", models]
    if generations is not None:
        argv += ["--generations", _whole("generations", generations, 0)]
    if iterations is not None:
        argv += ["--iterations", _whole("iterations", iterations, 0)]
    if islands is not None:
        argv += ["--islands", _whole("islands", islands, 1)]
    if run_timeout_s is not None:
        if not (isinstance(run_timeout_s, (int, float)) and 0 < run_timeout_s <= 1000000):
            raise ValueError(f"run_timeout_s must be a number of seconds from 1 to 1000000, not "
                             f"{run_timeout_s!r}")
        argv += ["--run-timeout", str(max(1, math.ceil(run_timeout_s)))]
    if resume:
        argv.append("--resume")

    def emit(line: str) -> None:
        if callable(progress):
            progress(line)
        elif progress:
            print(line, file=sys.stderr, flush=True)

    tail: "deque[str]" = deque(maxlen=20)
    printed: List[str] = []
    lines: "queue.Queue[Optional[str]]" = queue.Queue()

    ended = [False]  # stderr's end taken from `lines`

    def from_stderr(line: Optional[str]) -> None:
        if line is not None:
            tail.append(line)
        lines.put(line)

    def drain(to: Optional[Callable[[str], None]]) -> None:
        while not ended[0]:
            try:
                line = lines.get(timeout=0.5)
            except queue.Empty:  # its end may have been taken by an interrupted drain
                ended[0] = not readers[0].is_alive() and lines.empty()
                continue
            if line is None:
                ended[0] = True
            elif to is not None:
                to(line)

    # a process group of its own: a Ctrl-C at the terminal reaches only Python, which passes it
    # on once; SIGTERM to it (it stops as on Ctrl-C) when this thread ends without a word
    process = subprocess.Popen(argv, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True, errors="replace",
                               start_new_session=True, preexec_fn=_die_with_parent)
    readers = [threading.Thread(target=_read_lines, args=(process.stderr, from_stderr),
                                daemon=True, name="caliper-calibrate stderr"),
               threading.Thread(target=_read_lines, daemon=True, name="caliper-calibrate stdout",
                                args=(process.stdout,
                                      lambda line: line is not None and printed.append(line)))]
    for reader in readers:
        reader.start()
    try:
        drain(emit)
        rc = process.wait()
    except KeyboardInterrupt:
        _finish(process, drain, emit)
        raise
    except BaseException:
        _finish(process, drain, None)
        raise
    finally:
        for reader in readers:
            reader.join(timeout=10)
        for stream in (process.stdout, process.stderr):
            if stream is not None:
                stream.close()
    if rc not in (0, 130):
        what = (f"was killed by signal {-rc}" if rc < 0 else f"failed (exit {rc})")
        said = list(tail) + [line for line in printed[-1:] if line not in tail]
        raise Error(f"caliper-calibrate {path} {what}"
                    + (":\n" + "\n".join(said) if said else ""))
    return CalibrationResult.load(out)
