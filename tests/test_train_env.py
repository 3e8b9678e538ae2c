"""Environment construction, video, logs and driving measures of simoun-train."""

import importlib.util

import gymnasium as gym
import imageio.v2 as imageio
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

from simoun_agent.config import SetupError, resolve
from simoun_agent.envs import POINT_REACH_ID, PointReach
from simoun_agent.run.driving_metrics import DrivingEpisode, summarize
from simoun_agent.run.env_packages import provider
from simoun_agent.run.highway_config import limit_of
from simoun_agent.run.logger import CsvLog, plot_learning_curve, read_csv
from simoun_agent.run.make_env import (
    check_env_kwargs,
    check_task,
    ensure_registered,
    episode_limit,
    make_env,
    video_fps,
)
from simoun_agent.run.video import write_video


class StateOnly(gym.Env):
    """A continuous-control env with vector observations and no rgb_array rendering."""

    metadata = {"render_modes": ["human"]}  # noqa: RUF012

    def __init__(self, render_mode=None):
        self.render_mode = render_mode
        self.observation_space = gym.spaces.Box(-1.0, 1.0, (4,), np.float32)
        self.action_space = gym.spaces.Box(-1.0, 1.0, (1,), np.float32)

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        return np.zeros(4, np.float32), {}

    def step(self, action):
        return np.zeros(4, np.float32), 0.0, False, False, {}


gym.register("simoun-test/StateOnly-v0", entry_point=StateOnly)


def test_point_reach_passes_the_env_checker_and_rewards_reaching():
    env = gym.make(POINT_REACH_ID).unwrapped
    check_env(env)
    returns = {}
    for name in ("random", "reach"):
        env.reset(seed=0)
        total, done = 0.0, False
        while not done:
            toward = np.clip(-env._position / env.step_size, -1, 1)
            action = env.action_space.sample() if name == "random" else toward
            _, reward, terminated, truncated, _ = env.step(action)
            total, done = total + reward, terminated or truncated
        returns[name] = total
    assert returns["reach"] > returns["random"] + 3


def test_stack_gives_triplets_and_unit_actions():
    env = make_env(resolve(None, {"env": "Pendulum-v1", "image_size": 32}))
    assert env.observation_space["frames"].shape == (3, 3, 32, 32)
    assert "motion" not in env.observation_space.spaces  # the agent computes motion itself
    assert np.all(env.action_space.low == -1) and np.all(env.action_space.high == 1)
    obs, _ = env.reset(seed=0)
    assert obs["frames"].dtype == np.uint8 and (obs["frames"][0] == obs["frames"][2]).all()
    env.step(np.array([1.0], np.float32))
    assert env.unwrapped.last_u == pytest.approx(2.0)  # [-1, 1] rescaled to Pendulum's [-2, 2]


def test_dm_control_video_fps_comes_from_the_control_timestep():
    config = resolve("cpu", {"env": "dm_control/cartpole-swingup-v0"})
    env = make_env(config)
    size = config.image_size
    assert env.observation_space["frames"].shape == (3, 3, size, size)
    # control timestep 0.01 s x action repeat 8 -> 12.5 decisions per second of sim time;
    # shimmy's render_fps would claim 10.
    assert video_fps(env, config.resolved_action_repeat()) == pytest.approx(12.5)


def test_unknown_env_id_suggests_close_matches():
    with pytest.raises(SetupError, match="did you mean dm_control/cartpole-swingup-v0"):
        make_env(resolve(None, {"env": "dm_control/cartpol-swingup-v0"}))
    with pytest.raises(SetupError, match="did you mean Pendulum-v1"):
        make_env(resolve(None, {"env": "Pendullum-v1"}))


@pytest.mark.filterwarnings("ignore:.*render_mode='rgb_array' that is not in the possible")
def test_env_without_pixels_or_rgb_array_is_refused():
    with pytest.raises(
        SetupError, match=r"gives no frames.*no rgb_array rendering.*no images either"
    ):
        make_env(resolve(None, {"env": "simoun-test/StateOnly-v0"}))


def test_discrete_actions_are_refused_with_the_fix():
    with pytest.raises(SetupError, match=r"continuous actions.*--preset highway"):
        make_env(resolve(None, {"env": "highway-v0"}))


def test_module_colon_id_imports_the_package_that_registers_it():
    # MiniGrid registers its ids when minigrid is imported; its actions are discrete, so the
    # env is made and then refused for that (and not for an unknown id), without a highway hint
    config = resolve(None, {"env": "minigrid:MiniGrid-DoorKey-6x6-v0"})
    with pytest.raises(SetupError) as error:
        make_env(config)
    assert "MiniGrid-DoorKey-6x6-v0 has action space Discrete(7)" in str(error.value)
    assert "continuous actions" in str(error.value) and "highway" not in str(error.value)


def test_a_missing_env_module_is_refused_with_the_pip_hint():
    config = resolve(None, {"env": "simoun_no_such_package:Thing-v0"})
    with pytest.raises(SetupError, match=r"'simoun_no_such_package' is not installed.*pip install"):
        make_env(config)
    with pytest.raises(SetupError, match=r"did not register it; did you mean MiniGrid-DoorKey-6x6"):
        make_env(resolve(None, {"env": "MiniGrid-DoorKy-6x6-v0", "env_module": "minigrid"}))


def test_unknown_env_kwargs_are_refused_naming_the_key_and_the_accepted_ones():
    config = resolve(None, {"env": POINT_REACH_ID, "env_kwargs": {"sise": 40}, "image_size": 32})
    with pytest.raises(SetupError) as error:
        make_env(config)
    assert str(error.value) == (
        f"--env-kwargs: {POINT_REACH_ID} takes no keyword 'sise' (did you mean 'size'?); it "
        "accepts: max_steps, size, step_size"
    )
    highway = resolve(None, {"env": "highway-fast-v0", "env_kwargs": {"foo": 1}})
    with pytest.raises(SetupError, match=r"highway-fast-v0 takes no keyword 'foo'; it accepts: "):
        make_env(highway)
    with pytest.raises(SetupError, match=r"--env-kwargs sets render_mode='human'.*drop it"):
        make_env(resolve(None, {"env": "Pendulum-v1", "env_kwargs": {"render_mode": "human"}}))
    accepted = resolve(None, {"env": POINT_REACH_ID, "env_kwargs": {"size": 40}, "image_size": 32})
    assert make_env(accepted).unwrapped.size == 40


def test_env_kwargs_passed_on_to_the_env_are_refused_when_it_rejects_them():
    # shimmy's dm_control creator takes **kwargs, so only making the env finds the bad key
    config = resolve("cpu", {"env_kwargs": {"foo": 1}})
    with pytest.raises(SetupError) as error:
        make_env(config)
    message = str(error.value)
    assert message.startswith('--env-kwargs {"foo": 1} does not fit dm_control/cartpole-swingup')
    assert "unexpected keyword argument 'foo'" in message and "task_kwargs" in message


def _drive(env, action, steps):
    episode = DrivingEpisode()
    env.reset(seed=3)
    episode.start(env)
    for _ in range(steps):
        _, reward, terminated, truncated, info = env.step(np.asarray(action, np.float32))
        episode.step(env, reward, info)
        if terminated or truncated:
            break
    return episode


def test_highway_preset_stack_and_driving_measures():
    config = resolve("highway", {})
    env = make_env(config)
    assert env.observation_space["frames"].shape == (3, 3, 84, 252)
    assert video_fps(env, config.resolved_action_repeat()) == pytest.approx(5.0)

    braking = _drive(env, [-1.0, 0.5], steps=5)
    speed_m_per_decision = braking.distance_m / len(braking.steer)
    assert 0.5 < speed_m_per_decision < 8  # under ~40 m/s at 5 decisions per second
    stats = summarize([braking])
    assert stats["brake_fraction"] > 0.5
    assert stats["mean_abs_steer"] == pytest.approx(0.5, abs=0.05)

    cruising = _drive(env, [0.0, 0.0], steps=5)
    assert summarize([cruising])["brake_fraction"] == 0.0
    crash = DrivingEpisode(crashed=True, crash_speed=20.0, steer=[0.0], brake=[0.0])
    both = summarize([cruising, crash])
    assert both["crash_rate"] == 0.5 and both["crash_speed"] == 20.0


def test_video_is_written_at_the_given_fps(tmp_path):
    frames = [np.full((3, 32, 32), i * 20, np.uint8) for i in range(6)]
    path = write_video(tmp_path / "video.mp4", frames, fps=12.5)
    reader = imageio.get_reader(path)
    assert reader.get_meta_data()["fps"] == pytest.approx(12.5)
    first = reader.get_data(0)
    assert first.shape[0] >= 256 and first.shape[0] == first.shape[1]
    assert list(tmp_path.iterdir()) == [path]  # no temporary file left behind


def test_csv_log_drops_rows_after_the_resumed_step_and_curve_is_drawn(tmp_path):
    log = CsvLog(tmp_path / "eval.csv")
    for step in (0, 100, 200):
        row = {"env_step": step, "return_mean": step / 10}
        log.write({**row, "return_min": step / 20, "return_max": step / 5})
    resumed = CsvLog(tmp_path / "eval.csv", resume_step=100)
    resumed.write({"env_step": 150, "return_mean": 1.0, "return_min": 0.0, "return_max": 2.0})
    assert [row["env_step"] for row in read_csv(tmp_path / "eval.csv")] == [0, 100, 150]
    plot_learning_curve(tmp_path / "eval.csv", tmp_path / "curve.png", "test")
    assert (tmp_path / "curve.png").read_bytes()[:4] == b"\x89PNG"


class ScaledReach(PointReach):
    """PointReach whose actions are multiplied by ``scale``, stored unchecked: a bad value shows
    only when the env steps."""

    def __init__(self, render_mode=None, scale=None):
        super().__init__(render_mode=render_mode)
        self.scale = 1.0 if scale is None else scale

    def step(self, action):
        return super().step(np.asarray(action) * self.scale)


gym.register("simoun-test/ScaledReach-v0", entry_point=ScaledReach)


def env_config(env, env_kwargs, **more):
    return resolve(None, {"env": env, "env_kwargs": env_kwargs, "image_size": 32, **more})


def test_gymnasium_make_keywords_in_env_kwargs_go_to_make_checked_by_value():
    assert check_task(env_config("Pendulum-v1", {"max_episode_steps": 10})) == 10
    dmc_limit = env_config(
        "dm_control/cartpole-swingup-v0", {"max_episode_steps": 7}, action_repeat=1
    )
    assert check_task(dmc_limit) == 7
    env = make_env(env_config("Pendulum-v1", {"max_episode_steps": 3, "disable_env_checker": True}))
    env.reset(seed=0)
    assert [env.step(env.action_space.sample())[3] for _ in range(3)] == [False, False, True]
    for bad in (0, -1, 2.5, "10", True):
        with pytest.raises(SetupError, match=r"max_episode_steps=.* must be a whole number of at"):
            check_task(env_config("Pendulum-v1", {"max_episode_steps": bad}))
    with pytest.raises(SetupError, match=r"disable_env_checker='yes' .* must be true or false"):
        check_task(env_config("Pendulum-v1", {"disable_env_checker": "yes"}))
    for setting in ("autoreset", "order_enforce", "apply_api_compatibility"):
        with pytest.raises(SetupError) as error:
            check_task(env_config("Pendulum-v1", {setting: True}))
        assert f"{setting!r} is a setting of Pendulum-v1's registration" in str(error.value)
        assert "takes no keyword" not in str(error.value)


def test_an_env_kwarg_the_env_fails_on_is_refused_naming_it_not_raised():
    with pytest.raises(SetupError, match=r"g='x' does not fit Pendulum-v1: its 'g' is a number"):
        make_env(env_config("Pendulum-v1", {"g": "x"}))
    with pytest.raises(SetupError, match=r"goal_velocity='x' does not fit MountainCarContinuous"):
        check_task(env_config("MountainCarContinuous-v0", {"goal_velocity": "x"}))
    time_limit = {"task_kwargs": {"time_limit": "x"}}
    with pytest.raises(SetupError) as error:
        make_env(env_config("dm_control/cartpole-swingup-v0", time_limit))
    assert str(error.value).startswith('--env-kwargs {"task_kwargs": {"time_limit": "x"}}: dm_')
    assert "environment creator" not in str(error.value)
    # values the env stores unchecked fail at its first step: check_task takes one
    for env, kwargs, shown in (
        ("Pendulum-v1", {"g": None}, "g=None"),
        ("simoun-test/ScaledReach-v0", {"scale": "x"}, "scale='x'"),
    ):
        with pytest.raises(SetupError) as error:
            check_task(env_config(env, kwargs))
        message = str(error.value)
        assert shown in message and "failed at its first reset and step" in message, message
        assert "drop --env-kwargs" in message
    assert check_task(env_config("simoun-test/ScaledReach-v0", {"scale": 0.5})) == 20


def test_more_cameras_than_a_dm_control_task_has_are_refused_naming_cameras():
    config = env_config("dm_control/cartpole-swingup-v0", {}, cameras=3)
    for make in (make_env, check_task):
        with pytest.raises(SetupError) as error:
            make(config)
        assert str(error.value) == (
            "--cameras 3: dm_control/cartpole-swingup-v0 has only 2 cameras; pass --cameras 2 "
            "or fewer"
        )
    assert check_task(env_config("dm_control/cartpole-swingup-v0", {}, cameras=2)) == 1000


def test_an_env_id_that_cannot_be_made_is_refused_naming_it_and_the_fix():
    # gymnasium keeps the MuJoCo v2 ids only to raise an ImportError saying where they went
    with pytest.raises(SetupError) as error:
        check_task(env_config("InvertedPendulum-v2", {}))
    message = str(error.value)
    assert message.startswith("--env InvertedPendulum-v2 cannot be made: The mujoco v2 and v3")
    assert message.endswith("use --env InvertedPendulum-v5 instead, or pick another --env")
    if importlib.util.find_spec("jax") is None:  # the phys2d envs import jax
        with pytest.raises(SetupError) as error:
            make_env(env_config("phys2d/Pendulum-v0", {}))
        assert str(error.value) == (
            "--env phys2d/Pendulum-v0 cannot be made: it needs the module 'jax', which is not "
            "installed (pip install jax); pick another --env"
        )


def test_a_highway_task_without_continuous_actions_is_named_in_one_sentence_with_a_fix():
    continuous = {"config": {"action": {"type": "ContinuousAction"}}}
    with pytest.raises(SetupError) as error:
        check_task(env_config("merge-v0", continuous))
    assert str(error.value) == (
        'merge-v0 does not support continuous actions (config.action={"type": '
        '"ContinuousAction"}, which the agents need to drive); pick a highway-env task that '
        "does, e.g. highway-fast-v0"
    )


def test_an_env_kwarg_the_env_fails_on_inside_its_code_is_named_by_its_key():
    highway = {"config": {"action": {"type": "ContinuousAction"}, "initial_lane_id": 5}}
    with pytest.raises(SetupError) as error:
        check_task(env_config("highway-fast-v0", highway))
    assert "cannot use config.initial_lane_id=5 (making it failed: " in str(error.value)
    assert str(error.value).endswith("Fix or drop that key")
    with pytest.raises(SetupError, match=r'cannot use task_kwargs.random="x"'):
        check_task(env_config("dm_control/cartpole-swingup-v0", {"task_kwargs": {"random": "x"}}))


def test_episode_limits_and_action_repeats_that_leave_one_decision_are_refused():
    for env, kwargs, limit in (
        ("Pendulum-v1", {"max_episode_steps": 30}, 30),
        ("dm_control/cartpole-swingup-v0", {}, 1000),  # dm_control's own time limit
        ("simoun/PointReach-v0", {}, 20),  # the env's own max_steps
    ):
        made = make_env(env_config(env, kwargs))
        assert episode_limit(made) == limit
        made.close()
    assert check_task(env_config("Pendulum-v1", {}, action_repeat=100)) == 200
    with pytest.raises(SetupError) as error:
        check_task(env_config("dm_control/cartpole-swingup-v0", {}, action_repeat=1000))
    assert str(error.value).startswith(
        "--action-repeat 1000 (TrainConfig.action_repeat): an episode of "
        "dm_control/cartpole-swingup-v0 ends after 1000 env steps, so it would hold 1 agent "
        "decision"
    )
    assert str(error.value).endswith("set --action-repeat 500 or less (the paper uses 2 to 8)")


def test_env_kwargs_whose_episodes_end_at_the_first_step_are_refused_naming_the_key():
    dmc = "dm_control/cartpole-swingup-v0"
    with pytest.raises(SetupError) as error:
        check_task(env_config(dmc, {"task_kwargs": {"time_limit": 0}}))
    assert "--env-kwargs" in str(error.value)
    assert "ends at its first step" in str(error.value)
    assert "task_kwargs.time_limit=0 is the value that ends it" in str(error.value)
    with pytest.raises(SetupError, match=r"max_episode_steps=1 is the value that ends it"):
        check_task(env_config("Pendulum-v1", {"max_episode_steps": 1}))
    assert check_task(env_config("Pendulum-v1", {"max_episode_steps": 2}, action_repeat=1)) == 2


def test_a_negative_count_in_env_kwargs_is_refused_naming_the_key():
    continuous = {"action": {"type": "ContinuousAction"}}
    negative = {"config": {**continuous, "vehicles_count": -5}}
    with pytest.raises(SetupError) as error:
        check_task(env_config("highway-fast-v0", negative))
    assert str(error.value).startswith(
        "--env-kwargs: config.vehicles_count=-5 (highway-fast-v0's number of other vehicles) "
        "must be a whole number >= 0"
    )
    with pytest.raises(SetupError, match=r"size=-8 is negative"):
        check_task(env_config("MiniGrid-Empty-8x8-v0", {"size": -8}, env_module="minigrid"))
    # a key whose default is 0 is a reward here: a negative one is a penalty, and is taken
    penalty = {"config": {**continuous, "lane_change_reward": -0.5}}
    check_task(env_config("highway-fast-v0", penalty))


gym.register("simoun-test/NeedsMissing-v0", entry_point="simoun_test_absent.envs:Env")


def test_a_camera_id_beside_several_cameras_is_refused_naming_both():
    dmc = "dm_control/cartpole-swingup-v0"
    chosen = env_config(dmc, {"render_kwargs": {"camera_id": 1}}, cameras=2)
    for make in (check_task, make_env):
        with pytest.raises(SetupError) as error:
            make(chosen)
        assert str(error.value) == (
            "--cameras 2 with --env-kwargs render_kwargs.camera_id=1: --cameras N shows "
            f"{dmc}'s cameras 0..N-1 side by side (here 0..1), so the camera_id would be "
            "ignored; for the one camera of your choice pass --cameras 1 with "
            "render_kwargs.camera_id, or drop camera_id to see cameras 0..N-1"
        )
    assert check_task(env_config(dmc, {"render_kwargs": {"camera_id": 1}})) == 1000
    assert check_task(env_config(dmc, {"render_kwargs": {"width": 40}}, cameras=2)) == 1000


def test_a_highway_action_with_no_axis_is_named_for_that_not_for_the_task():
    # made directly (a sweep's trial, a resumed run): the same refusal as before the env is made
    none = {"type": "ContinuousAction", "lateral": False, "longitudinal": False}
    with pytest.raises(SetupError, match=r"^--env-kwargs: config.action has longitudinal=false"):
        make_env(env_config("highway-fast-v0", {"config": {"action": none}}))


def test_an_id_of_a_package_that_is_not_imported_names_the_package():
    assert provider("ALE/Pong-v5").pip == "ale-py"
    assert provider("FetchReach-v4").pip == "gymnasium-robotics"
    assert provider("MiniGrid-DoorKey-6x6-v0").module == "minigrid"
    assert provider("Hopper-v5") is None and provider("dm_control/walker-walk-v0") is None
    with pytest.raises(SetupError) as error:
        check_task(env_config("ALE/Pong-v5", {}))
    if importlib.util.find_spec("ale_py") is None:
        assert str(error.value) == (
            "--env ALE/Pong-v5: ids like this one belong to the Atari games of the Arcade "
            "Learning Environment, which the package ale-py registers when it is imported, and "
            "ale-py is not installed; pip install ale-py, then pass --env ale_py:ALE/Pong-v5"
        )
    else:
        assert "pass --env ale_py:ALE/Pong-v5" in str(error.value)


def test_an_env_whose_package_is_missing_is_refused_with_the_install():
    for make in (check_task, make_env):
        with pytest.raises(SetupError) as error:
            make(env_config("simoun-test/NeedsMissing-v0", {}))
        assert str(error.value) == (
            "--env simoun-test/NeedsMissing-v0 cannot be made: it needs the module "
            "'simoun_test_absent', which is not installed (pip install simoun_test_absent); "
            "pick another --env"
        )


def test_several_env_ids_joined_by_commas_are_named_as_several():
    ids = "dm_control/cartpole-swingup-v0,dm_control/cheetah-run-v0"
    with pytest.raises(SetupError) as refused:
        ensure_registered(ids)
    assert f"{ids!r} is 2 environment ids joined by commas; an env takes one id" in str(
        refused.value
    )
    assert f"simoun-sweep --envs {ids}" in str(refused.value)


HIGHWAY_CONTINUOUS = {"action": {"type": "ContinuousAction"}}


@pytest.mark.parametrize(
    ("given", "said"),
    [
        ({"simulation_frequency": 0}, "config.simulation_frequency=0 (highway-fast-v0's "
         "simulation steps per second) must be a number > 0; e.g. "
         "'{\"config\": {\"simulation_frequency\": 5}}' (its default)"),
        ({"simulation_frequency": -1}, "config.simulation_frequency=-1 (highway-fast-v0's "
         "simulation steps per second) must be a number > 0"),
        ({"policy_frequency": 0}, "config.policy_frequency=0 (highway-fast-v0's agent "
         "decisions per second) must be a number > 0"),
        ({"policy_frequency": 10}, "config.policy_frequency=10 is above "
         "config.simulation_frequency=5 for highway-fast-v0"),
        ({"simulation_frequency": 0.5}, "config.policy_frequency=1 is above "
         "config.simulation_frequency=0.5"),
        ({"duration": 0}, "config.duration=0 (highway-fast-v0's episode length in seconds) "
         "must be a number > 0"),
        ({"lanes_count": 0}, "config.lanes_count=0 (highway-fast-v0's number of lanes) must be "
         "a whole number >= 1"),
        ({"lanes_count": 2.5}, "config.lanes_count=2.5"),
        ({"vehicles_count": -1}, "config.vehicles_count=-1"),
        ({"controlled_vehicles": 0}, "config.controlled_vehicles=0"),
        ({"vehicles_density": 0}, "config.vehicles_density=0"),
        ({"ego_spacing": -1}, "config.ego_spacing=-1 (highway-fast-v0's spacing between "
         "vehicles at the start) must be a number > 0; e.g. '{\"config\": {\"ego_spacing\": "
         "1.5}}' (its default)"),
        ({"ego_spacing": 0}, "config.ego_spacing=0"),
    ],
)  # fmt: skip
def test_a_highway_config_value_that_breaks_the_task_is_refused_naming_the_key(given, said):
    kwargs = {"config": {**HIGHWAY_CONTINUOUS, **given}}
    with pytest.raises(SetupError) as error:
        check_env_kwargs("highway-fast-v0", kwargs)
    assert str(error.value).startswith(f"--env-kwargs: {said}")
    fix = "set config.simulation_frequency to" if "is above" in said else "or drop config."
    assert fix in str(error.value)


def test_a_simulation_frequency_of_zero_is_refused_before_a_run_is_spent():
    zero = {"config": {**HIGHWAY_CONTINUOUS, "simulation_frequency": 0}}
    with pytest.raises(SetupError, match=r"config.simulation_frequency=0 .* must be a number > 0"):
        check_task(env_config("highway-fast-v0", zero))
    # values that keep the task are taken: no traffic, a faster policy within the simulation
    kept = {"vehicles_count": 0, "policy_frequency": 5, "simulation_frequency": 5, "duration": 2}
    assert check_env_kwargs("highway-fast-v0", {"config": {**HIGHWAY_CONTINUOUS, **kept}}) is None
    penalty = {"config": {**HIGHWAY_CONTINUOUS, "collision_reward": -3}}
    assert check_env_kwargs("highway-fast-v0", penalty) is None


def test_an_env_that_renders_no_frame_is_refused_at_set_up_naming_the_key():
    dmc = "dm_control/cartpole-swingup-v0"
    zero_width = env_config(dmc, {"render_kwargs": {"width": 0}})
    with pytest.raises(SetupError) as error:
        check_task(zero_width)
    message = str(error.value)
    assert message.startswith("--env-kwargs: render_kwargs.width=0 (")
    assert "must be a whole number of at least 1" in message
    assert '\'{"render_kwargs": {"width": 84}}\', or drop render_kwargs.width' in message
    # built without the check (a sweep's trial, a resumed run), it is refused all the same
    with pytest.raises(SetupError, match=r"--env-kwargs: render_kwargs.width=0"):
        make_env(zero_width)
    assert check_task(env_config(dmc, {"render_kwargs": {"width": 48, "height": 40}})) == 1000


@pytest.mark.parametrize(
    ("given", "said"),
    [
        ({"lane_count": 4}, "config.lane_count is not a setting of highway-fast-v0's config, and "
         "highway-env would ignore it; did you mean config.lanes_count? Fix the key or drop it"),
        ({"lanes_count": True}, "config.lanes_count=true does not fit highway-fast-v0: "
         "config.lanes_count must be a whole number >= 1 (its default is 3); e.g. "
         "'{\"config\": {\"lanes_count\": 3}}', or drop config.lanes_count"),
        ({"offroad_terminal": "yes"}, "config.offroad_terminal=\"yes\" does not fit "
         "highway-fast-v0: config.offroad_terminal must be true or false (its default is false)"),
        ({"offroad_terminal": 1}, "config.offroad_terminal=1 does not fit"),
        ({"collision_reward": "-1"}, "config.collision_reward=\"-1\" does not fit "
         "highway-fast-v0: config.collision_reward must be a number"),
        ({"collision_reward": [1]}, "config.collision_reward=[1] does not fit"),
        ({"vehicles_count": None}, "config.vehicles_count=null does not fit"),
        ({"reward_speed_range": 20}, "config.reward_speed_range=20 does not fit highway-fast-v0: "
         "config.reward_speed_range must be a list of 2 numbers (its default is [20, 30])"),
        ({"other_vehicles_type": 3}, "config.other_vehicles_type=3 does not fit"),
        ({"controlled_vehicles": 2}, "config.controlled_vehicles=2 must be 1 for "
         "highway-fast-v0: the agent drives one vehicle"),
        ({"reward_speed_range": [30, 20]}, "config.reward_speed_range=[30, 20] (speeds mapped "
         "onto the high-speed reward, [slowest, fastest] in m/s) must have its low end first "
         "and below its high end; e.g. '{\"config\": {\"reward_speed_range\": [20, 30]}}'"),
        ({"reward_speed_range": [20, 20]}, "config.reward_speed_range=[20, 20] (speeds mapped "
         "onto the high-speed reward, [slowest, fastest] in m/s) has equal ends"),
        ({"action": {"type": "ContinousAction"}}, "config.action.type=\"ContinousAction\" is "
         "not an action type of highway-env; did you mean 'ContinuousAction'?"),
        ({"action": {"type": "ContinuousAction", "acceleraton_range": [-5, 5]}},
         "config.action.acceleraton_range is not a setting of highway-env's ContinuousAction, "
         "which would ignore it; did you mean config.action.acceleration_range?"),
        ({"action": {"type": "ContinuousAction", "lateral": "no"}},
         "config.action.lateral=\"no\" does not fit highway-fast-v0: config.action.lateral "
         "must be true or false"),
        ({"action": {"type": "ContinuousAction", "speed_range": [30, 0]}},
         "config.action.speed_range=[30, 0] (speeds the vehicle may reach, [lowest, highest] in "
         "m/s) must have its low end first"),
        ({"action": {"type": "ContinuousAction", "steering_range": [0.5, 0.5]}},
         "config.action.steering_range=[0.5, 0.5] (steering angles the action's [-1, 1] maps "
         "onto, [lowest, highest] in radians) has equal ends"),
        ({"action": {"type": "ContinuousAction", "steering_range": [0.5, -0.5]}},
         "config.action.steering_range=[0.5, -0.5] (steering angles the action's [-1, 1] maps "
         "onto, [lowest, highest] in radians) must have its low end first and below its high "
         "end, and swapped ends would mirror that axis of the agent's action; e.g. "
         "'{\"config\": {\"action\": {\"steering_range\": [-0.5, 0.5]}}}'"),
        ({"action": {"type": "ContinuousAction", "acceleration_range": [5, -5]}},
         "config.action.acceleration_range=[5, -5] (accelerations the action's [-1, 1] maps "
         "onto, [lowest, highest] in m/s^2) must have its low end first"),
        ({"manual_control": True}, "config.manual_control=true makes highway-fast-v0 drive the "
         "vehicle from the keyboard of a window, and highway-env would never apply the agent's "
         "actions"),
        ({"action": {"type": "ContinuousAction", "lateral": False, "longitudinal": False}},
         "config.action has longitudinal=false and lateral=false, so highway-env's "
         "ContinuousAction has no axis (neither throttle nor steering) and the agent could not "
         "drive; set one of them true"),
        ({"scaling": 3}, "config.scaling=3 sets highway-env's rendered view, which simoun's "
         "cameras set for every view the agent sees (from --cameras and --image-size), so the "
         "value would be replaced; drop config.scaling"),
        ({"scaling": -1}, "config.scaling=-1 sets highway-env's rendered view"),
        ({"centering_position": [0.3, 0.5]}, "config.centering_position=[0.3, 0.5] sets "
         "highway-env's rendered view"),
        ({"screen_width": 200}, "config.screen_width=200 sets highway-env's rendered view"),
        ({"action": {"type": "ContinuousAction", "steering_range": 0.5}},
         "config.action.steering_range=0.5 must be a list of 2 numbers [low, high]"),
    ],
)  # fmt: skip
def test_a_highway_config_key_or_value_that_changes_the_task_is_refused(given, said):
    kwargs = {"config": {**HIGHWAY_CONTINUOUS, **given}}
    with pytest.raises(SetupError) as error:
        check_env_kwargs("highway-fast-v0", kwargs)
    assert str(error.value).startswith(f"--env-kwargs: {said}")


def test_highway_config_values_of_the_defaults_kind_are_taken():
    kept = {
        "lanes_count": 2,
        "duration": 20.5,  # a float where the default is an int: both are numbers
        "collision_reward": -1.5,
        "offroad_terminal": True,
        "controlled_vehicles": 1,
        "initial_lane_id": 1,  # a None default takes any value
        "reward_speed_range": [10.5, 20],
    }
    assert check_env_kwargs("highway-fast-v0", {"config": {**HIGHWAY_CONTINUOUS, **kept}}) is None
    # ranges in order, switches that keep one axis or leave the keyboard alone are the user's
    ordered = {"type": "ContinuousAction", "acceleration_range": [-3, 4], "clip": False}
    assert check_env_kwargs("highway-fast-v0", {"config": {"action": ordered}}) is None
    steering_only = {"type": "ContinuousAction", "longitudinal": False}
    keys = {"action": steering_only, "manual_control": False}
    assert check_env_kwargs("highway-fast-v0", {"config": keys}) is None
    # racetrack's own default action holds a key its action class ignores: copying it is fine
    ensure_registered("racetrack-v0")
    own = {"type": "ContinuousAction", "lateral": True, "target_speeds": [0, 5, 10]}
    assert check_env_kwargs("racetrack-v0", {"config": {"action": own}}) is None


@pytest.mark.parametrize(
    ("env", "given", "said"),
    [
        ("highway-fast-v0", {"config": "highway.json"}, "config must be a JSON object of "
         "highway-env settings for highway-fast-v0, got \"highway.json\"; e.g. "
         "'{\"config\": {\"lanes_count\": 3}}' (a file's settings go in as its contents, not "
         "its name), or drop config"),
        ("highway-fast-v0", {"config": [1]}, "config must be a JSON object of highway-env "
         "settings for highway-fast-v0, got [1]"),
        ("dm_control/cartpole-swingup-v0", {"render_kwargs": "x"}, "render_kwargs must be a "
         "JSON object of settings for dm_control/cartpole-swingup-v0, got \"x\"; e.g. "
         "'{\"render_kwargs\": {\"width\": 84, \"height\": 84, \"camera_id\": 0}}'"),
        ("dm_control/cartpole-swingup-v0", {"task_kwargs": [1]}, "task_kwargs must be a JSON "
         "object"),
        ("dm_control/cartpole-swingup-v0", {"environment_kwargs": 3}, "environment_kwargs must "
         "be a JSON object"),
        ("dm_control/cartpole-swingup-v0", {"visualize_reward": "no"}, "visualize_reward='no' "
         "does not fit dm_control/cartpole-swingup-v0: its 'visualize_reward' is true or false"),
        ("Reacher-v5", {"default_camera_config": "camera.json"}, "default_camera_config must be "
         "a JSON object of settings for Reacher-v5"),
    ],
)  # fmt: skip
def test_an_env_kwarg_that_takes_a_json_object_refuses_anything_else(env, given, said):
    ensure_registered(env)
    with pytest.raises(SetupError) as error:
        check_env_kwargs(env, given)
    assert str(error.value).startswith(f"--env-kwargs: {said}")


@pytest.mark.parametrize(
    ("typed", "module", "first"),
    [
        ("cartpole-swingup-v0", "dm_control", "dm_control/cartpole-swingup-v0"),  # MODULE:ID
        ("dm_control/ball-in-cup-catch-v0", None, "dm_control/ball_in_cup-catch-v0"),
        ("DM_Control/Cartpole-Swingup-v0", None, "dm_control/cartpole-swingup-v0"),
        ("highway_fast-v0", None, "highway-fast-v0"),
        ("cartpole-swingup", None, "dm_control/cartpole-swingup-v0"),  # no version
        ("cartpole", None, "CartPole-v1"),  # the newest version of the id without a namespace
    ],
)
def test_an_env_id_spelt_another_way_is_offered_first(typed, module, first):
    with pytest.raises(SetupError) as error:
        ensure_registered(typed, module)
    assert f"did you mean {first}" in str(error.value)
    assert "no registered id is close" not in str(error.value)


@pytest.mark.parametrize(
    ("env", "given", "said"),
    [
        ("HalfCheetah-v5", {"camera_id": 99}, "camera_id=99 is not a camera of HalfCheetah-v5; "
         "camera_id is a camera id (a whole number), and its cameras are 0 'track' and -1, the "
         "free camera. Give e.g. '{\"camera_id\": 0}', or drop camera_id"),
        ("HalfCheetah-v5", {"camera_name": "nope"}, "camera_name=\"nope\" is not a camera of "
         "HalfCheetah-v5 (gymnasium would render the free camera instead, without a word); its "
         "named cameras are 'track'. Give e.g. '{\"camera_name\": \"track\"}'"),
        ("Reacher-v5", {"camera_id": 0}, "camera_id=0 is not a camera of Reacher-v5; camera_id "
         "is a camera id (a whole number), and its cameras are only -1, the free camera"),
        ("HalfCheetah-v5", {"camera_id": "track"}, "camera_id=\"track\" is not a camera"),
        ("HalfCheetah-v5", {"width": 0}, "width=0 (the width of HalfCheetah-v5's rendered "
         "frames in pixels) must be a whole number of at least 1"),
        ("HalfCheetah-v5", {"height": 1.5}, "height=1.5 (the height of HalfCheetah-v5's"),
        ("HalfCheetah-v5", {"default_camera_config": {"distnace": 3}}, "default_camera_config."
         "distnace is not a setting of MuJoCo's camera; its settings are azimuth, distance"),
        ("dm_control/cartpole-swingup-v0", {"render_kwargs": {"camera_id": "nope"}},
         "render_kwargs.camera_id=\"nope\" is not a camera of dm_control/cartpole-swingup-v0; "
         "render_kwargs.camera_id is a camera id (a whole number) or name, and its cameras are "
         "0 'fixed', 1 'lookatcart' and -1, the free camera"),
        ("dm_control/cartpole-swingup-v0", {"render_kwargs": {"camera_id": 2}},
         "render_kwargs.camera_id=2 is not a camera"),
    ],
)  # fmt: skip
def test_a_camera_or_render_size_the_model_lacks_is_refused_before_the_first_render(
    env, given, said
):
    # MuJoCo ends the process over a camera id it lacks at the first render, and gymnasium
    # renders the free camera for an unknown camera name: both are refused at set-up
    with pytest.raises(SetupError) as error:
        check_task(env_config(env, given))
    assert str(error.value).startswith(f"--env-kwargs: {said}")


def test_the_cameras_a_model_has_are_taken_by_id_and_by_name():
    assert check_task(env_config("HalfCheetah-v5", {"camera_name": "track", "width": 48})) == 1000
    assert check_task(env_config("HalfCheetah-v5", {"camera_id": -1})) == 1000
    lookatcart = {"render_kwargs": {"width": 32, "height": 32, "camera_id": "lookatcart"}}
    assert check_task(env_config("dm_control/cartpole-swingup-v0", lookatcart)) == 1000


def test_an_env_kwarg_naming_a_file_that_is_not_there_is_refused_naming_the_key(
    tmp_path, monkeypatch
):
    with pytest.raises(SetupError) as error:
        check_env_kwargs("HalfCheetah-v5", {"xml_file": "cheetah.xml"})
    message = str(error.value)
    assert message.startswith('--env-kwargs: xml_file="cheetah.xml" names no file: HalfCheetah-v5')
    assert "gymnasium's MuJoCo assets folder" in message and "half_cheetah.xml" in message
    assert "give the absolute path of an existing MuJoCo XML file, or drop xml_file" in message
    # a file in the current directory is not where gymnasium looks for a bare name: ./ is
    monkeypatch.chdir(tmp_path)
    (tmp_path / "cheetah.xml").write_text("<mujoco/>")
    with pytest.raises(SetupError, match=r"give it as './cheetah.xml' \(or its absolute path"):
        check_env_kwargs("HalfCheetah-v5", {"xml_file": "cheetah.xml"})
    assert check_env_kwargs("HalfCheetah-v5", {"xml_file": "half_cheetah.xml"}) is None


def test_an_env_kwarg_naming_a_class_that_does_not_import_is_refused_with_the_classes():
    careful = {**HIGHWAY_CONTINUOUS, "other_vehicles_type": "highway_env.vehicle.behavior.Careful"}
    with pytest.raises(SetupError) as error:
        check_env_kwargs("highway-fast-v0", {"config": careful})
    message = str(error.value)
    assert message.startswith(
        '--env-kwargs: config.other_vehicles_type="highway_env.vehicle.behavior.Careful" names '
        "no class that imports"
    )
    assert "highway_env.vehicle.behavior.AggressiveVehicle" in message
    assert "or drop config.other_vehicles_type" in message
    for path in ("highway_env.vehicle.behavior.Aggressive", "no_such_package.Vehicle"):
        with pytest.raises(SetupError, match="names no class that imports"):
            check_env_kwargs("merge-v0", {"config": {"other_vehicles_type": path}})
    aggressive = {
        **careful,
        "other_vehicles_type": "highway_env.vehicle.behavior.AggressiveVehicle",
    }
    assert check_env_kwargs("highway-fast-v0", {"config": aggressive}) is None


class ReadsItsData(gym.Env):
    """A pixel env that reads a file named by its ``data`` keyword when it is made."""

    metadata = {"render_modes": ["rgb_array"]}  # noqa: RUF012

    def __init__(self, data=None, render_mode=None):
        if data is not None:
            with open(data) as file:  # an OSError for a file that is not there
                file.read()
        self.render_mode = render_mode
        self.observation_space = gym.spaces.Box(0, 255, (8, 8, 3), np.uint8)
        self.action_space = gym.spaces.Box(-1.0, 1.0, (1,), np.float32)

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        return np.zeros((8, 8, 3), np.uint8), {}

    def step(self, action):
        return np.zeros((8, 8, 3), np.uint8), 0.0, False, False, {}

    def render(self):
        return np.zeros((8, 8, 3), np.uint8)


gym.register("simoun-test/ReadsItsData-v0", entry_point=ReadsItsData, max_episode_steps=10)


def test_any_error_of_an_env_made_with_env_kwargs_is_named_on_one_line_with_the_keys(tmp_path):
    missing = str(tmp_path / "no-such-file.txt")
    with pytest.raises(SetupError) as error:
        check_task(env_config("simoun-test/ReadsItsData-v0", {"data": missing}))
    message = str(error.value)
    assert message.startswith(f'--env-kwargs {{"data": "{missing}"}}: ')
    assert "cannot use data=" in message and "FileNotFoundError: " in message
    assert "\n" not in message
    (tmp_path / "data.txt").write_text("x")
    ok = env_config("simoun-test/ReadsItsData-v0", {"data": str(tmp_path / "data.txt")})
    assert check_task(ok) == 10


def test_an_env_whose_constructor_takes_no_render_mode_is_refused_for_that_reason():
    with pytest.raises(SetupError) as error:
        check_task(env_config("lane-keeping-v0", {}))
    message = str(error.value)
    assert message.startswith(
        "lane-keeping-v0 gives no frames to learn from: its constructor does not accept "
        "render_mode (gym.make('lane-keeping-v0', render_mode='rgb_array') raises TypeError)"
    )
    assert "neither" not in message and "Pick a highway-env task that takes render_mode" in message


@pytest.mark.parametrize(
    "env", ["intersection-v0", "racetrack-v0", "parking-v0", "exit-v0", "u-turn-v0"]
)
@pytest.mark.parametrize("preset", ["highway", "highway-cpu"])
def test_a_highway_preset_takes_every_highway_env_task_with_the_settings_it_has(preset, env):
    config = resolve(preset, {"env": env, "image_size": 32})
    check_task(config)


def test_a_highway_preset_on_a_task_without_continuous_actions_is_refused_for_that():
    with pytest.raises(SetupError, match=r"^two-way-v0 does not support continuous actions"):
        check_task(resolve("highway-cpu", {"env": "two-way-v0", "image_size": 32}))


def test_every_spacing_length_count_duration_and_noise_of_every_highway_task_is_held():
    # the limits come from what a key's name says, so every task's keys are covered, and
    # every task's own default passes them; rewards and costs stay free (a penalty is negative)
    checked = set()
    for env_id in (
        "highway-v0",
        "merge-v0",
        "roundabout-v0",
        "intersection-v0",
        "racetrack-v0",
        "parking-v0",
        "exit-v0",
        "u-turn-v0",
        "two-way-v0",
        "lane-keeping-v0",
        "roundabout-generic-v0",
        "merge-generic-v0",
    ):
        ensure_registered(env_id)
        creator = gym.envs.registration.load_env_creator(gym.spec(env_id).entry_point)
        defaults = creator.default_config()
        for key, value in defaults.items():
            limit = limit_of(key)
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                continue
            if limit is None:
                free = ("reward", "cost", "screen", "scaling", "constraint", "range")
                assert any(word in key for word in free), key
                continue
            assert limit.ok(value), (env_id, key, value)
            assert not limit.ok(-1), key
            checked.add(key)
    assert {"ego_spacing", "before_merge_length", "roundabout_radius", "state_noise"} <= checked
    with pytest.raises(SetupError, match=r"config.roundabout_radius=-20 .* must be a number > 0"):
        check_env_kwargs("roundabout-generic-v0", {"config": {"roundabout_radius": -20}})


def test_env_kwargs_merge_into_simouns_own_settings_key_by_key():
    dmc = make_env(
        env_config("dm_control/cartpole-swingup-v0", {"render_kwargs": {"camera_id": 1}})
    )
    try:  # the camera is the user's; the frame size stays the run's
        assert dmc.unwrapped.render_kwargs == {"width": 32, "height": 32, "camera_id": 1}
    finally:
        dmc.close()
    stack = {"observation": {"stack_size": 2}}
    highway = make_env(env_config("highway-fast-v0", {"config": {**HIGHWAY_CONTINUOUS, **stack}}))
    try:  # simoun's dropped observation keeps its type, shape and weights under the user's stack
        observation = highway.unwrapped.config["observation"]
        assert observation["type"] == "GrayscaleObservation"
        assert observation["stack_size"] == 2
        assert observation["observation_shape"] == (8, 8)
    finally:
        highway.close()
    # an observation of another type replaces simoun's whole: its settings are another class's
    other = {"config": {**HIGHWAY_CONTINUOUS, "observation": {"type": "Kinematics"}}}
    kinematics = make_env(env_config("highway-fast-v0", other))
    try:
        assert kinematics.unwrapped.config["observation"] == {"type": "Kinematics"}
    finally:
        kinematics.close()


def test_numpy_numbers_and_tuples_in_env_kwargs_are_read_as_json_numbers_and_lists():
    # from Python a count is often a numpy integer and a range a tuple: both are valid
    assert check_env_kwargs(POINT_REACH_ID, {"max_steps": np.int64(10)}) is None
    given = {"reward_speed_range": (20, 30), "lanes_count": np.int64(3), "duration": np.float32(9)}
    config = {**HIGHWAY_CONTINUOUS, **given}
    assert check_env_kwargs("highway-fast-v0", {"config": config}) is None
    with pytest.raises(SetupError, match=r"config.reward_speed_range=\[30, 20\]"):
        check_env_kwargs("highway-fast-v0", {"config": {"reward_speed_range": (30, 20)}})
