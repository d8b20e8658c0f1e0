"""Experiments (a scene, parameter overrides, a command schedule, the ids recorded, a duration;
the format of docs/cluster.md's experiment files) run on one Model or as a batch over every Model
of a session or cluster."""

from __future__ import annotations

import json
import os
import sys
import tempfile
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from typing import Any, Callable, Dict, List, Optional, Union

from . import _caliper
from .errors import Error
from .model import Data
from .session import Session, connect

__all__ = ["load_experiments", "experiments_of", "run_batch", "Batch"]

Experiment = _caliper._Experiment
ExperimentLike = Union[str, "os.PathLike[str]", Dict[str, Any], Experiment,
                       List[Union[Dict[str, Any], Experiment]]]


def load_experiments(experiments: ExperimentLike) -> List[Experiment]:
    """The runs (sweeps expanded) of an experiment file (JSON), of a dict in the file's format
    (paths relative to the working directory), or of a list of these. FormatError names the
    file, the experiment and the key that is wrong."""
    return experiments_of(experiments)


def _load_file(path: "str | os.PathLike[str]") -> List[Experiment]:
    return _caliper._load_experiments(os.path.abspath(os.fspath(path)))


def _absolute(spec: Dict[str, Any], base: str) -> Dict[str, Any]:
    out = dict(spec)
    for key in ("scene", "commands_csv"):
        if isinstance(out.get(key), (str, os.PathLike)):
            out[key] = os.path.join(base, os.fspath(out[key]))
    if isinstance(out.get("experiments"), list):
        out["experiments"] = [_absolute(e, base) if isinstance(e, dict) else e
                              for e in out["experiments"]]
    return out


def experiments_of(x: ExperimentLike) -> List[Experiment]:
    """Runs from a file path, a dict in the file's format (paths relative to the working
    directory), an Experiment, or a list of these."""
    if isinstance(x, Experiment):
        return [x]
    if isinstance(x, (str, os.PathLike)):
        return _load_file(x)
    if isinstance(x, dict):
        with tempfile.TemporaryDirectory(prefix="caliper-experiments-") as d:
            path = os.path.join(d, "experiments.json")
            with open(path, "w") as f:
                json.dump(_absolute(x, os.getcwd()), f)
            return _load_file(path)
    if isinstance(x, (list, tuple)):
        return [run for item in x for run in experiments_of(item)]
    raise TypeError(f"experiments must be a file, a dict, an Experiment or a list of them, not "
                    f"{type(x).__name__}")


class Batch:
    """What :func:`run_batch` returns: ``results`` (run name to :class:`caliper.Data`), in the
    order of the runs; ``failures`` (run name to the reason) for runs that failed on every
    attempt or cannot run (a physics fault, a scene that does not load); ``lost`` (what each
    lost Model said); ``runs`` (the runs, with their names and overrides); ``models``;
    ``wall_s``."""

    def __init__(self) -> None:
        self.runs: List[Experiment] = []
        self.results: Dict[str, Data] = {}
        self.failures: Dict[str, str] = {}
        self.lost: List[str] = []
        self.wall_s = 0.0
        self.models: List[str] = []

    def __getitem__(self, name: str) -> Data:
        return self.results[name]

    def __repr__(self) -> str:
        return (f"<caliper.Batch {len(self.results)} done, {len(self.failures)} failed on "
                f"{len(self.models)} Models in {self.wall_s:.3g} s>")


def run_batch(experiments: ExperimentLike, session: Optional[Session] = None,
              models: str = "*", attempts: int = 5, run_timeout_s: float = 3600,
              wait_for_model_s: float = 60, progress: Union[bool, Callable[[int, int], Any]] = True
              ) -> Batch:
    """Runs every experiment across every Model of the session whose name matches `models` (a
    glob: ``*``, ``*@hostb``), one run per Model at a time, as fast as possible. A run whose
    Model is lost (killed, unreachable, no answer in `run_timeout_s`) goes to another Model, at
    most `attempts` times, the rule of ``caliper-ctl batch``; while every Model is lost it looks
    for new ones for up to `wait_for_model_s`. `progress` prints a line per run to stderr (True),
    or is called with (done, total).
    Each run loads its scene afresh, so a run gives the same bits on any Model."""
    runs = experiments_of(experiments)
    names = [r.name for r in runs]
    if len(set(names)) != len(names):
        raise ValueError("experiment names must be unique in a batch")
    session = session or connect()
    pool = _caliper._Pool(session, models, run_timeout_s, attempts, wait_for_model_s)
    if pool.size == 0:
        raise Error(f"no Model matching {models!r} in the session at {session.address}")
    batch = Batch()
    batch.runs = runs
    batch.models = pool.names()
    lock = threading.Lock()
    pool.set_on_lost(lambda why: batch.lost.append(why))
    done = [0]
    start = time.monotonic()

    def one(run: Experiment) -> None:
        try:
            result: Optional[Data] = Data(*pool.run(run))
            reason = ""
        except Error as e:
            result, reason = None, str(e)
        with lock:
            done[0] += 1
            if result is not None:
                batch.results[run.name] = result
            else:
                batch.failures[run.name] = reason
            if callable(progress):
                progress(done[0], len(runs))
            elif progress:
                state = "done" if result is not None else f"FAILED: {reason}"
                print(f"batch: {done[0]}/{len(runs)} {run.name} {state} "
                      f"({time.monotonic() - start:.1f} s)", file=sys.stderr)

    with ThreadPoolExecutor(max_workers=max(1, pool.size)) as executor:
        list(executor.map(one, runs))
    batch.results = {n: batch.results[n] for n in names if n in batch.results}
    batch.wall_s = time.monotonic() - start
    return batch
