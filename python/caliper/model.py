"""A Model's results as typed tuples, and the methods of :class:`caliper.Model` written in Python:
``record`` and ``stream`` (lossless DAQ data as numpy arrays) and ``run_experiment``.

The rest of ``Model`` (load, step, commands, parameters, editing, recordings, replay) is the
extension's; see ``help(caliper.Model)``.
"""

from __future__ import annotations

import math
from typing import Dict, Iterator, List, NamedTuple, Optional, Sequence, Tuple, Union

import numpy as np

from . import _caliper

__all__ = ["Status", "Channel", "Actuator", "ActuatorState", "EditStatus", "RecordStatus",
           "ReplayStatus", "Data", "Feed", "Model"]


class Status(NamedTuple):
    """A Model's simulation status."""
    state: str                    #: EMPTY, STOPPED, RUNNING, PAUSED or FAULTED
    scene: str                    #: the loaded scene's file
    sim_time_s: float             #: simulated time [s]
    steps: int                    #: steps since the scene's start
    time_step_s: float            #: [s]
    real_time_factor: float       #: requested: 1 real time, 0 as fast as possible
    achieved_real_time_factor: float  #: measured over the last second
    last_error: str               #: why it faulted, "" when it did not


class Channel(NamedTuple):
    """A DAQ channel: its id, SI unit and the numpy shape of one value (() for a scalar, (3,) for
    a position, (rows, cols) for a matrix)."""
    id: str
    unit: str
    shape: Tuple[int, ...]
    writable: bool
    static: bool                  #: a model parameter (True) or a state changing every step
    description: str

    @property
    def size(self) -> int:
        """Values per sample."""
        return int(np.prod(self.shape, dtype=np.int64))


class Actuator(NamedTuple):
    name: str
    kind: str                     #: dc_motor, hill_muscle, ligament, ...
    tendon: str
    command_unit: str             #: V for a DC motor, "" for a passive element


class ActuatorState(NamedTuple):
    name: str
    command: float                #: in the actuator's command unit
    tension_n: float              #: the tendon's tension [N]


class EditStatus(NamedTuple):
    revision: int                 #: grows by one with every edit, undo and redo
    last: str                     #: what the last edit, undo or redo did
    undo: str                     #: what undo() would revert ("" = nothing)
    redo: str                     #: what redo() would apply again ("" = nothing)


class RecordStatus(NamedTuple):
    recording: bool
    path: str                     #: on the Model's host
    first_step: int
    steps: int                    #: recorded so far
    bytes: int                    #: the file's size at its last commit
    error: str                    #: why it stopped early ("" when it did not)


class ReplayStatus(NamedTuple):
    replaying: bool
    path: str
    first_step: int
    last_step: int
    step: int
    start_time_s: float
    end_time_s: float
    time_s: float


class Data:
    """Sampled channels: ``time`` [s] (n,), and per channel an array of shape
    (n,) + the channel's shape, in the channel's unit (``units``), exactly as the Model sent
    them (float64, no resampling). ``data["ecce_arm.elbow.position"]`` or ``data[id]``."""

    def __init__(self, channels: Sequence[Channel], time: np.ndarray, values: np.ndarray):
        self.channels: List[Channel] = list(channels)
        self.time: np.ndarray = time
        #: every value of a sample in one row: (n, values per sample)
        self.values: np.ndarray = values
        self.units: Dict[str, str] = {c.id: c.unit for c in self.channels}
        self._columns: Dict[str, np.ndarray] = {}
        at = 0
        for c in self.channels:
            width = c.size
            self._columns[c.id] = values[:, at:at + width].reshape((len(time),) + tuple(c.shape))
            at += width

    def __getitem__(self, id: str) -> np.ndarray:
        try:
            return self._columns[id]
        except KeyError:
            raise KeyError(f"no channel {id!r} in this data (it has {', '.join(self._columns)})") \
                from None

    def __contains__(self, id: object) -> bool:
        return id in self._columns

    def __len__(self) -> int:
        return len(self.time)

    def ids(self) -> List[str]:
        """The channel ids, in order."""
        return list(self._columns)

    def __repr__(self) -> str:
        span = f", t = {self.time[0]:.6g} .. {self.time[-1]:.6g} s" if len(self.time) else ""
        return f"<caliper.Data {len(self.time)} samples of {len(self.channels)} channels{span}>"


Model = _caliper.Model


class Feed:
    """A lossless subscription to channels of a Model (``Model.feed``): when the Model steps
    in lock-step or as fast as possible, its stepping waits for this client, so no sample is
    lost; running at a real-time factor above 0 it does not wait, and a client that lags loses
    batches (then :meth:`take` raises, saying so). :meth:`step` steps the Model itself and
    returns the samples of those steps; :meth:`take` returns what arrived while something else
    (a controller, ``start()``) ran it. Close it (or use ``with``) to end the subscription."""

    def __init__(self, model: Model, ids: Union[str, Sequence[str]], every: int = 1):
        self._feed = _caliper._Feed(model, ids, every)
        #: the channels, in the order of a sample's values
        self.channels: List[Channel] = list(self._feed.channels)

    def step(self, steps: int) -> Data:
        """Steps the Model `steps` times and returns the samples taken meanwhile."""
        return Data(self.channels, *self._feed.step(steps))

    def take(self, wait_s: float = 1.0) -> Data:
        """The samples that arrived since the last take; a Model at rest is waited for up to
        `wait_s` [s] until every sample it took has arrived (within one push poll, 20 ms)."""
        return Data(self.channels, *self._feed.take(wait_s))

    def close(self) -> None:
        """Ends the subscription (idempotent)."""
        self._feed.close()

    def __enter__(self) -> "Feed":
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def _steps_for(model: Model, steps: Optional[int], duration_s: Optional[float]) -> int:
    if (steps is None) == (duration_s is None):
        raise TypeError("give steps or duration_s (one of them)")
    if steps is not None:
        if not isinstance(steps, (int, np.integer)) or isinstance(steps, bool) or steps < 1:
            raise ValueError(f"steps must be a positive integer, not {steps!r}")
        return int(steps)
    if not isinstance(duration_s, (int, float)) or not math.isfinite(duration_s) or duration_s <= 0:
        raise ValueError(f"duration_s must be a positive number of seconds, not {duration_s!r}")
    return max(1, round(duration_s / model.time_step_s))


def _record(self: Model, ids: Union[str, Sequence[str]], steps: Optional[int] = None,
            duration_s: Optional[float] = None, every: int = 1) -> Data:
    """Steps the Model `steps` times (or for `duration_s` of simulated time) and returns every
    `every`-th sample of the channels `ids`, losslessly (the Model waits for this client), as
    :class:`Data`: time first, then each channel in its shape and unit. Samples are taken after
    the first step and then every `every` steps (steps 1, 1 + every, ...), as every DAQ
    subscription does. The Model must not be running (lock-step). Ctrl-C stops it between
    pieces of 20,000 steps. RunFailed (with ``.steps``) when the physics faults on the way."""
    n = _steps_for(self, steps, duration_s)
    with Feed(self, ids, every) as feed:
        return feed.step(n)


def _stream(self: Model, ids: Union[str, Sequence[str]], block_steps: int = 1000,
            blocks: Optional[int] = None, every: int = 1) -> Iterator[Data]:
    """Yields the channels `ids` as :class:`Data` blocks, stepping the Model `block_steps` per
    block, losslessly, `blocks` times (forever when None: stop iterating to end it)."""
    if block_steps < 1:
        raise ValueError("block_steps must be >= 1")
    with Feed(self, ids, every) as feed:
        done = 0
        while blocks is None or done < blocks:
            yield feed.step(block_steps)
            done += 1


def _run_experiment(self: Model, experiment) -> Data:
    """Runs one experiment on this Model (caliper.experiments: a dict, a file's run, or
    caliper.Experiment) with a fresh load of its scene, and returns its recording."""
    from .experiments import experiments_of
    runs = experiments_of(experiment)
    if len(runs) != 1:
        raise ValueError(f"run_experiment takes one experiment, not {len(runs)}; use "
                         "caliper.run_batch for several")
    return Data(*_caliper._run_on(self, runs[0]))


def _feed(self: Model, ids: Union[str, Sequence[str]], every: int = 1) -> Feed:
    """A lossless :class:`Feed` of the channels `ids`, every `every` steps."""
    return Feed(self, ids, every)


def _parameters(self: Model, pattern: str = "*") -> Dict[str, Tuple[np.ndarray, str]]:
    """The model parameters (static channels: masses, stiffnesses, motor constants, ...) whose
    id matches the glob, as {id: (value, unit)}, each value in its channel's shape and unit."""
    channels = [c for c in self.channels(pattern) if c.static]
    values = self.get([c.id for c in channels]) if channels else []
    return {c.id: (v, c.unit) for c, v in zip(channels, values)}


def _fault(self: Model) -> Optional[str]:
    """Why the simulation faulted (the Model's report), or None when it runs normally."""
    s = self.status()
    return s.last_error if s.state == "FAULTED" else None


Model.record = _record
Model.feed = _feed
Model.parameters = _parameters
Model.fault = property(_fault)
Model.stream = _stream
Model.run_experiment = _run_experiment
