"""Wrapper misuse a new user runs into: each case is a clear error, never a
silently wrong observation. Headless import order and SDL's signal handlers."""

import os
import signal
import subprocess
import sys
import threading

import gymnasium as gym
import pytest
import shimmy
from gymnasium.error import ResetNeeded

from simoun_wrappers import FrameTriplet, RandomConvolution, SimounObservation

gym.register_envs(shimmy)


def cartpole_pixels() -> gym.Env:
    return gym.make("CartPole-v1", render_mode="rgb_array")


def test_simoun_observation_step_before_reset_raises_reset_needed():
    env = SimounObservation(cartpole_pixels(), size=32)
    with pytest.raises(ResetNeeded, match=r"call env\.reset"):
        env.step(env.action_space.sample())
    env.reset(seed=0)
    obs, *_ = env.step(env.action_space.sample())
    assert obs["frames"][0].any()


def test_simoun_observation_on_dm_control_step_before_reset_raises_reset_needed():
    env = gym.make(
        "dm_control/cartpole-swingup-v0",
        render_mode="rgb_array",
        render_kwargs={"width": 32, "height": 32, "camera_id": 0},
    )
    env = SimounObservation(env, size=32)
    with pytest.raises(ResetNeeded):
        env.step(env.action_space.sample())


def test_frame_triplet_over_an_already_reset_env_needs_its_own_reset():
    inner = gym.make("CartPole-v1")
    inner.reset(seed=0)  # the inner env can step, but the triplet has no frames yet
    env = FrameTriplet(inner)
    with pytest.raises(ResetNeeded, match="FrameTriplet"):
        env.step(0)


@pytest.mark.parametrize("fold_frames", [False, True])
def test_random_convolution_over_a_frame_stack_names_the_right_order(fold_frames):
    stacked = SimounObservation(cartpole_pixels(), size=32, fold_frames=fold_frames)
    with pytest.raises(TypeError, match=r"SimounObservation\(RandomConvolution\(env\)"):
        RandomConvolution(stacked)
    right = SimounObservation(RandomConvolution(cartpole_pixels()), size=32)
    obs, _ = right.reset(seed=0)
    assert obs["frames"].shape == (3, 3, 32, 32)


def test_aec_env_to_parallel_wrapper_names_aec_to_parallel():
    from pettingzoo.butterfly import pistonball_v6

    from simoun_wrappers.pettingzoo import SimounParallelObservation

    with pytest.raises(TypeError, match=r"ParallelEnv.*aec_to_parallel"):
        SimounParallelObservation(pistonball_v6.env(n_pistons=3), size=32)


def python_without(*names: str, code: str, **extra: str) -> subprocess.CompletedProcess:
    env = {k: v for k, v in os.environ.items() if k not in names}
    env.update(extra)
    return subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=120
    )


def test_dm_control_imported_first_without_mujoco_gl_warns_with_the_fix():
    names = ("MUJOCO_GL", "DISPLAY", "WAYLAND_DISPLAY")
    late = python_without(*names, code="import shimmy, simoun_wrappers")
    assert "export MUJOCO_GL=egl" in late.stderr, late.stderr
    assert "Import simoun_wrappers before shimmy" in late.stderr
    early = python_without(*names, code="import simoun_wrappers, shimmy")
    set_by_user = python_without(*names, code="import shimmy, simoun_wrappers", MUJOCO_GL="egl")
    for quiet in (early, set_by_user):
        assert quiet.returncode == 0, quiet.stderr
        assert "MUJOCO_GL" not in quiet.stderr


def default_signal_state() -> None:
    """The child starts as a shell would start it: no signal blocked, SIGTERM at its default.
    A blocked or ignored SIGTERM is inherited across exec, and in CI (one pytest-xdist worker
    that had run the Ray tests before) the child ignored SIGTERM for 300 s, though it dies at
    once when this test runs alone: the test is about SDL, not about the worker's state."""
    signal.pthread_sigmask(signal.SIG_SETMASK, [])
    signal.signal(signal.SIGTERM, signal.SIG_DFL)


def test_sdl_leaves_sigterm_to_python_after_highway_env_renders():
    """pygame/SDL installs a SIGTERM handler that turns the signal into an unread quit event
    unless SDL_NO_SIGNAL_HANDLERS is set; then a plain process ignores SIGTERM."""
    code = (
        "import sys, time, simoun_wrappers, gymnasium as gym, highway_env\n"
        "env = gym.make('highway-fast-v0', render_mode='rgb_array')\n"
        "env.reset(seed=0); env.render()\n"
        "print('ready', flush=True); time.sleep(900)\n"
    )
    env = {k: v for k, v in os.environ.items() if k != "SDL_NO_SIGNAL_HANDLERS"}
    proc = subprocess.Popen(
        [sys.executable, "-c", code],
        env=env,
        stdout=subprocess.PIPE,
        text=True,
        preexec_fn=default_signal_state,
    )
    # Generous limits for a loaded machine: a child that ignores SIGTERM sleeps past them and
    # fails the test; a silent child is killed by the watchdog instead of hanging the suite.
    watchdog = threading.Timer(600, proc.kill)
    watchdog.start()
    try:
        assert proc.stdout.readline().strip() == "ready"
        proc.send_signal(signal.SIGTERM)
        assert proc.wait(timeout=300) == -signal.SIGTERM
    finally:
        watchdog.cancel()
        proc.kill()
        proc.wait()


@pytest.mark.parametrize("option", ["grayscale", "motion", "fold_frames"])
def test_switches_given_as_strings_are_refused(option):
    with pytest.raises(TypeError, match=f"{option} must be True or False, got 'false'"):
        SimounObservation(cartpole_pixels(), size=32, **{option: "false"})
