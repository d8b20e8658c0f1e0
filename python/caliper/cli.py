"""For scripts: the options that choose a session (a running one, or a private one started for
the run) and the Model's preparation for a lock-step run. The examples of examples/python use
them::

    parser = argparse.ArgumentParser(description=__doc__, formatter_class=caliper.cli.HelpFormatter)
    caliper.cli.add_session_arguments(parser)
    args = parser.parse_args()
    with caliper.cli.open_session(args, models=2, scene="models/ecce_arm.dae") as session:
        arm = session.model("model0")
        caliper.cli.prepare(arm, "models/ecce_arm.dae")
"""

from __future__ import annotations

import argparse
import contextlib
import os
import time
from typing import Iterator, Optional

from .errors import ConnectionError
from .model import Model
from .session import LocalSession, Session, connect

__all__ = ["HelpFormatter", "add_session_arguments", "open_session", "prepare"]


class HelpFormatter(argparse.RawDescriptionHelpFormatter):
    """--help: the description as written, and each option's default."""

    def _get_help_string(self, action):
        default = action.default
        if default in (None, False, argparse.SUPPRESS):
            return action.help
        if isinstance(default, (list, tuple)):
            default = " ".join(map(str, default))
        return f"{action.help} (default: {default})"


def add_session_arguments(parser: argparse.ArgumentParser) -> None:
    """--nameservice corbaname::HOST:PORT or --latest (the newest session on this host); with
    neither, :func:`open_session` starts a private one."""
    group = parser.add_argument_group("session (default: a private one started for this run)")
    which = group.add_mutually_exclusive_group()
    which.add_argument("--nameservice", metavar="corbaname::HOST:PORT",
                       help="use the Models of the running session with this naming service")
    which.add_argument("--latest", action="store_true",
                       help="use the newest session started on this host (caliper.connect())")


@contextlib.contextmanager
def open_session(args: argparse.Namespace, models: int, scene: Optional[str] = None
                 ) -> Iterator[Session]:
    """The running session the options name, else a private :class:`LocalSession` of `models`
    Models with `scene` loaded, stopped when the block ends. Prints which it is; a session that
    does not answer ends the program with its message."""
    if getattr(args, "nameservice", None) or getattr(args, "latest", False):
        try:
            session = connect(args.nameservice)
        except ConnectionError as e:
            raise SystemExit(f"error: {e}") from None
        print(f"session: {session.address} (running; Models: {', '.join(session.models())})")
        yield session
        return
    started = time.monotonic()
    local = LocalSession(models=models, scene=scene)
    try:
        what = f" of {os.path.basename(scene)}" if scene else ""
        print(f"session: private, {models} Model(s){what} at {local.address} "
              f"(started in {time.monotonic() - started:.2f} s)")
        yield local.session
    finally:
        local.close()


def prepare(model: Model, scene: str) -> None:
    """Lock-step from the scene's start: `scene` loaded (when the Model has another or none),
    paused, at time 0."""
    status = model.status()
    if status.state == "EMPTY" or os.path.basename(status.scene) != os.path.basename(scene):
        print(f"{model.name}: loading {scene}")
        model.load(scene)
    if model.status().state == "RUNNING":
        model.pause()
    model.reset()
