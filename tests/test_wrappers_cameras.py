"""MultiCamera on dm_control named cameras, highway-env viewports and callables."""

import gymnasium as gym
import highway_env
import numpy as np
import pytest
import shimmy

from simoun_wrappers import MultiCamera, SimounObservation

gym.register_envs(shimmy)
gym.register_envs(highway_env)


def _views(obs: np.ndarray, n: int) -> list[np.ndarray]:
    return np.split(obs, n, axis=1)


def _assert_distinct_non_black(views: list[np.ndarray]) -> None:
    for view in views:
        assert view.max() > 50 and view.std() > 5, "a view is black or blank"
    for i in range(len(views)):
        for j in range(i + 1, len(views)):
            assert np.abs(views[i].astype(int) - views[j]).mean() > 1, f"views {i}, {j} identical"


def test_dm_control_two_named_cameras():
    env = MultiCamera(gym.make("dm_control/walker-walk-v0"), ["side", "back"], size=(32, 40))
    assert env.observation_space == gym.spaces.Box(0, 255, (32, 80, 3), np.uint8)
    obs, _ = env.reset(seed=0)
    assert obs.shape == (32, 80, 3) and obs.dtype == np.uint8
    _assert_distinct_non_black(_views(obs, 2))
    obs2, *_ = env.step(env.action_space.sample())
    assert not np.shares_memory(obs, obs2)
    np.testing.assert_array_equal(env.render(), obs2)
    # each view is that camera's rendering of the current step, in the order given
    physics = env.unwrapped._env.physics
    for view, name in zip(_views(obs2, 2), ["side", "back"], strict=True):
        np.testing.assert_array_equal(view, physics.render(32, 40, camera_id=name))


def test_dm_control_camera_ids_and_unknown_name():
    env = gym.make("dm_control/cartpole-swingup-v0")
    obs, _ = MultiCamera(env, [0, 1, -1], size=24).reset(seed=0)
    assert obs.shape == (24, 72, 3)
    with pytest.raises(ValueError, match=r"unknown camera name 'front'.*\['fixed', 'lookatcart'\]"):
        MultiCamera(env, ["fixed", "front"])
    with pytest.raises(ValueError, match=r"camera id 5 out of range"):
        MultiCamera(env, [5])


def test_highway_three_viewports():
    env = gym.make("highway-fast-v0", config={"vehicles_count": 8, "simulation_frequency": 5})
    viewports = [
        {"scaling": 2.5},
        {"scaling": 6.0},
        {"centering_position": [0.2, 0.5], "scaling": 3.5},
    ]
    env = MultiCamera(env, viewports, size=(32, 48))
    obs, _ = env.reset(seed=0)
    assert obs.shape == (32, 144, 3)
    _assert_distinct_non_black(_views(obs, 3))
    for _ in range(2):
        obs, *_ = env.step(env.action_space.sample())
    _assert_distinct_non_black(_views(obs, 3))
    env.close()
    # Closing must not quit pygame under other viewers still in use.
    other = MultiCamera(gym.make("highway-fast-v0"), viewports[:2], size=16)
    assert other.reset(seed=0)[0].shape == (16, 32, 3)


def test_callables_are_resized():
    env = gym.make("CartPole-v1", render_mode="rgb_array")

    def left_half(e):
        return e.unwrapped.render()[:, :300]

    def full(e):
        return e.unwrapped.render()

    cams = MultiCamera(env, [left_half, full], size=(20, 30))
    obs, _ = cams.reset(seed=0)
    assert obs.shape == (20, 60, 3)
    _assert_distinct_non_black(_views(obs, 2))


def test_error_views_of_different_sizes_names_size():
    env = gym.make("CartPole-v1", render_mode="rgb_array")

    def small(e):
        return np.full((10, 10, 3), 100, np.uint8)

    def large(e):
        return np.full((12, 10, 3), 100, np.uint8)

    with pytest.raises(ValueError, match=r"views of different sizes.*\(10, 10, 3\).*size=\(H, W\)"):
        MultiCamera(env, [small, large], size=None)
    ok = MultiCamera(env, [small, large], size=(8, 8))
    assert ok.reset(seed=0)[0].shape == (8, 16, 3)


def test_error_bad_cameras():
    cartpole = gym.make("CartPole-v1")
    with pytest.raises(TypeError, match=r"not a dm_control env.*callables"):
        MultiCamera(cartpole, ["side"])
    with pytest.raises(TypeError, match=r"not a highway-env env"):
        MultiCamera(cartpole, [{"scaling": 2.0}])
    with pytest.raises(ValueError, match=r"viewport keys \['zoom'\]"):
        MultiCamera(gym.make("highway-fast-v0"), [{"zoom": 2.0}])
    with pytest.raises(TypeError, match=r"list of views"):
        MultiCamera(cartpole, "side")
    with pytest.raises(TypeError, match=r"must return an \(H, W, 3\) uint8 image"):
        MultiCamera(cartpole, [lambda e: np.zeros((4, 4, 3), np.float32)], size=4)


def test_camera_images_are_checked_as_renders_are_at_every_step():
    env = gym.make("CartPole-v1", render_mode="rgb_array")
    bad = [
        (lambda e: np.zeros((0, 4, 3), np.uint8), 16, ValueError, "an array of shape (0, 4, 3)"),
        (lambda e: [[0, 0, 0]], 16, TypeError, "returned a list; it must return an (H, W, 3)"),
        (lambda e: np.zeros((4, 4), np.uint8), 16, ValueError, "an array of shape (4, 4)"),
        (lambda e: np.zeros((4, 4, 4), np.uint8), None, ValueError, "an array of shape (4, 4, 4)"),
    ]
    for camera, size, error, said in bad:
        with pytest.raises(error) as raised:
            MultiCamera(env, [camera], size=size)
        assert f"MultiCamera takes its frames from camera {camera!r}, which returned" in str(
            raised.value
        )
        assert said in str(raised.value)
    sides = iter(range(8, 100))

    def growing(e):
        return np.zeros((next(sides), 8, 3), np.uint8)

    cams = MultiCamera(env, [growing], size=None)
    assert cams.observation_space.shape == (8, 8, 3)
    changed = r"returned an image of shape \(9, 8, 3\); it must return uint8 images of its first "
    with pytest.raises(ValueError, match=changed + r"image's shape \(8, 8, 3\).*size=\(H, W\)"):
        cams.reset(seed=0)
    resized = MultiCamera(env, [growing], size=8)
    for _ in range(3):
        assert resized.reset(seed=0)[0].shape == (8, 8, 3)


def rendered(env: gym.Env) -> np.ndarray:
    """A camera that pickles: the env's own render."""
    return env.render()


def test_cameras_from_a_generator_are_read_once_and_the_wrapper_copies_and_pickles():
    import pickle

    import simoun_agent.envs  # noqa: F401  (registers simoun/PointReach-v0, which pickles)

    point = gym.make("simoun/PointReach-v0", render_mode="rgb_array")
    env = MultiCamera(point, (camera for camera in [rendered, rendered]), size=16)
    assert env.spec.kwargs is not None and env._saved_kwargs["cameras"] == (rendered, rendered)
    for copied in (pickle.loads(pickle.dumps(env)), gym.make(env.spec), env):
        assert copied.reset(seed=0)[0].shape == (16, 32, 3)
    dmc = MultiCamera(gym.make("dm_control/cartpole-swingup-v0"), iter([0, 1]), size=16)
    assert dmc.reset(seed=0)[0].shape == (16, 32, 3)
    assert gym.make(dmc.spec).reset(seed=0)[0].shape == (16, 32, 3)
    cartpole = gym.make("CartPole-v1", render_mode="rgb_array")
    for wrap in (
        lambda size: MultiCamera(cartpole, [rendered], size),
        lambda size: SimounObservation(cartpole, size),
    ):
        with pytest.raises(ValueError, match=r"size must be a positive int or an \(H, W\) pair"):
            wrap(size=(n for n in [8, 8]))


def test_step_before_the_users_reset_is_refused():
    # the constructor resets the env to read the views' sizes; that episode is not the user's
    env = MultiCamera(gym.make("CartPole-v1", render_mode="rgb_array"), [lambda e: e.render()], 16)
    with pytest.raises(gym.error.ResetNeeded, match=r"MultiCamera\.step\(\) before reset\(\)"):
        env.step(0)
    env.reset(seed=0)
    obs, *_ = env.step(0)
    assert obs.shape == (16, 16, 3)
