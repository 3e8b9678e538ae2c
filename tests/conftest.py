"""Fixtures shared by several test modules."""

import os
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest

TESTS = Path(__file__).parent
PYTHONPATH = [part for part in os.environ.get("PYTHONPATH", "").split(os.pathsep) if part]


@pytest.fixture
def small_ppo() -> Callable[..., Any]:
    """A factory: a small, seeded Stable-Baselines3 ``CnnPolicy`` PPO on ``env`` (64-step
    rollouts, one epoch, a 32-unit NatureCNN head, cpu; keyword arguments replace these), for
    short runs through a wrapper. Imports SB3 only when used (it is an optional extra)."""

    def build(env: Any, **overrides: Any) -> Any:
        import stable_baselines3 as sb3

        settings = {
            "n_steps": 64,
            "batch_size": 32,
            "n_epochs": 1,
            "policy_kwargs": {"features_extractor_kwargs": {"features_dim": 32}},
            "device": "cpu",
            "seed": 0,
        }
        return sb3.PPO("CnnPolicy", env, **{**settings, **overrides})

    return build


@pytest.fixture(scope="module")
def ray_address() -> Iterator[str]:
    """One local Ray instance for the module (each study or sweep would otherwise start its
    own); its address. Imports Ray only when used (the lab extra)."""
    import ray

    # at pytest's own priority: Ray's default (nice 15 above it) starves the trials whenever
    # anything else runs, and a suite under load then waits on them for tens of minutes
    ray.init(
        address="local",
        num_cpus=2,
        include_dashboard=False,
        log_to_driver=False,
        _system_config={"worker_niceness": 0},
        # the workers import the tests' own env modules (broken_envs) as the tests do
        runtime_env={"env_vars": {"PYTHONPATH": os.pathsep.join([str(TESTS), *PYTHONPATH])}},
    )
    yield ray.get_runtime_context().gcs_address
    ray.shutdown()
