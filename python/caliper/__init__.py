"""Caliper from Python: drive the Models of a Caliper session (tendon-driven robots in a Bullet
world), get their data as numpy arrays, run experiments, batches and calibrations over a cluster,
and train controllers in a Gymnasium-style environment.

    import caliper
    session = caliper.connect()                 # the newest session on this host
    arm = session.model("model0")
    arm.set_commands({"elbow_flexor": 6.0, "elbow_extensor": 1.0})   # [V]
    data = arm.record(["ecce_arm.elbow.position"], duration_s=1.0)
    print(data.time[-1], data["ecce_arm.elbow.position"][-1])          # [s], [rad]

See docs/python.md for the whole tour and ``help()`` on every class.
"""

from . import cli, errors
from .errors import (ConnectionError, EditRefused, Error, FormatError, InvalidParameter,
                     LimitExceeded, LoadFailed, NotAvailable, RecordingError, RunFailed,
                     SetupError, UnknownId)
from .session import Component, LocalSession, Session, binary, connect
from .model import (Actuator, ActuatorState, Channel, Data, EditStatus, Feed, Model, RecordStatus,
                    ReplayStatus, Status)
from .recording import Event, LogRecord, Recording, SceneVersion, verify
from .experiments import Batch, load_experiments, run_batch
from .calibration import Calibration, CalibrationResult, Evaluation, calibrate
from .env import TendonEnv, VectorEnv
from .spaces import Box

__version__ = "0.1.0"

__all__ = [
    "connect", "Session", "LocalSession", "Component", "Model", "Status", "Channel", "Actuator",
    "ActuatorState", "EditStatus", "RecordStatus", "ReplayStatus", "Data", "Feed", "Recording",
    "Event", "LogRecord", "SceneVersion", "verify", "load_experiments", "run_batch", "Batch",
    "Calibration", "Evaluation", "calibrate", "CalibrationResult", "TendonEnv", "VectorEnv", "Box",
    "binary", "cli", "errors", "Error", "ConnectionError", "UnknownId", "InvalidParameter",
    "NotAvailable", "LoadFailed", "LimitExceeded", "RunFailed", "EditRefused", "SetupError",
    "FormatError", "RecordingError",
]
