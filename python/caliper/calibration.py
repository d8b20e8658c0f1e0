"""A calibration file's cost for parameter vectors, evaluated on the Models of a session or
cluster, so that any optimiser (scipy.optimize, your own) can drive it::

    cal = caliper.Calibration("examples/calibration/calibration.json")
    result = scipy.optimize.minimize(cal.cost, cal.initial, bounds=cal.bounds,
                                     method="Nelder-Mead")

The cost is caliper-calibrate's (docs/calibration.md): the weighted RMS of simulated minus
measured over each measured column's range, 0 for a perfect fit.
"""

from __future__ import annotations

import os
from concurrent.futures import ThreadPoolExecutor
from typing import List, NamedTuple, Optional, Sequence, Tuple

import numpy as np

from . import _caliper
from .errors import Error
from .model import Data
from .session import Session, connect

__all__ = ["Calibration", "Evaluation", "Parameter", "ChannelCost"]


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
