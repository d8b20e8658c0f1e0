"""caliper.TendonEnv and caliper.VectorEnv on the shipped arm: seeded episodes repeat bit for bit,
the spaces describe what comes back, actions are mapped, checked and clipped, episodes end by the
terminated callable and by truncation, and a VectorEnv over 2 Models returns exactly what 2 single
environments return (autoreset included)."""

import os

import numpy as np
import pytest

import caliper

ROOT = os.path.abspath(os.environ.get("CALIPER_SOURCE_DIR") or os.path.join(
    os.path.dirname(os.path.abspath(__file__)), "..", ".."))
SCENE = os.path.join(ROOT, "models", "ecce_arm.dae")

ACTUATORS = ["elbow_flexor", "elbow_extensor"]
OBSERVATIONS = ["ecce_arm.elbow.position", "ecce_arm.elbow.velocity", "ecce_arm.hand.position"]
MASS = "ecce_arm.forearm.mass"
RANDOMIZE = {MASS: (0.8, 1.6)}
TARGET = 0.5  # [rad]


def reward(obs, action, env):
    """Depends on the observation and on the action (so that both reach it)."""
    return -abs(float(obs[0]) - TARGET) - 0.001 * float(np.sum(action))


def bent(threshold):
    def terminated(obs, env):
        return bool(obs[0] > threshold)
    return terminated


@pytest.fixture(scope="module")
def session():
    """A private session of its own: 2 Models with the arm (the VectorEnv needs two)."""
    with caliper.LocalSession(models=2, scene=SCENE) as s:
        yield s


def make_env(model, **kwargs):
    options = dict(actuators=ACTUATORS, observations=OBSERVATIONS, reward=reward,
                   randomize=RANDOMIZE)
    options.update(kwargs)
    return caliper.TendonEnv(model, **options)


def episode(env, seed, steps):
    """An episode from reset(seed), its actions drawn from the action space (seeded by reset)."""
    obs, info = env.reset(seed=seed)
    out = {"obs": [obs], "actions": [], "rewards": [], "parameters": dict(info["parameters"])}
    for _ in range(steps):
        action = env.action_space.sample()
        obs, r, terminated, truncated, info = env.step(action)
        out["obs"].append(obs)
        out["actions"].append(action)
        out["rewards"].append(r)
        assert not terminated and not truncated
    return {k: (np.array(v) if isinstance(v, list) else v) for k, v in out.items()}


def test_a_seed_repeats_its_episode_bit_for_bit_and_another_seed_does_not(session):
    model = session.model("model0")
    env = make_env(model, max_episode_steps=1000)
    first = episode(env, 11, 30)
    other = episode(env, 12, 30)
    again = episode(env, 11, 30)

    # the same seed: the same drawn parameter, actions, observations and rewards, bit for bit
    assert first["parameters"] == again["parameters"]
    for key in ("actions", "obs", "rewards"):
        assert np.array_equal(first[key], again[key]), key
    # the parameter was drawn in its range and written into the Model (Bullet keeps it in
    # single precision)
    low, high = RANDOMIZE[MASS]
    assert low <= first["parameters"][MASS] <= high
    env.reset(seed=11)
    assert float(model.get(MASS)) == pytest.approx(first["parameters"][MASS], rel=1e-6)
    # the arm moved at all (else equal observations would prove little)
    assert np.abs(first["obs"][-1][0]) > 1e-4

    # another seed: another parameter, other actions, another trajectory
    assert other["parameters"][MASS] != first["parameters"][MASS]
    assert not np.array_equal(other["actions"], first["actions"])
    assert not np.array_equal(other["obs"][1:], first["obs"][1:])
    # but the same start (the scene's initial state)
    assert np.array_equal(other["obs"][0], first["obs"][0])


def test_reset_without_a_seed_continues_the_generator(session):
    env = make_env(session.model("model0"))
    _, info1 = env.reset(seed=3)
    _, info2 = env.reset()
    _, info3 = env.reset(seed=3)
    _, info4 = env.reset()
    assert info1["parameters"] == info3["parameters"]
    assert info2["parameters"] == info4["parameters"]
    assert info1["parameters"] != info2["parameters"]


def test_spaces_describe_what_comes_back(session):
    env = make_env(session.model("model0"), action_low=[0.5, 1.0], action_high=[6.0, 9.0])
    obs, info = env.reset(seed=0)
    space = env.observation_space
    # 1 + 1 + 3 values: elbow position, velocity, hand position (x, y, z)
    assert space.shape == (5,) and obs.shape == (5,)
    assert space.dtype == np.float64 and obs.dtype == np.float64
    assert np.all(space.low == -np.inf) and np.all(space.high == np.inf)
    assert space.contains(obs)
    assert np.array_equal(obs, np.concatenate([np.ravel(v) for v in
                                               env.model.get(OBSERVATIONS)]))
    assert info == {"elapsed_steps": 0, "parameters": env.parameters}

    actions = env.action_space
    assert actions.shape == (2,) and actions.dtype == np.float64
    assert np.array_equal(actions.low, [0.5, 1.0]) and np.array_equal(actions.high, [6.0, 9.0])
    for _ in range(20):
        a = actions.sample()
        assert a.shape == (2,) and a.dtype == np.float64
        assert actions.contains(a)
        obs, r, terminated, truncated, info = env.step(a)
        assert obs.shape == (5,) and obs.dtype == np.float64 and space.contains(obs)
        assert isinstance(r, float) and r == reward(obs, a, env)
        assert terminated is False and truncated is False
    assert info["elapsed_steps"] == 20
    # one action is frames_per_action physics steps
    assert env.model.status().steps == 20 * env.frames_per_action
    assert env.control_period_s == pytest.approx(10 * env.model.time_step_s)

    default = make_env(session.model("model0"), randomize=None)
    assert np.array_equal(default.action_space.low, [0.0, 0.0])
    assert np.array_equal(default.action_space.high, [12.0, 12.0])


def commands(model):
    return {a.name: a.command for a in model.actuator_states() if a.name in ACTUATORS}


def test_normalized_actions_map_onto_the_volt_bounds(session):
    model = session.model("model0")
    env = make_env(model, action_mode="normalized", action_low=[0.5, 1.0],
                   action_high=[6.0, 9.0])
    assert np.array_equal(env.action_space.low, [-1.0, -1.0])
    assert np.array_equal(env.action_space.high, [1.0, 1.0])
    env.reset(seed=0)
    assert commands(model) == {"elbow_flexor": 0.0, "elbow_extensor": 0.0}  # off after reset
    for action, volts in (([-1.0, 1.0], [0.5, 9.0]), ([1.0, -1.0], [6.0, 1.0]),
                          ([0.0, 0.0], [3.25, 5.0]), ([0.5, -0.5], [4.625, 3.0]),
                          # outside the box: clipped to it first
                          ([3.0, -7.0], [6.0, 1.0])):
        env.step(np.array(action))
        assert commands(model) == dict(zip(ACTUATORS, volts)), action
        assert np.array_equal(env.to_commands(np.clip(action, -1, 1)), volts)


def test_volt_actions_are_clipped_and_the_reward_sees_the_clipped_action(session):
    model = session.model("model0")
    seen = []
    env = make_env(model, reward=lambda obs, a, e: seen.append((a.copy(), e)) or 0.0)
    env.reset(seed=0)
    _, r, _, _, _ = env.step([20.0, -3.0])
    assert r == 0.0
    assert commands(model) == {"elbow_flexor": 12.0, "elbow_extensor": 0.0}
    assert np.array_equal(seen[0][0], [12.0, 0.0]) and seen[0][1] is env


def test_truncated_after_max_episode_steps(session):
    env = make_env(session.model("model0"), max_episode_steps=5)
    for seed in (0, 1):  # and again after a reset
        env.reset(seed=seed)
        flags = []
        for k in range(1, 6):
            _, _, terminated, truncated, info = env.step(env.action_space.sample())
            flags.append(truncated)
            assert info["elapsed_steps"] == k
            assert terminated is False
        assert flags == [False, False, False, False, True]


def test_terminated_callable_is_honoured(session):
    model = session.model("model0")
    calls = []
    threshold = 0.004

    def terminated(obs, env):
        calls.append((obs.copy(), env))
        return bool(obs[0] > threshold)

    env = make_env(model, terminated=terminated, max_episode_steps=200)
    env.reset(seed=0)
    ended_at = None
    for k in range(1, 201):
        obs, _, done, truncated, _ = env.step([12.0, 0.0])  # flex as hard as it goes
        assert calls[-1][1] is env and np.array_equal(calls[-1][0], obs)
        assert done == (obs[0] > threshold)
        assert truncated is False
        if done:
            ended_at = k
            break
    assert ended_at is not None and ended_at > 1, "the flexed elbow passes the threshold"
    assert len(calls) == ended_at

    # without the callable an episode never terminates
    plain = make_env(model, max_episode_steps=200)
    plain.reset(seed=0)
    for _ in range(ended_at + 5):
        _, _, done, _, _ = plain.step([12.0, 0.0])
        assert done is False


@pytest.mark.parametrize("action", [[1.0, 2.0, 3.0], [1.0], [[1.0, 2.0]], 1.0, [np.nan, 1.0],
                                    [1.0, np.inf], [-np.inf, 0.0]],
                         ids=["three", "one", "2d", "scalar", "nan", "inf", "-inf"])
def test_bad_actions_raise_value_error_and_step_nothing(session, action):
    model = session.model("model0")
    env = make_env(model)
    env.reset(seed=0)
    env.step([3.0, 1.0])
    before = model.status()
    with pytest.raises(ValueError):
        env.step(action)
    after = model.status()
    assert after.steps == before.steps
    assert env.elapsed_steps == 1
    assert commands(model) == {"elbow_flexor": 3.0, "elbow_extensor": 1.0}


# -- VectorEnv -----------------------------------------------------------------------------------

VECTOR_STEPS = 24
VECTOR_KWARGS = dict(actuators=ACTUATORS, observations=OBSERVATIONS, reward=reward,
                     terminated=bent(0.0035), randomize=RANDOMIZE, max_episode_steps=9)


def vector_actions():
    """The same actions for the vector and the single environments: flexor-heavy on lane 0 (its
    episodes end by the terminated callable), gentle on lane 1 (truncated)."""
    rng = np.random.default_rng(2024)
    return np.stack([rng.uniform([[0.0, 0.0], [0.0, 0.0]], [[12.0, 2.0], [2.0, 2.0]])
                     for _ in range(VECTOR_STEPS)])


def run_single(env, seed, actions):
    """What a single environment gives when driven like one lane of a VectorEnv (classic
    autoreset: reset without a seed as soon as an episode ends)."""
    obs0, info0 = env.reset(seed=seed)
    steps = []
    for a in actions:
        obs, r, terminated, truncated, info = env.step(a)
        step = {"obs": obs, "reward": r, "terminated": terminated, "truncated": truncated,
                "info": info, "final_observation": None, "reset_info": None}
        if terminated or truncated:
            step["final_observation"] = obs
            step["obs"], step["reset_info"] = env.reset()
        steps.append(step)
    return obs0, info0, steps


@pytest.fixture(scope="module")
def vector_and_singles(session):
    seed = 40
    actions = vector_actions()
    venv = caliper.VectorEnv.across(session, "model*", **VECTOR_KWARGS)
    try:
        assert venv.num_envs == 2
        assert venv.action_space.shape == (2, 2)
        assert venv.observation_space.shape == (2, 5)
        obs0, info0 = venv.reset(seed=seed)
        vector = [venv.step(a) for a in actions]
    finally:
        venv.close()
    names = [e.model.name for e in venv.envs]
    singles = []
    for i, name in enumerate(names):  # environment i on the Model of lane i, seeded seed + i
        env = caliper.TendonEnv(session.model(name), session=session, **VECTOR_KWARGS)
        singles.append(run_single(env, seed + i, actions[:, i]))
    return (obs0, info0, vector), singles


def test_vector_env_equals_single_envs_bit_for_bit(vector_and_singles):
    (obs0, info0, vector), singles = vector_and_singles
    assert np.array_equal(obs0, np.stack([s[0] for s in singles]))
    assert info0["parameters"] == [s[1]["parameters"] for s in singles]
    # seed + i: the two lanes drew different parameters
    assert info0["parameters"][0] != info0["parameters"][1]
    assert np.array_equal(info0["elapsed_steps"], [0, 0])

    ended = {"terminated": 0, "truncated": 0}
    for t, (obs, rewards, terminated, truncated, info) in enumerate(vector):
        assert obs.shape == (2, 5) and rewards.shape == (2,)
        assert terminated.dtype == bool and truncated.dtype == bool
        for i, single in enumerate(singles):
            s = single[2][t]
            where = f"step {t}, env {i}"
            assert np.array_equal(obs[i], s["obs"]), where
            assert rewards[i] == s["reward"], where
            assert terminated[i] == s["terminated"], where
            assert truncated[i] == s["truncated"], where
            done = s["final_observation"] is not None
            if done:
                ended["terminated" if s["terminated"] else "truncated"] += 1
                assert info["_final_observation"][i], where
                assert np.array_equal(info["final_observation"][i], s["final_observation"]), where
            elif "_final_observation" in info:
                assert not info["_final_observation"][i], where
            else:
                assert not any(x[2][t]["final_observation"] is not None for x in singles)
            if not done:  # an ongoing episode: its step's info
                assert info["elapsed_steps"][i] == s["info"]["elapsed_steps"], where
                assert info["parameters"][i] == s["info"]["parameters"], where
    # the run covered both ways an episode ends
    assert ended["terminated"] >= 1 and ended["truncated"] >= 1, ended


def test_vector_env_info_after_autoreset_describes_the_new_episode(vector_and_singles):
    """gymnasium's classic autoreset (SyncVectorEnv before 1.0): a lane that ended returns the
    reset's observation with the reset's info; the finished episode is in final_observation
    (and final_info)."""
    (_, _, vector), singles = vector_and_singles
    checked = 0
    for t, (obs, _, _, _, info) in enumerate(vector):
        for i, single in enumerate(singles):
            s = single[2][t]
            if s["reset_info"] is None:
                continue
            checked += 1
            where = f"step {t}, env {i}"
            # the observation is the new episode's (checked above) and so must be the info
            assert info["elapsed_steps"][i] == 0, where
            assert info["parameters"][i] == s["reset_info"]["parameters"], where
    assert checked >= 2
