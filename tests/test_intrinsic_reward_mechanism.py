"""The reward-wrapper mechanism both intrinsic signals share (simoun_wrappers.intrinsic_reward):
the reward's sum, what a learning source is handed, resets with options and masks, the errors
before a reset, close, and the triplet layouts it reads. Real envs (CartPole's pixels)."""

import gymnasium as gym
import numpy as np
import pytest
from gymnasium import spaces
from gymnasium.vector import AutoresetMode, SyncVectorEnv

from simoun_wrappers import SimounObservation
from simoun_wrappers.curiosity_reward import (
    ConsistencyCuriosityReward,
    ConsistencyCuriosityVectorReward,
)
from simoun_wrappers.intrinsic_normalization import Normalization, Raw, ReturnStd
from simoun_wrappers.intrinsic_reward import (
    ConstantBonusReward,
    ConstantBonusVectorReward,
    triplet_shape,
)
from simoun_wrappers.rnd import RNDReward, RNDVectorReward


class Recorder:
    """A novelty source by hand (0.5 + the newest frame's mean pixel value / 255) that records
    every transition it is handed and whether it was closed."""

    def __init__(self):
        self.watched = []
        self.closed = 0

    def __call__(self, triplets):
        return 0.5 + triplets[:, -1].reshape(len(triplets), -1).mean(axis=1) / 255.0

    def watch(self, triplets, actions, next_triplets, terminated, truncated):
        names = ("start", "actions", "end", "terminated", "truncated")
        values = (triplets, actions, next_triplets, terminated, truncated)
        self.watched.append({name: np.array(v) for name, v in zip(names, values, strict=True)})

    def close(self):
        self.closed += 1


def cartpole() -> gym.Env:
    return SimounObservation(gym.make("CartPole-v1", render_mode="rgb_array"), size=16)


def vector(mode: AutoresetMode, n: int = 2) -> SyncVectorEnv:
    return SyncVectorEnv([cartpole for _ in range(n)], autoreset_mode=mode)


@pytest.mark.parametrize("mode", [AutoresetMode.NEXT_STEP, AutoresetMode.SAME_STEP])
def test_the_vector_reward_is_the_extrinsic_plus_the_scaled_intrinsic(mode):
    envs = RNDVectorReward(vector(mode), Recorder(), scale=0.5, warmup=0, normalization="none")
    envs.reset(seed=[0, 1])
    for t in range(4):
        _, rewards, _, _, info = envs.step(np.array([t % 2, 1 - t % 2]))
        np.testing.assert_array_equal(info["reward_extrinsic"], [1.0, 1.0])  # CartPole's
        assert np.all(info["reward_intrinsic"] > 0)
        np.testing.assert_array_equal(rewards, info["reward_extrinsic"] + info["reward_intrinsic"])
        for key in ("_reward_extrinsic", "_reward_intrinsic"):  # Gymnasium's vector-info masks
            assert info[key].dtype == np.bool_ and info[key].all()
    envs.close()


def test_the_single_reward_is_the_extrinsic_plus_the_scaled_intrinsic():
    env = RNDReward(cartpole(), Recorder(), scale=0.5, warmup=0, normalization="none")
    env.reset(seed=0)
    _, reward, *_, info = env.step(0)
    assert info["reward_extrinsic"] == 1.0 and info["reward_intrinsic"] > 0
    assert reward == info["reward_extrinsic"] + info["reward_intrinsic"]


def test_the_source_is_handed_each_transition_with_its_flags():
    source = Recorder()
    env = RNDReward(cartpole(), source, warmup=0)
    obs, _ = env.reset(seed=0)
    terminated, steps = False, 0
    while not terminated:  # always pushing left ends the episode in a few steps
        start = obs["frames"]
        obs, _, terminated, truncated, _ = env.step(0)
        steps += 1
        watched = source.watched[-1]
        np.testing.assert_array_equal(watched["start"], start[None])
        np.testing.assert_array_equal(watched["end"], obs["frames"][None])
        np.testing.assert_array_equal(watched["actions"], [0])
        np.testing.assert_array_equal(watched["terminated"], [terminated])
        np.testing.assert_array_equal(watched["truncated"], [truncated])
    assert len(source.watched) == steps > 1


def test_the_vector_source_gets_the_flags_of_the_sub_envs_it_scores():
    source = Recorder()
    envs = RNDVectorReward(vector(AutoresetMode.NEXT_STEP), source, warmup=0)
    envs.reset(seed=[0, 1])
    active, ends = np.ones(2, dtype=bool), 0
    for t in range(40):
        calls = len(source.watched)
        actions = np.array([0, t % 2])  # sub-env 0 falls first, then both again and again
        _, _, terminated, truncated, _ = envs.step(actions)
        assert len(source.watched) == calls + active.any()
        if active.any():  # the sub-envs not resetting this step, and their flags
            watched = source.watched[-1]
            np.testing.assert_array_equal(watched["actions"], actions[active])
            np.testing.assert_array_equal(watched["terminated"], terminated[active])
            np.testing.assert_array_equal(watched["truncated"], truncated[active])
        ends += int(terminated.sum())
        active = ~(terminated | truncated)
    assert ends >= 2
    envs.close()


def test_reset_hands_its_options_to_the_env():
    env = RNDReward(cartpole(), Recorder(), warmup=0)
    env.reset(seed=0, options={"low": 0.04, "high": 0.04})
    np.testing.assert_allclose(env.unwrapped.state, 0.04)


def test_a_masked_reset_renews_only_the_masked_sub_envs_triplets():
    source = Recorder()
    envs = RNDVectorReward(vector(AutoresetMode.DISABLED), source, warmup=0)
    envs.reset(seed=[0, 1])
    for _ in range(4):  # the poles lean visibly
        before, *_ = envs.step(np.array([0, 1]))
    after, _ = envs.reset(options={"reset_mask": np.array([True, False])})
    assert not np.array_equal(after["frames"][0], before["frames"][0])  # sub-env 0 starts afresh
    np.testing.assert_array_equal(after["frames"][1], before["frames"][1])  # sub-env 1 goes on
    envs.step(np.array([1, 0]))
    np.testing.assert_array_equal(source.watched[-1]["start"], after["frames"])
    envs.close()


def test_a_masked_reset_leaves_the_other_sub_envs_autoreset_step_unscored():
    source = Recorder()
    envs = RNDVectorReward(vector(AutoresetMode.NEXT_STEP), source, warmup=0, normalization="none")
    envs.reset(seed=[0, 1])
    terminated = np.zeros(2, dtype=bool)
    while not terminated[0]:  # sub-env 0 falls; sub-env 1, balanced by turns, does not yet
        _, _, terminated, _, _ = envs.step(np.array([0, int(len(source.watched) % 2)]))
    assert not terminated[1]
    envs.reset(options={"reset_mask": np.array([False, True])})
    _, _, _, _, info = envs.step(np.array([1, 1]))  # sub-env 0's autoreset step
    assert info["reward_intrinsic"][0] == 0.0 and info["reward_intrinsic"][1] > 0
    assert len(source.watched[-1]["actions"]) == 1  # only sub-env 1 was handed on
    envs.close()


def test_a_step_before_reset_is_refused_and_close_closes_the_source():
    for wrapped in (
        RNDReward(cartpole(), Recorder()),
        RNDVectorReward(vector(AutoresetMode.NEXT_STEP), Recorder()),
    ):
        action = wrapped.action_space.sample()
        with pytest.raises(gym.error.ResetNeeded, match="Call reset"):
            wrapped.step(action)
        source = wrapped.signal.source
        wrapped.close()
        assert source.closed == 1


def box(*shape: int) -> spaces.Box:
    return spaces.Box(0, 255, shape, np.uint8)


def test_the_triplet_layouts_read():
    assert triplet_shape(box(3, 1, 8, 8)) == (3, 1, 8, 8)  # grayscale, one frame a row
    assert triplet_shape(box(3, 3, 8, 8)) == (3, 3, 8, 8)
    assert triplet_shape(box(3, 8, 8)) == (3, 1, 8, 8)  # grayscale folded
    assert triplet_shape(box(9, 8, 8)) == (3, 3, 8, 8)  # RGB folded
    assert triplet_shape(spaces.Dict({"frames": box(3, 3, 8, 8)})) == (3, 3, 8, 8)
    for shape in ((6, 1, 8, 8), (4, 8, 8), (3, 8)):
        with pytest.raises(ValueError, match="triplet of frames"):
            triplet_shape(box(*shape))


class Features:
    """A feature source by hand: f_m the newest frame's mean, f_a zeros."""

    def __call__(self, triplets):
        newest = triplets[:, -1].reshape(len(triplets), -1).mean(axis=1, keepdims=True) / 255
        return newest.astype(np.float32), np.zeros((len(triplets), 3, 1), np.float32)


def test_the_consistency_wrapper_starts_from_its_maxima_and_defaults():
    env = ConsistencyCuriosityReward(cartpole(), Features(), r_e_max_init=3.0, r_i_max_init=2.0)
    assert env.state_dict() == {"scored": 0, "normalization": {"r_e_max": 3.0, "r_i_max": 2.0}}
    env = ConsistencyCuriosityReward(cartpole(), Features())
    assert env.scale == 0.2 and env.decay == 2e-5
    assert env.state_dict() == {"scored": 0, "normalization": {"r_e_max": 1.0, "r_i_max": 1.0}}


def test_scale_zero_logs_the_intrinsic_reward_without_adding_it():
    env = RNDReward(cartpole(), Recorder(), scale=0, warmup=0)
    env.reset(seed=0)
    _, reward, *_, info = env.step(0)
    assert reward == info["reward_extrinsic"] == 1.0 and info["reward_intrinsic"] == 0.0
    assert env.scored == 1  # the signal still ran


def test_the_errors_name_the_wrapper_and_the_source():
    with pytest.raises(TypeError, match=r"RNDReward wraps a single env.*put RNDReward in each"):
        RNDReward(vector(AutoresetMode.NEXT_STEP), Recorder())
    with pytest.raises(gym.error.ResetNeeded, match=r"before step\(\) on RNDVectorReward"):
        RNDVectorReward(vector(AutoresetMode.NEXT_STEP), Recorder()).step(np.array([0, 0]))
    with pytest.raises(TypeError, match=r"FeatureSource.*got int"):
        ConsistencyCuriosityReward(cartpole(), 42)

    class Diverged(Features):
        def __call__(self, triplets):
            f_m, f_a = super().__call__(triplets)
            return f_m * np.nan, f_a

    env = ConsistencyCuriosityReward(cartpole(), Diverged())
    env.reset(seed=0)
    with pytest.raises(ValueError, match="feature source Diverged returned NaN"):
        env.step(0)


def test_reset_hands_its_seeds_to_the_env():
    env = RNDReward(cartpole(), Recorder())
    with pytest.raises(gym.error.ResetNeeded, match=r"before step\(\) on RNDReward"):
        env.step(0)
    envs = RNDVectorReward(vector(AutoresetMode.NEXT_STEP), Recorder())
    plain = vector(AutoresetMode.NEXT_STEP)
    for seed in ([3, 4], [5, 6]):
        envs.reset(seed=seed)
        plain.reset(seed=seed)
        for wrapped, unwrapped in zip(envs.env.envs, plain.envs, strict=True):
            np.testing.assert_array_equal(wrapped.unwrapped.state, unwrapped.unwrapped.state)
    env.reset(seed=7)
    single = cartpole()
    single.reset(seed=7)
    np.testing.assert_array_equal(env.unwrapped.state, single.unwrapped.state)


def pendulum() -> gym.Env:
    return SimounObservation(gym.make("Pendulum-v1", render_mode="rgb_array"), size=16)


def intrinsic_wrappers():
    """Every intrinsic wrapper, single and vector, each stepped so its statistics are not the
    initial ones."""
    vec = SyncVectorEnv([pendulum, pendulum])
    return [
        ConsistencyCuriosityReward(pendulum(), Features()),
        RNDReward(pendulum(), Recorder(), normalization="return_std"),
        ConstantBonusReward(pendulum(), scale=0.1),
        RNDVectorReward(vec, Recorder(), normalization="standardize"),
        ConstantBonusVectorReward(SyncVectorEnv([pendulum]), scale=0.1),
    ]


def test_load_state_dict_refuses_a_state_that_does_not_fit_and_loads_nothing():
    for env in intrinsic_wrappers():
        name = type(env).__name__
        env.reset(seed=0)
        for _ in range(3):
            env.step(env.action_space.sample())
        before = env.state_dict()
        own = env.normalization.name
        other = "paper" if own != "paper" else "return_std"
        foreign = RNDReward(pendulum(), Recorder(), normalization=other).state_dict()
        wanted = f"state_dict\\(\\) of a {name} with normalization='{env.normalization.name}'"
        with pytest.raises(
            TypeError, match=f"got a NoneType, not a dict; the state must come from {wanted}"
        ):
            env.load_state_dict(None)
        with pytest.raises(TypeError, match="got a list"):
            env.load_state_dict([before])
        cases = {
            "it lacks 'scored'; it lacks 'normalization'": {},
            f"saved with normalization '{other}', but this wrapper's is '{own}'": foreign,
            "its scored is 'x', not an int >= 0": {**before, "scored": "x"},
            "its normalization statistics are a NoneType": {**before, "normalization": None},
        }
        if before["normalization"]:
            key = next(iter(before["normalization"]))
            damaged = {**before["normalization"], key: "nan"}
            cases[f"its {key} is 'nan', not a finite number"] = {**before, "normalization": damaged}
        for message, state in cases.items():
            with pytest.raises(ValueError, match=f"{message}.*{wanted}.*Nothing was loaded"):
                env.load_state_dict(state)
            assert env.state_dict() == before
        env.load_state_dict(before)
        assert env.state_dict() == before
        env.close()


def test_the_vector_wrappers_check_the_actions_and_seeds_of_their_sub_envs():
    envs = RNDVectorReward(vector(AutoresetMode.SAME_STEP), Recorder(), warmup=0)
    with pytest.raises(
        ValueError, match=r"seed=\[...\]\) takes one seed per sub-env, 2 here, got 3"
    ):
        envs.reset(seed=[0, 1, 2])
    with pytest.raises(ValueError, match=r"RNDVectorReward.reset\(seed=...\) takes None or an int"):
        envs.reset(seed=[0, True])
    envs.reset(seed=[np.int64(0), None])
    for wrong, said in [
        (np.zeros(1, np.int64), r"of shape \(1,\), not \(2,\)"),
        (np.array([0.5, 0.5]), "ndarray of dtype float64, not ints"),
    ]:
        with pytest.raises(ValueError, match=rf"MultiDiscrete\(\[2 2\]\): {said}.*one per sub-env"):
            envs.step(wrong)
    envs.step([0, 1])
    pendulums = ConstantBonusVectorReward(SyncVectorEnv([pendulum, pendulum]), scale=0.1)
    pendulums.reset(seed=0)
    with pytest.raises(ValueError, match=r"of shape \(2,\), not \(2, 1\)"):
        pendulums.step(np.zeros(2))
    pendulums.step(np.zeros((2, 1)))


def test_a_single_reward_wrapper_checks_the_action_and_the_seed():
    env = ConstantBonusReward(cartpole(), scale=0.1)
    with pytest.raises(ValueError, match=r"ConstantBonusReward.reset\(seed=...\)"):
        env.reset(seed=True)
    env.reset(seed=np.int64(0))
    with pytest.raises(ValueError, match=r"Discrete\(2\): float of dtype float64, not ints"):
        env.step(0.5)


@pytest.mark.parametrize(
    ("between", "fold_frames"),
    [(gym.wrappers.FlattenObservation, False), (gym.wrappers.NormalizeObservation, True)],
)
def test_a_gymnasium_wrapper_between_is_named_with_the_order_that_works(between, fold_frames):
    def pixels() -> gym.Env:
        pendulum = gym.make("Pendulum-v1", render_mode="rgb_array")
        return SimounObservation(pendulum, size=16, fold_frames=fold_frames)

    name = between.__name__
    with pytest.raises(
        TypeError,
        match=rf"but {name} over SimounObservation changed them.*Put {name} outside "
        rf"ConstantBonusReward: e.g. {name}\(ConstantBonusReward\(SimounObservation",
    ):
        ConstantBonusReward(between(pixels()), scale=0.1)
    right = between(ConstantBonusReward(pixels(), scale=0.1))
    right.reset(seed=0)
    right.step(right.action_space.sample())


class Returning(Normalization):
    """A user's own normalization that returns what it is told to (the raw batch's length
    given)."""

    name = "returning"

    def __init__(self, make):
        self.make = make

    def __call__(self, raw, extrinsic, envs, counted):
        return self.make(len(raw))

    def state_dict(self):
        return {}

    def restore(self, state):
        return None


def features(triplets):
    """f_m the newest frame's mean, f_a zeros."""
    newest = triplets[:, -1].reshape(len(triplets), -1).mean(axis=1, keepdims=True)
    return newest.astype(np.float32), np.zeros((len(triplets), 3, 1), np.float32)


WRAPPERS = {
    "rnd": lambda norm: RNDReward(cartpole(), Recorder(), warmup=0, normalization=norm),
    "consistency": lambda norm: ConsistencyCuriosityReward(
        cartpole(), features, normalization=norm
    ),
    "rnd vector": lambda norm: RNDVectorReward(
        vector(AutoresetMode.NEXT_STEP), Recorder(), warmup=0, normalization=norm
    ),
}


def first_step(env):
    env.reset(seed=0)
    return env.step(np.zeros(env.num_envs, np.int64) if hasattr(env, "num_envs") else 0)


@pytest.mark.parametrize("wrapper", WRAPPERS)
@pytest.mark.parametrize(
    ("make", "said"),
    [
        (lambda n: np.ones(n + 1), r"returned shape \(\d,\) for a batch of \d raw values"),
        (lambda n: None, r"returned None \(NoneType\)"),
        (lambda n: np.full(n, np.nan), "gave the non-finite reward nan .* at transition 0"),
        (lambda n: np.full(n, -np.inf), "gave the non-finite reward -inf"),
    ],
)
def test_a_normalization_s_output_is_checked_in_every_wrapper(wrapper, make, said):
    env = WRAPPERS[wrapper](Returning(make))
    with pytest.raises(ValueError, match=said) as error:
        first_step(env)
    assert "Returning()" in str(error.value)


@pytest.mark.parametrize("normalization", ["standardize", "reward_std", "paper", ReturnStd()])
def test_the_constant_bonus_refuses_a_normalization_and_says_why(normalization):
    for wrapper, env in ((ConstantBonusReward, cartpole()), (ConstantBonusVectorReward, None)):
        env = env if env is not None else vector(AutoresetMode.NEXT_STEP)
        with pytest.raises(ValueError) as error:
            wrapper(env, 0.1, normalization=normalization)
        said = str(error.value)
        assert f"{wrapper.__name__} takes no normalization" in said and "running std is 0" in said
        assert f"{wrapper.__name__}(env, scale=b)" in said and "RNDReward" in said


def test_the_constant_bonus_takes_none_by_name_or_instance_and_re_makes_from_its_spec():
    for normalization in ("none", Raw()):
        env = ConstantBonusReward(cartpole(), 0.1, normalization=normalization)
        env.reset(seed=0)
        assert env.step(0)[4]["reward_intrinsic"] == pytest.approx(0.1)
    again = gym.make(ConstantBonusReward(cartpole(), 0.1).spec)
    again.reset(seed=0)
    assert again.step(0)[4]["reward_intrinsic"] == pytest.approx(0.1)


def test_dict_info_to_list_under_a_vector_reward_is_named_with_the_order_that_works():
    listed = gym.wrappers.vector.DictInfoToList(vector(AutoresetMode.NEXT_STEP))
    with pytest.raises(TypeError, match=r"DictInfoToList\(ConstantBonusVectorReward\(envs, "):
        ConstantBonusVectorReward(listed, 0.1)
    outside = gym.wrappers.vector.DictInfoToList(
        ConstantBonusVectorReward(vector(AutoresetMode.NEXT_STEP), 0.1)
    )
    outside.reset(seed=0)
    _, _, _, _, infos = outside.step(outside.action_space.sample())
    assert isinstance(infos, list) and "reward_intrinsic" in infos[0]


def every_intrinsic_wrapper():
    """Each intrinsic wrapper class, single and vector, on Pendulum."""
    vec = lambda: SyncVectorEnv([pendulum, pendulum])  # noqa: E731
    return [
        ConsistencyCuriosityReward(pendulum(), Features()),
        ConsistencyCuriosityVectorReward(vec(), Features()),
        RNDReward(pendulum(), Recorder()),
        RNDVectorReward(vec(), Recorder()),
        ConstantBonusReward(pendulum(), scale=0.1),
        ConstantBonusVectorReward(vec(), scale=0.1),
    ]


@pytest.mark.parametrize("call", ["step", "reset"])
def test_a_reset_or_step_after_close_is_refused_by_every_intrinsic_wrapper(call):
    for env in every_intrinsic_wrapper():
        env.reset(seed=0)
        env.close()
        name = type(env).__name__
        with pytest.raises(ValueError, match=rf"Cannot call {name}\.{call}\(\) after close\(\)"):
            env.step(env.action_space.sample()) if call == "step" else env.reset(seed=0)
        with pytest.raises(gym.error.ClosedEnvironmentError):
            env.step(env.action_space.sample())


def test_a_stable_baselines3_vec_env_is_named_with_the_single_reward_inside_it():
    from stable_baselines3.common.vec_env import DummyVecEnv

    for vector_reward, single in [
        (ConstantBonusVectorReward, "ConstantBonusReward"),
        (RNDVectorReward, "RNDReward"),
    ]:
        args = (0.1,) if vector_reward is ConstantBonusVectorReward else (Recorder(),)
        with pytest.raises(TypeError) as raised:
            vector_reward(DummyVecEnv([pendulum]), *args)
        said = str(raised.value)
        assert "Stable-Baselines3's DummyVecEnv, which is not one" in said
        assert f"DummyVecEnv([lambda: {single}(SimounObservation(" in said
    # the fix it gives works
    from stable_baselines3.common.vec_env import DummyVecEnv

    fixed = DummyVecEnv(
        [
            lambda: ConstantBonusReward(
                SimounObservation(
                    gym.make("Pendulum-v1", render_mode="rgb_array"), size=16, fold_frames=True
                ),
                0.1,
            )
        ]
    )
    fixed.reset()
    fixed.step(np.zeros((1, 1), np.float32))


def test_a_source_class_is_refused_naming_for_env():
    from simoun_agent.curiosity_model import CuriosityModel
    from simoun_agent.rnd_model import RNDModel

    with pytest.raises(TypeError, match=r"got the class RNDModel itself; pass novelty=RNDModel"):
        RNDReward(pendulum(), RNDModel)
    with pytest.raises(TypeError, match=r"features=CuriosityModel\.for_env\(env\)"):
        ConsistencyCuriosityReward(pendulum(), CuriosityModel)
    with pytest.raises(TypeError, match=r"got the class Recorder itself; pass an instance"):
        RNDVectorReward(SyncVectorEnv([pendulum]), Recorder)


def test_an_error_inside_a_source_names_the_source_and_the_numpy_triplets():
    import torch

    net = torch.nn.Sequential(torch.nn.Flatten(), torch.nn.LazyLinear(1))
    env = RNDReward(pendulum(), lambda t: net(t).squeeze(-1), warmup=0)
    env.reset(seed=0)
    with pytest.raises(TypeError) as raised:
        env.step(env.action_space.sample())
    said = str(raised.value)
    assert "The novelty= source function" in said
    assert "a numpy uint8 array of shape (1, 3, 3, 16, 16) (B, 3, C, H, W)" in said
    assert isinstance(raised.value.__cause__, TypeError)
    # the call it suggests works
    fixed = RNDReward(
        pendulum(),
        lambda t: net(torch.as_tensor(t).float().flatten(1)).squeeze(-1).detach().numpy() ** 2,
        warmup=0,
    )
    fixed.reset(seed=0)
    fixed.step(fixed.action_space.sample())


def test_a_wrapper_below_that_changes_the_observations_but_not_their_space_is_named():
    def pixels(env: gym.Env) -> gym.Env:
        return SimounObservation(env, size=16)

    vector = gym.make_vec(
        "Pendulum-v1",
        2,
        vectorization_mode="sync",
        render_mode="rgb_array",
        vector_kwargs={"autoreset_mode": AutoresetMode.NEXT_STEP},
        wrappers=[pixels],
    )
    last_frame = gym.wrappers.vector.TransformObservation(
        vector, lambda obs: {"frames": obs["frames"][:, -1]}
    )  # keeps the triplet's space: nothing at construction can see the change
    env = ConstantBonusVectorReward(last_frame, 0.1)
    with pytest.raises(
        ValueError,
        match=r"ConstantBonusVectorReward got observations with frames of shape \(2, 3, 16, 16\), "
        r"but the observation_space below it gives frames of shape \(3, 3, 16, 16\) per "
        r"observation: TransformObservation under ConstantBonusVectorReward changed",
    ):
        env.reset(seed=0)
    single = gym.wrappers.TransformObservation(
        pixels(gym.make("Pendulum-v1", render_mode="rgb_array")),
        lambda obs: {"frames": obs["frames"][:2]},
        None,
    )
    wrapped = ConstantBonusReward(single, scale=0.1)
    with pytest.raises(ValueError, match=r"TransformObservation under ConstantBonusReward"):
        wrapped.reset(seed=0)
