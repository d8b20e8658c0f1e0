"""Shared fixtures of the Python package's tests (tests/python/test_*.py).

Each test file gets its own private session (caliper.LocalSession: a naming service and Models on
loopback), so that ctest can run the files in parallel:

- ``ROOT``: the source tree ($CALIPER_SOURCE_DIR, else two levels above this file); ``SCENE``:
  the shipped arm, models/ecce_arm.dae.
- ``scene_path``: SCENE as a fixture.
- ``session``: a module-scoped session with one Model (model0) loaded with the arm. It is the
  :class:`caliper.LocalSession` (``files_dir``, ``kill``, ``model``) and answers the
  :class:`caliper.Session` calls too (``models()``, ``components()``, ``timeout_s``).
- ``arm``: its model0, before each test paused or stopped, reset to time 0, out of any replay
  (the arm loaded again) and with every command at 0. A test that changes a parameter, the time
  step or the scene puts it back.
- ``new_session``: a factory of further sessions (``new_session(models=2)``,
  ``new_session(scene=None)``, ``new_session(options=[...])``), closed after the test; for tests
  that kill Models or need other options. Sessions opened in one process share its ORB
  (test_errors.py, test_a_second_local_session_leaves_the_first_working).
"""

import os

import pytest

import caliper

ROOT = os.path.abspath(os.environ.get("CALIPER_SOURCE_DIR")
                       or os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
SCENE = os.path.join(ROOT, "models", "ecce_arm.dae")

#: the keyword that means "the arm" for new_session's scene (None: no scene)
_ARM = object()


class LocalSession(caliper.LocalSession):
    """A caliper.LocalSession that also answers caliper.Session's calls, and whose ``with`` gives
    the object itself (so that a test can kill its Models)."""

    def __getattr__(self, name):
        session = self.__dict__.get("session")
        if session is None:
            raise AttributeError(name)
        return getattr(session, name)

    def __enter__(self):
        return self


def start_session(models=1, scene=_ARM, **options):
    """A new LocalSession of `models` Models loaded with `scene` (the arm by default)."""
    return LocalSession(models=models, scene=SCENE if scene is _ARM else scene, **options)


@pytest.fixture(scope="session")
def scene_path():
    return SCENE


@pytest.fixture(scope="module")
def session():
    local = start_session()
    try:
        yield local
    finally:
        local.close()


@pytest.fixture
def arm(session):
    model = session.model("model0")
    if model.replay_status().replaying:
        model.fork()
        model.load(SCENE)  # the arm again, not the replayed recording's scene
    if model.status().state == "RUNNING":
        model.pause()  # reset() of a running Model rewinds and keeps it running
    model.reset()
    states = model.actuator_states()
    if any(s.command != 0 for s in states):
        model.set_commands({s.name: 0.0 for s in states if s.command != 0})
    status = model.status()
    assert status.state in ("PAUSED", "STOPPED") and status.steps == 0, status
    return model


@pytest.fixture
def new_session():
    started = []

    def make(models=1, scene=_ARM, **options):
        local = start_session(models, scene, **options)
        started.append(local)
        return local

    yield make
    for local in reversed(started):
        local.close()


def pytest_sessionfinish(session, exitstatus):
    """A run that skipped a test exits 77, which ctest reports as Skipped (SKIP_RETURN_CODE):
    a skip is never counted as a pass."""
    reporter = session.config.pluginmanager.get_plugin("terminalreporter")
    if exitstatus == 0 and reporter is not None and reporter.stats.get("skipped"):
        session.exitstatus = 77
