"""CuriosityModel's update thread and frame pooling, on dm_control cartpole through shimmy."""

import copy
import dataclasses
import gc
import pickle

import gymnasium as gym
import numpy as np
import pytest
import shimmy
import torch
from test_curiosity_model_by_hand import SMALL

from simoun_agent.curiosity_model import CuriosityConfig, CuriosityModel
from simoun_wrappers import SimounObservation
from simoun_wrappers.curiosity_reward import (
    ConsistencyCuriosityReward,
    ConsistencyCuriosityVectorReward,
)

gym.register_envs(shimmy)

pytestmark = pytest.mark.filterwarnings("ignore::UserWarning")

SIZE = 32
TINY = CuriosityConfig(**SMALL, batch_size=8, capacity=64, learning_starts=16)


def cartpole(size: int = SIZE) -> gym.Env:
    render = {"height": size, "width": size, "camera_id": 0}
    env = gym.make("dm_control/cartpole-swingup-v0", render_mode="rgb_array", render_kwargs=render)
    return SimounObservation(env, size=size)


class Recorded:
    """A CuriosityModel seen through the wrapper: each feature call's output and the number of
    published gradient steps it used."""

    def __init__(self, model: CuriosityModel) -> None:
        self.model = model
        self.calls: list[tuple[np.ndarray, np.ndarray, np.ndarray, int]] = []

    def __call__(self, triplets):
        f_m, f_a = self.model(triplets)
        self.calls.append((triplets.copy(), f_m, f_a, self.model.feature_version))
        return f_m, f_a

    def watch(self, *transition):
        self.model.watch(*transition)

    def close(self):
        self.model.close()


def rollout(config: CuriosityConfig, steps: int = 24, vector: bool = False):
    """Intrinsic rewards of a seeded rollout with fixed actions, and the recorded source."""
    if vector:
        env = gym.vector.SyncVectorEnv([cartpole, cartpole])
        model = CuriosityModel.for_env(env, config, device="cpu")
        source = Recorded(model)
        env = ConsistencyCuriosityVectorReward(env, source)
    else:
        env = cartpole()
        model = CuriosityModel.for_env(env, config, device="cpu")
        source = Recorded(model)
        env = ConsistencyCuriosityReward(env, source)
    env.reset(seed=0)
    actions = np.sin(np.arange(steps * 2) * 0.7).astype(np.float32).reshape(steps, 2, 1)
    rewards = []
    for t in range(steps):
        action = actions[t] if vector else actions[t, 0]
        rewards.append(np.atleast_1d(env.step(action)[4]["reward_intrinsic"]).copy())
    env.close()
    return np.array(rewards), source


@pytest.mark.parametrize("vector", [False, True])
def test_the_thread_changes_no_reward_and_a_seed_fixes_them(vector):
    thread, recorded = rollout(TINY, vector=vector)
    inline, recorded_inline = rollout(dataclasses.replace(TINY, background=False), vector=vector)
    again, _ = rollout(TINY, vector=vector)
    # The same updates from the same weights: equal up to float rounding (one run in CI differed
    # by 1 ulp, 3.6e-8 in one of 24 rewards, between the thread and inline: the kernels torch
    # picks may differ between threads); a different seed moves them by far more than 1e-6
    np.testing.assert_allclose(thread, inline, rtol=1e-6, atol=0)
    np.testing.assert_allclose(thread, again, rtol=1e-6, atol=0)
    versions = [call[3] for call in recorded.calls]
    assert versions == [call[3] for call in recorded_inline.calls]
    assert max(versions) >= 3  # the rewards span several published updates
    other, _ = rollout(dataclasses.replace(TINY, seed=1), vector=vector)
    assert not np.allclose(thread, other, rtol=1e-3, atol=0)


def test_features_come_only_from_weights_published_whole():
    # One update per step, so the thread trains while most feature calls run.
    config = dataclasses.replace(TINY, update_every=1, batch_size=16)
    weights, calls = {}, None
    for background in (False, True):
        env = cartpole()
        model = CuriosityModel.for_env(env, dataclasses.replace(config, background=background))
        source = Recorded(model)
        env = ConsistencyCuriosityReward(env, source)
        env.reset(seed=0)
        env.action_space.seed(0)
        for _ in range(30):
            if not background:  # the weights after exactly `updates` whole steps
                weights[model.updates] = copy.deepcopy(model.published.state_dict())
            env.step(env.action_space.sample())
        env.close()
        calls = source.calls
    assert len(weights) > 10
    # Each feature call of the threaded run equals a re-encoding with the weights of exactly the
    # version it used: never a model half-way through a step. The thread's weights match the
    # inline run's up to float rounding (a CI run differed by 7e-7 after some updates: the kernels
    # torch picks may differ between threads), so "equal" is within 1e-5, and the neighbouring
    # versions must differ by far more than that, or the check could not tell them apart.
    reference = CuriosityModel.for_env(cartpole(), config, device="cpu")

    def features(version, triplets):
        reference.published.load_state_dict(weights[version])
        return np.concatenate([f.ravel() for f in reference(triplets)])

    told_apart = 0
    for triplets, f_m, f_a, version in calls:
        seen = np.concatenate([f_m.ravel(), f_a.ravel()])
        np.testing.assert_allclose(seen, features(version, triplets), rtol=0, atol=1e-5)
        for neighbour in (version - 1, version + 1):
            if neighbour in weights:
                assert np.abs(seen - features(neighbour, triplets)).max() > 1e-3
                told_apart += 1
    assert told_apart > 10


def test_at_most_one_update_is_in_flight_and_none_is_dropped():
    config = dataclasses.replace(TINY, update_every=1, batch_size=32, learning_starts=32)
    env = cartpole()
    model = CuriosityModel.for_env(env, config, device="cpu")
    env = ConsistencyCuriosityReward(env, model)
    env.reset(seed=0)
    env.action_space.seed(0)
    for t in range(1, 51):
        env.step(env.action_space.sample())
        started = max(0, t - config.learning_starts + 1)
        # every due step was started (none dropped) and all but the newest are published: at
        # most one is in flight, and it is the one started at this step
        assert model.updates + model.pending == started
        assert model.updates == max(0, started - 1)
    assert model._thread is not None and model._thread.thread.is_alive()  # it ran in the thread
    env.close()


def test_a_failed_update_raises_on_the_next_step_until_a_state_is_loaded():
    config = dataclasses.replace(TINY, update_every=1)
    env = cartpole()
    model = CuriosityModel.for_env(env, config, device="cpu")
    env = ConsistencyCuriosityReward(env, model)
    env.reset(seed=0)
    for _ in range(20):
        env.step(np.zeros(1, np.float32))
    saved = model.state_dict()  # waits for the step in flight
    with torch.no_grad():  # a diverged encoder: the next gradient step meets a NaN loss
        next(model.encoder.parameters()).fill_(float("nan"))
    env.step(np.zeros(1, np.float32))  # publishes the good step, starts the bad one
    with pytest.raises(RuntimeError, match=r"gradient step failed \(FloatingPointError.*lr") as err:
        env.step(np.zeros(1, np.float32))
    assert isinstance(err.value.__cause__, FloatingPointError)
    with pytest.raises(RuntimeError, match="load_state_dict"):
        env.step(np.zeros(1, np.float32))
    model.load_state_dict(saved)
    env.step(np.zeros(1, np.float32))
    env.close()


def test_close_stops_the_update_thread_and_a_later_step_starts_a_new_one():
    model = CuriosityModel.for_env(cartpole(), TINY, device="cpu")
    envs = [ConsistencyCuriosityReward(cartpole(), model) for _ in range(2)]
    for env in envs:
        env.reset(seed=0)
    for _ in range(20):
        envs[0].step(np.zeros(1, np.float32))
    thread = model._thread.thread
    assert thread.is_alive()
    envs[0].close()
    assert not thread.is_alive() and model._thread is None
    for _ in range(4):  # the model is shared: the other env keeps training it
        envs[1].step(np.zeros(1, np.float32))
    assert model._thread.thread.is_alive()
    envs[1].close()
    assert model._thread is None


def test_a_pickled_model_keeps_its_unpublished_step_and_not_the_thread():
    env = ConsistencyCuriosityReward(cartpole(), CuriosityModel.for_env(cartpole(), TINY))
    env.reset(seed=0)
    for _ in range(20):
        env.step(np.zeros(1, np.float32))
    model = env.signal.features
    clone = pickle.loads(pickle.dumps(model))
    assert clone.pending and clone._thread is None and clone.updates == model.updates
    env.step(np.zeros(1, np.float32))
    triplets = np.stack([env.step(np.zeros(1, np.float32))[0]["frames"]] * 2)  # a due step
    for a, b in zip(model(triplets), clone(triplets), strict=True):
        assert not np.array_equal(a, b)  # the clone has not published the step yet
    transition = (triplets, np.zeros((2, 1), np.float32), triplets, *np.zeros((2, 2), bool))
    clone.watch(*transition)
    clone.watch(*transition)  # a due call: publishes the step made before pickling
    for a, b in zip(model(triplets), clone(triplets), strict=True):
        np.testing.assert_array_equal(a, b)
    env.close()
    clone.close()


def test_a_model_nobody_closed_stops_its_thread_when_freed():
    env = ConsistencyCuriosityReward(cartpole(), CuriosityModel.for_env(cartpole(), TINY))
    env.reset(seed=0)
    for _ in range(20):
        env.step(np.zeros(1, np.float32))
    thread = env.signal.features._thread.thread
    assert thread.is_alive()
    del env
    gc.collect()
    thread.join(timeout=120)  # generous under load; a thread that never stops still fails
    assert not thread.is_alive()


def test_frames_are_average_pooled_to_about_encoder_size():
    pooled_config = dataclasses.replace(TINY, encoder_size=24)
    model = CuriosityModel.for_env(cartpole(48), pooled_config, device="cpu")
    full = CuriosityModel((3, 24, 24), model.action_space, dataclasses.replace(TINY), "cpu")
    assert model.pool == 2 and model.encoded_shape == (3, 24, 24)
    env = cartpole(48)
    obs, _ = env.reset(seed=0)
    obs, *_ = env.step(np.ones(1, np.float32))
    triplet = obs["frames"][None]
    by_hand = triplet.reshape(1, 3, 3, 24, 2, 24, 2).mean((4, 6)).round().astype(np.uint8)
    for a, b in zip(model(triplet), full(by_hand), strict=True):
        np.testing.assert_array_equal(a, b)
    assert CuriosityModel.for_env(cartpole(), pooled_config, device="cpu").pool == 1
    with pytest.raises(ValueError, match=r"encoded at \(3, 16, 16\).*encoder_size=16"):
        CuriosityModel.for_env(cartpole(), dataclasses.replace(TINY, encoder_size=16))
    with pytest.raises(ValueError, match=r"encoder_size=0 must be None or an int >= 1"):
        dataclasses.replace(TINY, encoder_size=0)
