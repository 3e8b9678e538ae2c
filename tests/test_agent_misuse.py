"""SimounAgent and FrameReplay misuse: each a clear error
or the right result, on real environments."""

import dataclasses

import gymnasium as gym
import highway_env
import minigrid
import numpy as np
import pytest
import torch

import simoun_agent.envs  # noqa: F401  (registers simoun/PointReach-v0)
from simoun_agent import AgentConfig, FrameReplay, SimounAgent
from simoun_agent.curiosity_model import CuriosityModel
from simoun_agent.rnd_model import RNDModel
from simoun_wrappers import SimounObservation

gym.register_envs(highway_env)
gym.register_envs(minigrid)

SIZE = 32


def point_reach_replay(steps: int, seed: int = 0) -> FrameReplay:
    """A replay of PointReach frames taken with random actions."""
    env = SimounObservation(gym.make("simoun/PointReach-v0"), size=None, motion=False)
    replay = FrameReplay(capacity=50, frame_shape=(3, SIZE, SIZE), action_dim=2, seed=seed)
    obs, _ = env.reset(seed=seed)
    replay.start_episode(obs["frames"][-1])
    env.action_space.seed(seed)
    for _ in range(steps):
        action = env.action_space.sample()
        obs, reward, terminated, truncated, _ = env.step(action)
        replay.add(action, reward, obs["frames"][-1], terminated, truncated)
        if terminated or truncated:
            obs, _ = env.reset()
            replay.start_episode(obs["frames"][-1])
    return replay


def test_load_on_an_instance_fills_that_instance(tmp_path):
    saved = point_reach_replay(steps=30, seed=1)
    path = tmp_path / "replay.npz"
    saved.save(path)
    target = FrameReplay(capacity=50, frame_shape=(3, SIZE, SIZE), action_dim=2)
    assert len(target) == 0
    assert target.load(path) is target
    assert len(target) == len(saved) == 30
    fresh = FrameReplay.load(path)
    for _ in range(2):
        a, b, c = saved.sample(8), target.sample(8), fresh.sample(8)
        for key in a:
            np.testing.assert_array_equal(a[key], b[key])
            np.testing.assert_array_equal(a[key], c[key])


def test_load_into_a_buffer_of_another_shape_names_both(tmp_path):
    path = tmp_path / "replay.npz"
    point_reach_replay(steps=5).save(path)
    other = FrameReplay(capacity=50, frame_shape=(3, 48, 48), action_dim=2)
    with pytest.raises(
        ValueError,
        match=r"frame_shape \(3, 32, 32\) in the file, \(3, 48, 48\) here.*"
        r"FrameReplay\.load\(path\).*frame_shape=\(3, 32, 32\)",
    ):
        other.load(path)
    assert len(other) == 0
    smaller = FrameReplay(capacity=10, frame_shape=(3, SIZE, SIZE), action_dim=1)
    with pytest.raises(ValueError, match=r"capacity 50 in the file, 10 here; action_dim 2"):
        smaller.load(path)


def test_act_on_the_whole_observation_dict_says_pass_frames():
    env = SimounObservation(gym.make("simoun/PointReach-v0"), size=None)
    agent = SimounAgent((3, SIZE, SIZE), action_dim=2, config=AgentConfig(batch_size=8))
    obs, _ = env.reset(seed=0)
    with pytest.raises(ValueError, match=r"whole dict \(keys \['frames', 'motion'\]\).*"
                       r"agent\.act\(obs\['frames'\]\)"):  # fmt: skip
        agent.act(obs)
    assert agent.act(obs["frames"]).shape == (2,)


@pytest.mark.parametrize(
    "make", [lambda: gym.make("highway-fast-v0"), lambda: gym.make("MiniGrid-Empty-5x5-v0")]
)
def test_discrete_action_space_is_refused_with_what_to_do(make):
    space = make().action_space
    assert isinstance(space, gym.spaces.Discrete)
    with pytest.raises(ValueError, match=r"continuous actions \(a 1-D Box\).*ContinuousAction.*"
                       r"fold_frames=True"):  # fmt: skip
        SimounAgent((3, 48, 48), action_dim=space)


SMALL = AgentConfig(batch_size=8, num_filters=4, feature_dim=8, hidden_dim=16, aux_hidden_dim=16)


@pytest.mark.parametrize(
    ("build", "error", "said"),
    [
        (lambda: SimounAgent((3, SIZE, SIZE), 1, {"lr": 1e-3}), TypeError, "config must be an"),
        (lambda: SimounAgent((3, SIZE, SIZE), 1, AgentConfig), TypeError, "config must be an"),
        (lambda: SimounAgent(None, 1, SMALL), ValueError, "frame_shape must be (C, H, W)"),
        (lambda: SimounAgent((3, SIZE, SIZE), 1, SMALL, "tpu"), ValueError, "device 'tpu': "),
        (lambda: SimounAgent((3, SIZE, SIZE), 1, SMALL, 3), TypeError, "device must be a str"),
        (lambda: FrameReplay(10.5, (3, SIZE, SIZE), 1), ValueError, "capacity must be an int"),
        (lambda: FrameReplay("100", (3, SIZE, SIZE), 1), ValueError, "capacity must be an int"),
        (lambda: FrameReplay(100, (3, SIZE, SIZE), 0), ValueError, "action_dim must be an int"),
        (lambda: FrameReplay(100, None, 1), ValueError, "frame_shape must be (C, H, W)"),
        (lambda: FrameReplay(100, (3, SIZE, SIZE), 1, seed=-1), ValueError, "seed must be None"),
        (lambda: FrameReplay(100, np.zeros((3, 1)), 1), ValueError, "frame_shape must be (C, H"),
        (
            lambda: FrameReplay(10**12, (3, SIZE, SIZE), 1),
            ValueError,
            "FrameReplay(capacity=1000000000000) needs 3,144,660,000,009,249 bytes",
        ),
    ],
)
def test_agent_and_replay_arguments_are_named(build, error, said):
    with pytest.raises(error) as raised:
        build()
    assert said in str(raised.value)


def test_a_replay_of_other_frames_or_a_word_for_a_reward_is_named():
    agent = SimounAgent((3, SIZE, SIZE), action_dim=2, config=SMALL, device="cpu")
    other = FrameReplay(capacity=50, frame_shape=(3, 16, 16), action_dim=2)
    with pytest.raises(ValueError, match=r"replay holds frames \(3, 16, 16\).*FrameReplay\("):
        agent.update(other, 0)
    replay = point_reach_replay(steps=10)
    assert set(agent.update(replay, 10)) >= {"critic_loss"}
    with pytest.raises(ValueError, match="reward must be a number, got str 'a'"):
        replay.add(np.zeros(2), "a", np.zeros((3, SIZE, SIZE), np.uint8), False, False)


@pytest.mark.parametrize("flag", ["no", 0, 1, None, np.array([True])])
def test_a_bool_argument_that_is_not_a_bool_is_named(flag):
    agent = SimounAgent((3, SIZE, SIZE), action_dim=2, config=SMALL, device="cpu")
    env = SimounObservation(gym.make("simoun/PointReach-v0"), size=None)
    obs, _ = env.reset(seed=0)
    with pytest.raises(TypeError, match=r"act\(deterministic=\.\.\.\) must be True or False"):
        agent.act(obs["frames"], deterministic=flag)
    assert agent.act(obs["frames"], deterministic=np.bool_(True)).shape == (2,)
    replay = point_reach_replay(steps=2)
    frame = obs["frames"][-1]
    for name in ("terminated", "truncated"):
        flags = {"terminated": False, "truncated": False, name: flag}
        with pytest.raises(TypeError, match=rf"add\({name}=\.\.\.\) must be True or False"):
            replay.add(np.zeros(2), 0.0, frame, **flags)
    assert replay.episode_step == 2  # nothing stored, the episode still open
    replay.add(np.zeros(2), 0.0, frame, np.bool_(False), False)
    assert replay.episode_step == 3


@pytest.mark.parametrize(
    ("kwargs", "said"),
    [
        ({"size": 0}, "size must be a positive int, got 0"),
        ({"size": -3}, "size must be a positive int, got -3"),
        ({"size": 2.5}, "size must be a positive int, got 2.5"),
        ({"max_steps": 0}, "max_steps must be a positive int, got 0"),
        ({"max_steps": True}, "max_steps must be a positive int, got True"),
        ({"step_size": float("nan")}, "step_size must be a finite number > 0, got nan"),
        ({"step_size": -0.2}, "step_size must be a finite number > 0, got -0.2"),
        ({"step_size": "0.2"}, "step_size must be a finite number > 0, got '0.2'"),
    ],
)
def test_point_reach_names_a_bad_constructor_argument(kwargs, said):
    with pytest.raises(ValueError, match=r"; pass .*, e\.g\. ") as raised:
        gym.make("simoun/PointReach-v0", **kwargs)
    assert said in str(raised.value)


def intrinsic_model(model, action_space):
    """``model`` (an intrinsic-reward model class) built for PointReach frames of 48x48 (RND's
    convolutions need 36 or more)."""
    env = SimounObservation(gym.make("simoun/PointReach-v0", size=48), size=None)
    env.action_space = action_space
    return model.for_env(env, device="cpu")


TRIPLETS = np.zeros((4, 3, 3, 48, 48), np.uint8)
NO = np.zeros(4, bool)


@pytest.mark.parametrize("model", [RNDModel, CuriosityModel])
@pytest.mark.parametrize(
    ("call", "said"),
    [
        (lambda m: m(TRIPLETS[0]), "expects triplets as uint8 (B, 3, 3, 48, 48), got uint8 (3, 3"),
        (lambda m: m(TRIPLETS.astype(np.float32)), "triplets as uint8 (B, 3, 3, 48, 48), got fl"),
        (lambda m: m.watch(TRIPLETS, np.zeros((4, 2)), TRIPLETS[:, :2], NO, NO),
         "expects next_triplets as uint8 (B, 3, 3, 48, 48)"),
        (lambda m: m.watch(TRIPLETS, np.zeros((4, 2)), TRIPLETS[:2], NO, NO),
         "got 4 triplets and 2 next_triplets"),
        (lambda m: m.watch(TRIPLETS[:0], np.zeros((0, 2)), TRIPLETS[:0], NO[:0], NO[:0]),
         "watch() needs one or more transitions"),
        (lambda m: m.watch(TRIPLETS, np.zeros((4, 3)), TRIPLETS, NO, NO),
         "expects actions of shape (4, 2) in Box(-1.0, 1.0, (2,), float32), one per transition, "
         "got shape (4, 3)"),
        (lambda m: m.watch(TRIPLETS, np.zeros(2), TRIPLETS, NO, NO), "got shape (2,)"),
        (lambda m: m.watch(TRIPLETS, np.full((4, 2), np.nan), TRIPLETS, NO, NO),
         "actions of shape (4, 2) in Box(-1.0, 1.0, (2,), float32), one per transition, got a NaN"),
        (lambda m: m.watch(TRIPLETS, None, TRIPLETS, NO, NO), "got object values, not numbers"),
        (lambda m: m.watch(TRIPLETS, np.zeros((4, 2)), TRIPLETS, NO[:3], NO),
         "expects terminated of shape (4,), one flag per transition, got shape (3,)"),
    ],
)  # fmt: skip
def test_intrinsic_models_name_a_bad_frame_or_action_argument(model, call, said):
    built = intrinsic_model(model, gym.spaces.Box(-1.0, 1.0, (2,), np.float32))
    with pytest.raises(ValueError) as raised:
        call(built)
    assert said in str(raised.value)
    assert built.size == 0  # nothing stored
    built.watch(TRIPLETS, np.zeros((4, 2)), TRIPLETS, NO, NO)
    assert built.size == 4


@pytest.mark.parametrize(
    ("actions", "said"), [([0, 1, 2, 3], "outside the space"), ([0, 1, 0.5, 1], "fractional")]
)
def test_discrete_actions_outside_the_space_are_named(actions, said):
    built = intrinsic_model(CuriosityModel, gym.spaces.Discrete(3))
    with pytest.raises(ValueError, match=rf"actions of shape \(4,\) in Discrete\(3\).*{said}"):
        built.watch(TRIPLETS, np.array(actions), TRIPLETS, NO, NO)
    built.watch(TRIPLETS, np.array([0, 1, 2, 1]), TRIPLETS, NO, NO)
    assert built.size == 4


@pytest.mark.parametrize("step", [-1, "a", 1.5, True, None])
def test_a_step_that_is_not_an_int_of_zero_or_more_is_named(step):
    agent = SimounAgent((3, SIZE, SIZE), action_dim=2, config=SMALL, device="cpu")
    replay = point_reach_replay(steps=10)
    frames = np.zeros((3, 3, SIZE, SIZE), np.uint8)
    calls = [
        ("act", lambda: agent.act(frames, step=step)),
        ("update", lambda: agent.update(replay, step)),
        ("update_actor", lambda: agent.update_actor(torch.zeros(2, agent.encoder.repr_dim), step)),
    ]
    for name, call in calls:
        if step is None and name != "update_actor":
            continue
        if step is None:
            call()  # None: the step of the latest update
            continue
        with pytest.raises(ValueError, match=rf"{name}\(step=\.\.\.\) must be an int >= 0, got"):
            call()
    assert agent.num_updates == 0  # nothing learned from a refused step
    assert agent.act(frames, step=np.int64(3)).shape == (2,)
    agent.update(replay, np.int64(10))
    assert agent.env_step == 10 and type(agent.env_step) is int


def test_a_step_beyond_an_int64_is_named():
    agent = SimounAgent((3, SIZE, SIZE), action_dim=2, config=SMALL, device="cpu")
    replay = point_reach_replay(steps=10)
    for name, call in (
        ("update", lambda: agent.update(replay, 2**70)),
        ("act", lambda: agent.act(np.zeros((3, 3, SIZE, SIZE), np.uint8), step=2**63)),
    ):
        with pytest.raises(ValueError, match=rf"{name}\(step=\.\.\.\) must be below 2\*\*63, got"):
            call()
    assert agent.num_updates == 0
    agent.update(replay, 2**63 - 1)
    assert agent.env_step == 2**63 - 1


@pytest.mark.parametrize("frames", [np.zeros((3, 3, SIZE, SIZE), np.uint8).tolist(), None, 7])
def test_an_observation_that_is_no_array_is_named_with_the_array_it_must_be(frames):
    agent = SimounAgent((3, SIZE, SIZE), action_dim=2, config=SMALL, device="cpu")
    with pytest.raises(TypeError, match=r"act\(frames\) must be a uint8 numpy array \(or torch "
                       r"tensor\) of shape \(3, 3, 32, 32\)"):  # fmt: skip
        agent.act(frames)
    with pytest.raises(TypeError, match=r"encoder_features\(triplets\) must be a uint8 numpy "
                       r"array \(or torch tensor\) of shape \(B, 3, 3, 32, 32\)"):  # fmt: skip
        agent.encoder_features([frames])
    assert agent.act(torch.zeros((3, 3, SIZE, SIZE), dtype=torch.uint8)).shape == (2,)


def test_a_state_of_another_agent_or_none_is_named_before_anything_loads():
    agent = SimounAgent((3, SIZE, SIZE), action_dim=2, config=SMALL, device="cpu")
    before = {k: v.clone() for k, v in agent.encoder.state_dict().items()}
    with pytest.raises(ValueError, match=r"does not fit this agent: it lacks encoder, "
                       r"encoder_target, .*same config"):  # fmt: skip
        agent.load_state_dict({})
    with pytest.raises(TypeError, match=r"state must be the dict SimounAgent\.state_dict"):
        agent.load_state_dict(None)
    wider = SimounAgent((3, SIZE, SIZE), 2, dataclasses.replace(SMALL, num_filters=8), "cpu")
    state = wider.state_dict()
    with pytest.raises(ValueError) as raised:
        agent.load_state_dict(state)
    message = str(raised.value)
    assert "encoder.appearance.0.weight is (8, 3, 3, 3) there, (4, 3, 3, 3) here" in message
    assert "(the state's config differs: num_filters 8 there, 4 here)" in message
    assert "must come from SimounAgent.state_dict() of an agent of the same config" in message
    for key, value in agent.encoder.state_dict().items():
        assert torch.equal(value, before[key]), key  # nothing loaded
    other_actions = SimounAgent((3, SIZE, SIZE), 3, SMALL, "cpu").state_dict()
    with pytest.raises(ValueError, match=r"critic\.q1\.0\.weight is \(16, 19\) there, "
                       r"\(16, 18\) here; .*; \d+ more\. The state must"):  # fmt: skip
        agent.load_state_dict(other_actions)
    agent.load_state_dict(SimounAgent((3, SIZE, SIZE), 2, SMALL, "cpu").state_dict())


def test_a_shape_read_off_a_space_is_taken_as_the_frame_shape():
    for shape in (np.array([3, SIZE, SIZE]), tuple(np.array([3, SIZE, SIZE]))):
        replay = FrameReplay(100, shape, np.int64(1), seed=np.int64(3))
        assert replay.frame_shape == (3, SIZE, SIZE) and type(replay.frame_shape[0]) is int


def test_a_capacity_beyond_the_memory_names_the_bytes_and_a_capacity_that_fits():
    with pytest.raises(ValueError) as raised:
        FrameReplay(10**12, (3, SIZE, SIZE), 1)
    message = str(raised.value)
    assert "more than this machine's" in message and "GB of memory; lower capacity" in message
    fits = int(message.split("(about ")[1].split(" transitions")[0].replace(",", ""))
    assert FrameReplay(fits // 1000, (3, SIZE, SIZE), 1).capacity == fits // 1000


def test_saving_a_replay_to_no_path_a_directory_or_a_missing_folder_is_named(tmp_path):
    replay = point_reach_replay(steps=5)
    with pytest.raises(TypeError, match=r"FrameReplay\.save\(path\) takes a file path .* got "
                       r"NoneType None; e\.g\. replay\.save\('replay\.npz'\)"):  # fmt: skip
        replay.save(None)
    with pytest.raises(ValueError, match=rf"{tmp_path} is a directory; pass a file path in it, "
                       rf"e\.g\. replay\.save\('{tmp_path}/replay\.npz'\)"):  # fmt: skip
        replay.save(tmp_path)
    with pytest.raises(FileNotFoundError, match=r"the folder .*nope of .* does not exist"):
        replay.save(tmp_path / "nope" / "replay.npz")
    with pytest.raises(TypeError, match=r"FrameReplay\.load\(path\) takes a file path"):
        FrameReplay.load(None)
    assert list(tmp_path.iterdir()) == []
    replay.save(tmp_path / "replay.npz")
    assert len(FrameReplay.load(tmp_path / "replay.npz")) == len(replay)


def spoilt_states(state: dict) -> list[tuple[str, object, str]]:
    """An agent's state with one part spoilt: (key, value, what the refusal must say)."""
    critic = state["critic"]
    first = next(iter(state["critic_optimizer"]["state"]))
    slots = state["critic_optimizer"]["state"][first]
    return [
        ("num_updates", "x", "its num_updates is 'x', not an int >= 0"),
        ("env_step", -1, "its env_step is -1, not an int >= 0"),
        ("critic", {k: v.numpy() for k, v in critic.items()}, "critic.q1.0.weight is a numpy"),
        ("critic", {**critic, "extra": torch.zeros(1)}, "its critic holds extra, which this"),
        ("critic_optimizer", {}, "its critic_optimizer lacks state, param_groups"),
        (
            "critic_optimizer",
            {**state["critic_optimizer"], "state": {first: {**slots, "exp_avg": torch.zeros(2)}}},
            f"its critic_optimizer state of parameter {first!r}: exp_avg is (2,) there",
        ),
        (
            "actor_optimizer",
            {**state["actor_optimizer"], "param_groups": [{"params": []}]},
            "its actor_optimizer parameter group 0 holds 0 parameters",
        ),
        (
            "running_max",
            None,
            "its running_max: it is a NoneType, not a dict of r_e_max and r_i_max",
        ),
        ("running_max", {"r_e_max": 1.0}, "its running_max: it lacks r_i_max"),
        ("running_max", {"r_e_max": 1.0, "r_i_max": 0}, "its running_max: its r_i_max is 0, not a"),
        ("log_alpha", 0.1, "its log_alpha is a float, not a torch tensor"),
    ]


def test_a_state_with_a_spoilt_part_is_refused_whole_naming_it_and_nothing_loads():
    agent = SimounAgent((3, SIZE, SIZE), action_dim=2, config=SMALL, device="cpu")
    before = {k: v.clone() for k, v in agent.critic.state_dict().items()}
    trained = SimounAgent((3, SIZE, SIZE), 2, SMALL, "cpu")
    trained.update(point_reach_replay(steps=20), 20)  # fills the optimizers' states
    state = trained.state_dict()
    state["num_updates"] = 7
    for key, value, said in spoilt_states(state):
        with pytest.raises(ValueError) as raised:
            agent.load_state_dict({**state, key: value})
        assert said in str(raised.value), (key, str(raised.value))
        assert str(raised.value).endswith("Nothing was loaded")
        assert agent.num_updates == 0
        for name, tensor in agent.critic.state_dict().items():
            assert torch.equal(tensor, before[name]), name
    agent.load_state_dict(state)
    assert agent.num_updates == 7


def small_agent_config() -> AgentConfig:
    return AgentConfig(batch_size=8, num_filters=4, feature_dim=8, hidden_dim=16, aux_hidden_dim=16)


@pytest.mark.parametrize(
    ("field", "value", "said"),
    [
        ("lr", -1, "--agent.lr -1 (AgentConfig.lr) must be a number > 0"),
        ("discount", 1.5, "(AgentConfig.discount) must be a number in [0, 1) (gamma)"),
        ("batch_size", 2.5, "(AgentConfig.batch_size) must be an int >= 1"),
        ("encoder", "single", "(AgentConfig.curiosity): curiosity (Eq. 13) compares"),
    ],
)
def test_an_agent_config_changed_after_it_was_built_is_checked_again_by_the_agent(
    field, value, said
):
    config = small_agent_config()
    setattr(config, field, value)
    with pytest.raises(ValueError) as error:
        SimounAgent((3, SIZE, SIZE), 1, config, device="cpu")
    assert str(error.value).startswith("SimounAgent cannot use this config: ")
    assert said in str(error.value)


@pytest.mark.parametrize(
    ("model", "field", "value", "said"),
    [
        (CuriosityModel, "lr", -1.0, "CuriosityConfig.lr=-1.0 must be a number > 0"),
        (CuriosityModel, "batch_size", 1, "CuriosityConfig.batch_size=1 must be an int >= 2"),
        (RNDModel, "seed", -1, "RNDConfig.seed=-1 must be None or an int in [0, 2**32)"),
        (RNDModel, "learning_starts", 10**6, "needs batch_size <= learning_starts <= capacity"),
    ],
)
def test_an_online_model_config_changed_after_it_was_built_is_checked_again(
    model, field, value, said
):
    config = model.config_type()
    setattr(config, field, value)
    env = SimounObservation(gym.make("simoun/PointReach-v0", size=48), size=None)
    with pytest.raises(ValueError) as error:
        model.for_env(env, config, device="cpu")
    assert str(error.value).startswith(f"{model.__name__} cannot use this config: ")
    assert said in str(error.value)


@pytest.mark.parametrize(
    "move", [lambda a: a.to("meta"), lambda a: a.to(torch.device("meta")), lambda a: a.cuda()]
)
def test_moving_an_agent_like_a_torch_module_says_how_to_move_it(move):
    agent = SimounAgent((3, SIZE, SIZE), 1, small_agent_config(), device="cpu")
    with pytest.raises(TypeError) as error:
        move(agent)
    said = str(error.value)
    assert "device is chosen when it is built" in said and "this one is on cpu" in said
    assert "load_state_dict(agent.state_dict())" in said


def test_an_agent_moves_by_a_new_agent_and_its_state_as_the_error_says():
    agent = SimounAgent((3, SIZE, SIZE), 1, small_agent_config(), device="cpu")
    moved = SimounAgent((3, SIZE, SIZE), 1, small_agent_config(), device=torch.device("cpu"))
    moved.load_state_dict(agent.state_dict())
    frames = np.zeros((3, 3, SIZE, SIZE), np.uint8)
    np.testing.assert_array_equal(
        agent.act(frames, deterministic=True), moved.act(frames, deterministic=True)
    )


@pytest.mark.parametrize(
    "move", [lambda a: a.cpu(), lambda a: a.to("cpu"), lambda a: a.to("cpu:0")]
)
def test_moving_an_agent_to_the_device_it_is_on_returns_it(move):
    agent = SimounAgent((3, SIZE, SIZE), 1, small_agent_config(), device="cpu")
    assert move(agent) is agent


def window_batch(size=8, frames=4, action_dim=1):
    """What FrameReplay.sample gives update_window for a triplet agent of SIZE frames."""
    return (
        torch.zeros((size, frames, 3, SIZE, SIZE), dtype=torch.uint8),
        torch.zeros(size, action_dim),
        torch.zeros(size),
        torch.ones(size),
    )


@pytest.mark.parametrize(
    ("change", "error", "said"),
    [
        (lambda b: (b[0].numpy(), *b[1:]), TypeError, "window=...) must be a torch tensor"),
        (lambda b: (b[0].float(), *b[1:]), TypeError, "window=...) must be uint8"),
        (
            lambda b: (b[0], torch.zeros(8, 2), *b[2:]),
            ValueError,
            "action=...) must have shape (8, 1)",
        ),
        (
            lambda b: (b[0], b[1], torch.zeros(8, 1), b[3]),
            ValueError,
            "reward=...) must have shape (8,)",
        ),
        (lambda b: (b[0][:4], *b[1:]), ValueError, "action=...) must have shape (4, 1)"),
        (lambda b: (b[0], b[1].long(), *b[2:]), TypeError, "action=...) must be float"),
        (
            lambda b: (b[0].permute(0, 1, 3, 4, 2).contiguous(), *b[1:]),
            ValueError,
            "window=...) must be uint8 (B, frames, 3, 32, 32)",
        ),
    ],
)
def test_update_window_names_the_argument_its_shape_and_dtype(change, error, said):
    agent = SimounAgent((3, SIZE, SIZE), 1, small_agent_config(), device="cpu")
    batch = window_batch()
    agent.update_window(*batch, 0)
    with pytest.raises(error) as raised:
        agent.update_window(*change(batch), 0)
    assert said in str(raised.value)


def test_update_with_a_replay_of_another_frame_count_names_num_frames():
    agent = SimounAgent((3, SIZE, SIZE), 1, small_agent_config(), device="cpu")
    replay = FrameReplay(100, (3, SIZE, SIZE), 1, num_frames=2)
    with pytest.raises(ValueError, match=r"replay has num_frames=2.*num_frames=3\)"):
        agent.update(replay, 0)


@pytest.mark.parametrize(
    ("config", "shape", "error", "said"),
    [
        (AgentConfig(), (SIZE, SIZE, 3), ValueError, "looks channel-last"),
        (AgentConfig(), (3, 8, 8), ValueError, "too small for the conv trunk"),
        ({"encoder": "dual"}, (3, SIZE, SIZE), TypeError, "make_encoder(config=...) must be an"),
    ],
)
def test_make_encoder_refuses_what_the_agent_refuses(config, shape, error, said):
    from simoun_agent import make_encoder

    with pytest.raises(error) as raised:
        make_encoder(config, shape)
    assert said in str(raised.value)
