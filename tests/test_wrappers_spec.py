"""Every wrapper records its constructor arguments: gym.make(env.spec) rebuilds the same chain."""

import inspect
import json
import pickle
from functools import partial

import gymnasium as gym
import numpy as np
import pytest
import shimmy
from gymnasium.envs.registration import EnvSpec

import simoun_wrappers
from simoun_wrappers import (
    ActionRepeat,
    ColorShift,
    ConsistencyCuriosityReward,
    ConstantBonusReward,
    ConstantBonusVectorReward,
    FrameTriplet,
    MovingBackground,
    MultiCamera,
    RandomConvolution,
    ResidualMotion,
    RNDReward,
    RNDVectorReward,
    SimounObservation,
)
from simoun_wrappers.intrinsic_normalization import ReturnStd

gym.register_envs(shimmy)


def _channel_first(env: gym.Env) -> gym.Env:
    env = gym.wrappers.ResizeObservation(gym.wrappers.AddRenderObservation(env), (16, 16))
    space = gym.spaces.Box(0, 255, (3, 16, 16), np.uint8)
    return gym.wrappers.TransformObservation(env, lambda o: o.transpose(2, 0, 1), space)


def _cartpole() -> gym.Env:
    return gym.make("CartPole-v1", render_mode="rgb_array")


def _novelty(triplets: np.ndarray) -> np.ndarray:
    return triplets[:, -1].mean(axis=(1, 2, 3)).astype(np.float32)


def _features(triplets: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    f_a = triplets.reshape(*triplets.shape[:2], -1)[..., :8].astype(np.float32)
    return f_a[:, 2] - f_a[:, 1], f_a


def _pixels() -> gym.Env:
    return SimounObservation(_cartpole(), size=16)


CHAINS = {
    "FrameTriplet": lambda: FrameTriplet(gym.make("CartPole-v1"), num_frames=4),
    "ResidualMotion": lambda: ResidualMotion(FrameTriplet(_channel_first(_cartpole()), 2)),
    "ActionRepeat": lambda: ActionRepeat(gym.make("CartPole-v1"), repeat=3),
    "RandomConvolution": lambda: SimounObservation(RandomConvolution(_cartpole(), 5), size=16),
    "MultiCamera": lambda: MultiCamera(
        gym.make("dm_control/cartpole-swingup-v0"), ["lookatcart", 0], size=(12, 20)
    ),
    "SimounObservation": lambda: SimounObservation(
        _cartpole(), size=(12, 20), grayscale=True, num_frames=4, fold_frames=True
    ),
    "ConstantBonusReward": lambda: ConstantBonusReward(_pixels(), 0.1, decay=0.01),
    "RNDReward": lambda: RNDReward(_pixels(), _novelty, scale=0.3, warmup=0, progress=0.5),
    "ConsistencyCuriosityReward": lambda: ConsistencyCuriosityReward(
        _pixels(), _features, normalization="reward_std", warmup=1
    ),
    "ColorShift": lambda: ColorShift(
        gym.make("dm_control/cartpole-swingup-v0", render_mode="rgb_array"), seed=0
    ),
    "MovingBackground": lambda: MovingBackground(
        gym.make("dm_control/cartpole-swingup-v0", render_mode="rgb_array"), seed=0
    ),
}
"""one chain per wrapper class of simoun_wrappers that takes a single env"""


def test_every_single_env_wrapper_has_a_chain():
    wrappers = {
        name
        for name in simoun_wrappers.__all__
        if isinstance(getattr(simoun_wrappers, name), type)
        and issubclass(getattr(simoun_wrappers, name), gym.utils.RecordConstructorArgs)
        and "Vector" not in name
    }
    assert wrappers == set(CHAINS)


@pytest.mark.parametrize("name", list(CHAINS))
def test_the_recorded_arguments_are_the_constructors_own(name):
    env = CHAINS[name]()
    recorded = env.spec.additional_wrappers[-1].kwargs
    taken = inspect.signature(type(env).__init__).parameters
    assert set(recorded) <= set(taken) - {"self", "env"}, set(recorded) - set(taken)


@pytest.mark.parametrize("name", list(CHAINS))
def test_spec_rebuilds_an_equal_env(name):
    env = CHAINS[name]()
    rebuilt = gym.make(env.spec)
    assert rebuilt.spec.additional_wrappers[-1].name == env.spec.additional_wrappers[-1].name
    assert rebuilt.observation_space == env.observation_space
    env.action_space.seed(0)
    actions = [env.action_space.sample() for _ in range(3)]
    for a, b in [(env.reset(seed=2)[0], rebuilt.reset(seed=2)[0])] + [
        (env.step(action)[0], rebuilt.step(action)[0]) for action in actions
    ]:  # the observations; the rewards of the intrinsic-reward wrappers are checked below
        if isinstance(a, dict):
            assert a.keys() == b.keys()
            for key in a:
                np.testing.assert_array_equal(a[key], b[key])
        else:
            np.testing.assert_array_equal(a, b)


@pytest.mark.parametrize("name", ["ConstantBonusReward", "RNDReward", "ConsistencyCuriosityReward"])
def test_a_rebuilt_intrinsic_reward_wrapper_pays_the_same_rewards(name):
    env = CHAINS[name]()
    rebuilt = gym.make(env.spec)
    env.reset(seed=0)
    rebuilt.reset(seed=0)
    for action in (0, 1, 1):
        ours, theirs = env.step(action), rebuilt.step(action)
        assert ours[1] == theirs[1]
        assert ours[4]["reward_intrinsic"] == theirs[4]["reward_intrinsic"]


NUMPY_CHAINS = {
    "FrameTriplet": lambda: FrameTriplet(gym.make("CartPole-v1"), num_frames=np.int64(4)),
    "ActionRepeat": lambda: ActionRepeat(gym.make("CartPole-v1"), repeat=np.uint8(3)),
    "RandomConvolution": lambda: SimounObservation(
        RandomConvolution(_cartpole(), np.int64(5)), size=np.int32(16)
    ),
    "MultiCamera": lambda: MultiCamera(
        gym.make("dm_control/cartpole-swingup-v0"), [np.int64(0)], size=(np.int64(12), 20)
    ),
    "SimounObservation": lambda: SimounObservation(
        _cartpole(), size=np.int64(12), grayscale=np.bool_(True), num_frames=np.int32(4)
    ),
    "ConstantBonusReward": lambda: ConstantBonusReward(
        _pixels(), np.float32(0.1), decay=np.float16(1e-3)
    ),
    "RNDReward": lambda: RNDReward(_pixels(), _novelty, scale=np.float32(0.3), warmup=np.int64(0)),
    "ColorShift": lambda: ColorShift(
        gym.make("dm_control/cartpole-swingup-v0", render_mode="rgb_array"), seed=np.int64(0)
    ),
}
"""wrappers given numpy scalars, which they take as the Python values they hold"""


@pytest.mark.parametrize("name", list(NUMPY_CHAINS))
def test_numpy_arguments_are_recorded_as_python_values(name):
    kwargs = NUMPY_CHAINS[name]().spec.additional_wrappers[-1].kwargs
    # a source is recorded by reference (SharedSource), never as JSON
    written = {key: value for key, value in kwargs.items() if key != "novelty"}
    assert json.loads(json.dumps(written)) == {
        key: list(value) if isinstance(value, tuple) else value for key, value in written.items()
    }


@pytest.mark.parametrize(
    "name",
    [
        "FrameTriplet",
        "ActionRepeat",
        "RandomConvolution",
        "SimounObservation",
        "ConstantBonusReward",
    ],
)
def test_a_spec_of_numpy_arguments_round_trips_through_json(name):
    # the dm_control ids' entry points are callables, which EnvSpec.to_json refuses
    env = NUMPY_CHAINS[name]()
    rebuilt = gym.make(EnvSpec.from_json(env.spec.to_json()))
    assert rebuilt.observation_space == env.observation_space
    rebuilt.reset(seed=0)
    rebuilt.step(rebuilt.action_space.sample())


@pytest.mark.parametrize(
    ("build", "words"),
    [
        (
            lambda: MultiCamera(_cartpole(), [lambda e: e.render()], size=16),
            ("MultiCamera's cameras=", "camera names or ids"),
        ),
        (  # a wrapper above keeps the check: the spec is deep-copied with its class
            lambda: SimounObservation(
                MultiCamera(_cartpole(), [lambda e: e.render()], size=16), size=None
            ),
            ("MultiCamera's cameras=",),
        ),
        (
            lambda: gym.wrappers.TimeLimit(RNDReward(_pixels(), _novelty), 10),
            ("RNDReward's novelty=<function _novelty", "RNDReward(env, novelty=...)"),
        ),
        (
            lambda: ConsistencyCuriosityReward(_pixels(), _features),
            ("ConsistencyCuriosityReward's features=<function _features",),
        ),
        (
            lambda: RNDReward(_pixels(), _novelty, normalization=ReturnStd()),
            (
                "RNDReward's novelty=",
                "RNDReward's normalization=ReturnStd(gamma=0.99)",
                "'return_std'",
            ),
        ),
    ],
)
def test_to_json_names_the_argument_json_cannot_hold(build, words):
    env = build()
    with pytest.raises(TypeError) as refused:
        env.spec.to_json()
    for word in words:
        assert word in str(refused.value)
    # in the same process the spec still re-makes the env
    gym.make(env.spec).reset(seed=0)


def _pixel_vector() -> gym.vector.VectorEnv:
    return gym.make_vec(
        "CartPole-v1",
        num_envs=2,
        vectorization_mode="sync",
        render_mode="rgb_array",
        wrappers=[partial(SimounObservation, size=16)],
    )


@pytest.mark.parametrize(
    "build",
    [
        lambda: ConstantBonusVectorReward(_pixel_vector(), 0.1),
        lambda: RNDVectorReward(_pixel_vector(), _novelty, normalization=ReturnStd()),
    ],
)
def test_a_vector_wrappers_to_json_names_the_make_vec_argument_json_cannot_hold(build):
    envs = build()
    with pytest.raises(TypeError) as refused:
        envs.spec.to_json()
    said = str(refused.value)
    assert "gym.make_vec's wrappers=[a partial]" in said
    assert "make the vector env without wrappers= to write its spec" in said
    # the vector env's own spec keeps its class; the spec still pickles and re-makes the env
    assert type(envs.env.spec) is EnvSpec and envs.spec == envs.env.spec
    pickled = pickle.loads(pickle.dumps(envs.spec))  # a new partial, equal in all else
    assert type(pickled) is type(envs.spec) and pickled.kwargs["num_envs"] == 2
    remade = gym.make_vec(envs.spec)
    assert remade.single_observation_space == envs.single_observation_space
    remade.close()
    envs.close()


def test_to_json_names_a_gym_make_argument_json_cannot_hold():
    made = gym.make("CartPole-v1", render_mode="rgb_array", sutton_barto_reward=np.True_)
    env = ConstantBonusReward(SimounObservation(made, size=16), 0.1)
    with pytest.raises(TypeError) as refused:
        env.spec.to_json()
    said = str(refused.value)
    assert "gym.make's sutton_barto_reward=np.True_" in said
    assert "pass sutton_barto_reward as a plain value to gym.make" in said
    assert pickle.loads(pickle.dumps(env.spec)) == env.spec


def test_a_checked_spec_equals_the_gymnasium_spec_it_writes():
    env = ConstantBonusReward(_pixels(), 0.1)
    assert env.spec == EnvSpec.from_json(env.spec.to_json())
    assert EnvSpec.from_json(env.spec.to_json()) == env.spec
