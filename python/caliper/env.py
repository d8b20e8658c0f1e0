"""A Gymnasium-style environment on a Caliper Model, and a vector of them over several Models.

It follows gymnasium's API exactly (``reset(seed=None, options=None) -> (obs, info)``,
``step(action) -> (obs, reward, terminated, truncated, info)``, ``observation_space`` and
``action_space`` as Box with shape, dtype and bounds, ``render()`` returning an RGB array) and is
a ``gymnasium.Env`` with gymnasium's own Box when gymnasium is importable; Caliper does not need
it. Lock-step: the Model advances only in ``step``, by ``frames_per_action`` physics steps, so
an episode is a function of its seed and actions::

    env = caliper.TendonEnv(session.model("model0"),
                            actuators=["elbow_flexor", "elbow_extensor"],
                            observations=["ecce_arm.elbow.position", "ecce_arm.elbow.velocity"],
                            reward=lambda obs, action, env: -abs(obs[0] - 1.0),
                            randomize={"ecce_arm.forearm.mass": (0.8, 1.2)})
    obs, info = env.reset(seed=1)
    obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
"""

from __future__ import annotations

import io
import math
from concurrent.futures import ThreadPoolExecutor
from typing import Any, Callable, Dict, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from . import _caliper
from .model import Model
from .session import Session
from .spaces import GYMNASIUM, Box

__all__ = ["TendonEnv", "VectorEnv"]

if GYMNASIUM:  # pragma: no cover - depends on the machine
    import gymnasium
    _EnvBase: type = gymnasium.Env
else:
    _EnvBase = object

Reward = Callable[[np.ndarray, np.ndarray, "TendonEnv"], float]
Terminated = Callable[[np.ndarray, "TendonEnv"], bool]


def _check_ids(ids: Sequence[str], what: str) -> List[str]:
    if isinstance(ids, str) or not all(isinstance(i, str) for i in ids) or not ids:
        raise TypeError(f"{what} must be a non-empty list of ids")
    return list(ids)


class TendonEnv(_EnvBase):  # type: ignore[misc,valid-type]
    """An episode task on one Model.

    - `model`: a :class:`caliper.Model` (or its name in `session`); `scene`, when given, is
      loaded into it first.
    - `actuators`: the actuators the action drives, in order. `action_mode` "volts": actions are
      commands in [`action_low`, `action_high`] (the actuators' unit, V for DC motors);
      "normalized": actions in [-1, 1] mapped linearly onto that range.
    - `observations`: DAQ ids; the observation is their values, flat, in this order (float64).
    - `reward(obs, action, env)` and `terminated(obs, env)`: Python callables (reward 0 and
      never terminated without them); an episode is truncated after `max_episode_steps`
      actions.
    - `frames_per_action`: physics steps per action (the control period is that times the
      Model's time step, :attr:`control_period_s`).
    - `randomize`: {id: (low, high)} parameter ranges drawn uniformly at each reset from the
      environment's generator (seeded by ``reset(seed=...)``), written after the Model's reset.
    - `render_mode` "rgb_array": :meth:`render` returns the Scene Renderer's view (one must run
      in the session) as a (height, width, 3) uint8 array of `render_size` (width, height).
    """

    metadata = {"render_modes": ["rgb_array"]}

    def __init__(self, model: Union[Model, str] = "model0", *, session: Optional[Session] = None,
                 scene: Optional[str] = None, actuators: Sequence[str],
                 observations: Sequence[str], reward: Optional[Reward] = None,
                 terminated: Optional[Terminated] = None, frames_per_action: int = 10,
                 max_episode_steps: int = 1000, action_mode: str = "volts",
                 action_low: Union[float, Sequence[float]] = 0.0,
                 action_high: Union[float, Sequence[float]] = 12.0,
                 randomize: Optional[Mapping[str, Tuple[float, float]]] = None,
                 render_mode: Optional[str] = None, render_size: Tuple[int, int] = (480, 360)):
        if isinstance(model, str):
            from .session import connect
            session = session or connect()
            model = session.model(model)
        self.model: Model = model
        self.session = session
        self.actuators = _check_ids(actuators, "actuators")
        self.observation_ids = _check_ids(observations, "observations")
        if action_mode not in ("volts", "normalized"):
            raise ValueError(f"action_mode must be 'volts' or 'normalized', not {action_mode!r}")
        if not isinstance(frames_per_action, int) or frames_per_action < 1:
            raise ValueError("frames_per_action must be a positive integer")
        if not isinstance(max_episode_steps, int) or max_episode_steps < 1:
            raise ValueError("max_episode_steps must be a positive integer")
        if render_mode not in (None, "rgb_array"):
            raise ValueError(f"render_mode must be None or 'rgb_array', not {render_mode!r}")
        self.action_mode = action_mode
        self.frames_per_action = frames_per_action
        self.max_episode_steps = max_episode_steps
        self.reward_fn = reward
        self.terminated_fn = terminated
        self.render_mode = render_mode
        self.render_size = render_size
        self.randomize: Dict[str, Tuple[float, float]] = {}
        for id, bounds in (randomize or {}).items():
            low, high = (float(b) for b in bounds)
            if not (math.isfinite(low) and math.isfinite(high) and low <= high):
                raise ValueError(f"randomize[{id!r}] must be finite (low, high) with low <= high")
            self.randomize[id] = (low, high)
        if scene is not None:
            self.model.load(scene)
        if self.model.status().state == "RUNNING":
            self.model.pause()  # lock-step: the environment steps it
        n = len(self.actuators)
        self._volts_low = np.broadcast_to(np.asarray(action_low, dtype=np.float64), (n,)).copy()
        self._volts_high = np.broadcast_to(np.asarray(action_high, dtype=np.float64), (n,)).copy()
        if np.any(self._volts_low > self._volts_high):
            raise ValueError("action_low must be <= action_high")
        if action_mode == "volts":
            self.action_space = Box(self._volts_low, self._volts_high, shape=(n,), dtype=np.float64)
        else:
            self.action_space = Box(-1.0, 1.0, shape=(n,), dtype=np.float64)
        width = sum(int(np.prod(np.shape(v), dtype=np.int64)) for v in
                    self.model.get(self.observation_ids))
        self.observation_space = Box(-np.inf, np.inf, shape=(width,), dtype=np.float64)
        self._lockstep = _caliper._Lockstep([self.model], self.actuators, self.observation_ids)
        self.np_random = np.random.default_rng()
        self.elapsed_steps = 0
        self.parameters: Dict[str, float] = {}
        self.control_period_s = frames_per_action * self.model.time_step_s

    # -- gymnasium's API ---------------------------------------------------------------------
    def reset(self, *, seed: Optional[int] = None,
              options: Optional[Dict[str, Any]] = None) -> Tuple[np.ndarray, Dict[str, Any]]:
        """Back to the scene's initial state with the actuators off and freshly drawn
        parameters. `seed` reseeds the environment's generator (and the action space's);
        `options` may hold "parameters": {id: value} written after the drawn ones."""
        if seed is not None:
            self.np_random = np.random.default_rng(seed)
            self.action_space.seed(seed)
        self.model.reset()
        self.model.set_commands({a: 0.0 for a in self.actuators})
        self.parameters = {id: float(self.np_random.uniform(low, high))
                           for id, (low, high) in self.randomize.items()}
        self.parameters.update((options or {}).get("parameters", {}))
        for id, value in self.parameters.items():
            self.model.set(id, value)
        self.elapsed_steps = 0
        return self._observe(), self._info()

    def step(self, action) -> Tuple[np.ndarray, float, bool, bool, Dict[str, Any]]:
        """Applies `action` (clipped to the action space), runs `frames_per_action` steps and
        returns (observation, reward, terminated, truncated, info)."""
        a = self._check_action(action)
        obs = self._lockstep.step(self.to_commands(a)[None, :], self.frames_per_action)[0]
        return self._outcome(obs, a)

    def _check_action(self, action) -> np.ndarray:
        a = np.asarray(action, dtype=np.float64)
        if a.shape != self.action_space.shape:
            raise ValueError(f"action must have shape {self.action_space.shape}, not {a.shape}")
        if not np.all(np.isfinite(a)):
            raise ValueError("action must be finite")
        return np.clip(a, self.action_space.low, self.action_space.high)

    def _outcome(self, obs: np.ndarray, a: np.ndarray
                 ) -> Tuple[np.ndarray, float, bool, bool, Dict[str, Any]]:
        """What step returns once the Model ran the action (set, stepped, observed)."""
        self.elapsed_steps += 1
        reward = float(self.reward_fn(obs, a, self)) if self.reward_fn else 0.0
        terminated = bool(self.terminated_fn(obs, self)) if self.terminated_fn else False
        truncated = self.elapsed_steps >= self.max_episode_steps
        return obs, reward, terminated, truncated, self._info()

    def render(self) -> Optional[np.ndarray]:
        """The renderer's view as an RGB array (render_mode "rgb_array"), else None."""
        if self.render_mode != "rgb_array":
            return None
        from PIL import Image  # Debian's python3-pil
        session = self.session
        if session is None:
            from .session import connect
            session = self.session = connect()
        png = session.screenshot(*self.render_size)
        return np.asarray(Image.open(io.BytesIO(png)).convert("RGB"))

    def close(self) -> None:
        """Switches the environment's actuators off."""
        try:
            self.model.set_commands({a: 0.0 for a in self.actuators})
        except Exception:  # the Model may be gone; nothing left to switch off
            pass

    # -- helpers -----------------------------------------------------------------------------
    def to_commands(self, action: np.ndarray) -> np.ndarray:
        """The actuators' commands for an action of the action space."""
        if self.action_mode == "volts":
            return action
        return self._volts_low + (action + 1.0) * 0.5 * (self._volts_high - self._volts_low)

    def _observe(self) -> np.ndarray:
        return self.model.get_values(self.observation_ids)

    def _info(self) -> Dict[str, Any]:
        return {"elapsed_steps": self.elapsed_steps, "parameters": dict(self.parameters)}

    @property
    def unwrapped(self) -> "TendonEnv":
        return self

    def __repr__(self) -> str:
        return (f"<caliper.TendonEnv on {self.model.name}: {len(self.actuators)} actuators, "
                f"{self.observation_space.shape[0]} observed values, "
                f"{self.control_period_s * 1e3:.3g} ms per action>")


class VectorEnv:
    """N environments with the same actuators, observations and control period, each on its
    own Model, stepped in parallel (one lock-step cycle per Model on threads of the extension,
    without the GIL; each Model computes in its own process, here or on other hosts). Observations,
    rewards and flags come stacked along a first axis of size N. An environment whose episode
    ends is reset in the same call (gymnasium's classic autoreset): the observation and info are
    the new episode's, its last observation and info are in ``info["final_observation"][i]`` and
    ``info["final_info"][i]``, marked by ``info["_final_observation"][i]``.

    ``VectorEnv.across(session, models="*", **kwargs)`` makes one TendonEnv(**kwargs) per Model
    matching the glob."""

    def __init__(self, envs: Sequence[TendonEnv]):
        if not envs:
            raise ValueError("a VectorEnv needs at least one environment")
        self.envs = list(envs)
        self.num_envs = len(self.envs)
        first = self.envs[0]
        for e in self.envs[1:]:
            if (e.actuators, e.observation_ids, e.frames_per_action) != \
                    (first.actuators, first.observation_ids, first.frames_per_action):
                raise ValueError("the environments of a VectorEnv must have the same actuators, "
                                 "observations and frames_per_action")
        if len({e.model.path for e in self.envs}) != self.num_envs:
            raise ValueError("each environment of a VectorEnv needs a Model of its own")
        self._lockstep = _caliper._Lockstep([e.model for e in self.envs], first.actuators,
                                            first.observation_ids)
        self.single_observation_space = first.observation_space
        self.single_action_space = first.action_space
        self.observation_space = Box(-np.inf, np.inf,
                                     shape=(self.num_envs,) + first.observation_space.shape,
                                     dtype=np.float64)
        self.action_space = Box(np.stack([e.action_space.low for e in self.envs]),
                                np.stack([e.action_space.high for e in self.envs]),
                                dtype=np.float64)
        self._executor = ThreadPoolExecutor(max_workers=self.num_envs)

    @classmethod
    def across(cls, session: Session, models: str = "*", **kwargs) -> "VectorEnv":
        names = session.models(models)
        if not names:
            raise ValueError(f"no Model matching {models!r} in the session at {session.address}")
        return cls([TendonEnv(session.model(n), session=session, **kwargs) for n in names])

    def _map(self, fn, *args):
        return list(self._executor.map(fn, *args))

    def reset(self, *, seed: Optional[int] = None, options: Optional[Dict[str, Any]] = None
              ) -> Tuple[np.ndarray, Dict[str, Any]]:
        """Resets every environment; environment i is seeded `seed` + i."""
        seeds = [None if seed is None else seed + i for i in range(self.num_envs)]
        results = self._map(lambda e, s: e.reset(seed=s, options=options), self.envs, seeds)
        return np.stack([r[0] for r in results]), self._stack_infos([r[1] for r in results])

    def step(self, actions) -> Tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray,
                                     Dict[str, Any]]:
        """Steps every environment with its row of `actions` (N x action size), in parallel;
        returns stacked (observations, rewards, terminated, truncated, infos)."""
        actions = np.asarray(actions, dtype=np.float64)
        if actions.shape != self.action_space.shape:
            raise ValueError(f"actions must have shape {self.action_space.shape}, not "
                             f"{actions.shape}")

        clipped = [e._check_action(a) for e, a in zip(self.envs, actions)]
        commands = np.stack([e.to_commands(a) for e, a in zip(self.envs, clipped)])
        observed = self._lockstep.step(commands, self.envs[0].frames_per_action)
        results = []
        for env, obs, a in zip(self.envs, observed, clipped):
            obs, reward, terminated, truncated, info = env._outcome(obs, a)
            if terminated or truncated:
                final_obs, final_info = obs, info
                obs, info = env.reset()
                info = dict(info, final_observation=final_obs, final_info=final_info)
            results.append((obs, reward, terminated, truncated, info))
        infos = self._stack_infos([r[4] for r in results])
        return (np.stack([r[0] for r in results]), np.array([r[1] for r in results]),
                np.array([r[2] for r in results]), np.array([r[3] for r in results]), infos)

    def _stack_infos(self, infos: List[Dict[str, Any]]) -> Dict[str, Any]:
        out: Dict[str, Any] = {"elapsed_steps": np.array([i["elapsed_steps"] for i in infos]),
                               "parameters": [i["parameters"] for i in infos]}
        if any("final_observation" in i for i in infos):
            for key in ("final_observation", "final_info"):
                out[key] = np.array([i.get(key) for i in infos], dtype=object)
                out["_" + key] = np.array([key in i for i in infos])
        return out

    def close(self) -> None:
        """Closes every environment and the worker threads."""
        for e in self.envs:
            e.close()
        self._lockstep = None  # its threads end with it
        self._executor.shutdown()
