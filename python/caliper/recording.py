"""Recording files read here, without a session: :class:`Recording`."""

from __future__ import annotations

import os
from typing import List, NamedTuple, Optional, Tuple

import numpy as np

from . import _caliper
from .model import Channel, Data

__all__ = ["Recording", "Event", "LogRecord", "SceneVersion"]


class Event(NamedTuple):
    """Something that happened in the recording, taking effect after `step` steps: kind
    "command" (target: the actuator; values: the command in its unit, V for a DC motor),
    "parameter" (target: the id; values in its unit), "pull" (target: the body; values: the point
    in the body's frame [m], the target in the world [m], the stiffness [N/m]), "release", "edit"
    (target: what the edit did), "keyframe" (a full-state keyframe was written) and "end"
    (target: why the recording ended, e.g. "stopped")."""
    step: int
    kind: str
    target: str
    values: np.ndarray


class LogRecord(NamedTuple):
    time_s: float       #: wall time since the epoch [s]
    priority: str
    category: str
    component: str
    message: str


class SceneVersion(NamedTuple):
    version: int        #: 0 at the start, one more after each edit
    step: int           #: in force from this step on
    file_name: str
    data: bytes         #: the scene file's bytes (COLLADA)


class Recording:
    """A session recording (the SQLite file a Model writes; docs/recording.md), read without a
    session::

        rec = caliper.Recording("run.caliper")
        data = rec.channels_data()           # caliper.Data: rec.time, data["arm.elbow.position"]
        rec.events(kind="command")           # every motor command, with its step
        rec.keyframe_times_s                 # [s]

    Raises :class:`caliper.RecordingError` naming the file when it is missing or not a
    recording.
    """

    def __init__(self, path: "os.PathLike[str] | str"):
        self.path = os.fspath(path)
        self._file = _caliper._RecordingFile(self.path)
        h = self._file.header()
        self.model_name: str = h["model_name"]
        self.scene_file_name: str = h["scene_file_name"]
        self.time_step_s: float = h["time_step_s"]
        self.keyframe_every: int = h["keyframe_every"]
        self.channels_every: int = h["channels_every"]
        self.first_step: int = h["first_step"]
        self.last_step: int = h["last_step"]
        self.duration_s: float = h["duration_s"]
        self.engine: str = h["engine"]
        #: the sampled channels, in the order of their values
        self.channels: List[Channel] = list(h["channels"])
        steps, times = self._file.keyframes()
        self.keyframe_steps: np.ndarray = steps
        self.keyframe_times_s: np.ndarray = times

    def channels_data(self, first_step: Optional[int] = None,
                      last_step: Optional[int] = None) -> Data:
        """The channels' samples with first_step <= step < last_step (all by default), as
        :class:`caliper.Data` (its ``steps`` too)."""
        first = self.first_step if first_step is None else first_step
        last = self.last_step + 1 if last_step is None else last_step
        steps, time, values = self._file.samples(first, last)
        if values.shape[1] == 0:
            values = np.zeros((len(time), sum(c.size for c in self.channels)))
        data = Data(self.channels, time, values)
        data.steps = steps
        return data

    def events(self, kind: Optional[str] = None, first_step: Optional[int] = None,
               last_step: Optional[int] = None) -> List[Event]:
        """The events in order (only those of `kind` when given)."""
        first = self.first_step if first_step is None else first_step
        last = self.last_step + 1 if last_step is None else last_step
        return [e for e in self._file.events(first, last) if kind is None or e.kind == kind]

    def log(self) -> List[LogRecord]:
        """The session's log records."""
        return [LogRecord(*r) for r in self._file.log()]

    def scenes(self) -> List[SceneVersion]:
        """Every version of the scene (the first, then one per edit)."""
        return [SceneVersion(*s) for s in self._file.scenes()]

    def export_csv(self, csv_path: "os.PathLike[str] | str") -> None:
        """Writes the channels as CSV (``time [s]`` then one column per element with its unit)."""
        self._file.export_csv(os.fspath(csv_path))

    def __repr__(self) -> str:
        return (f"<caliper.Recording {self.path}: {self.model_name}, {self.duration_s:.6g} s, "
                f"{len(self.keyframe_steps)} keyframes, {len(self.channels)} channels>")


def verify(path: "os.PathLike[str] | str") -> Tuple[bool, str]:
    """Re-simulates a recording from its start in a Model process of its own (``caliper-model
    --verify``) and compares every keyframe and sample bit for bit: (True, its report) when
    identical, (False, the first divergence) otherwise."""
    import subprocess
    from .session import binary
    p = subprocess.run([binary("caliper-model"), "--verify", os.fspath(path)],
                       capture_output=True, text=True)
    report = (p.stdout + p.stderr).strip()
    if p.returncode not in (0, 1):
        raise _errors().RecordingError(report or f"caliper-model --verify exited {p.returncode}")
    return p.returncode == 0, report


def _errors():
    from . import errors
    return errors
