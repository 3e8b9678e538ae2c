"""Seeds: every stream of a run comes from one SeedSequence(seed), so runs of different
seeds share no training or evaluation episode start, and a run evaluates on the same episodes at
every evaluation, never on its training ones."""

import gymnasium as gym
import pytest
import torch
from test_train_resume import tiny_config

from simoun_agent.config import SetupError
from simoun_agent.envs import PointReach
from simoun_agent.run import train
from simoun_agent.run.checkpoint import CHECKPOINT_NAME
from simoun_agent.run.seeds import HALF, Stream, first_eval_seed, int_seed, train_episode_seed

RESETS: list[int | None] = []
"""Every reset seed that the SeedLog env of this module was given, in order."""


class ResetLog(gym.Wrapper, gym.utils.RecordConstructorArgs):
    """Append the seed of every ``reset`` to ``log``."""

    def __init__(self, env: gym.Env, log: list) -> None:
        gym.utils.RecordConstructorArgs.__init__(self)
        gym.Wrapper.__init__(self, env)
        self.log = log

    def reset(self, *, seed=None, options=None):
        self.log.append(seed)
        return super().reset(seed=seed, options=options)


SEED_LOG = "SimounTest/SeedLog-v0"
if SEED_LOG not in gym.registry:
    gym.register(
        SEED_LOG,
        entry_point=lambda render_mode=None: ResetLog(PointReach(render_mode=render_mode), RESETS),
    )


def test_seeds_1_to_5_share_no_training_or_evaluation_episode_start():
    starts = {
        seed: [train_episode_seed(seed, i) for i in range(1000)]
        + [first_eval_seed(seed) + i for i in range(100)]
        for seed in range(1, 6)
    }
    every = [start for seeds in starts.values() for start in seeds]
    assert len(set(every)) == len(every) == 5 * 1100
    for seeds in starts.values():
        assert all(0 <= s < HALF for s in seeds[:1000])  # training: the lower half
        assert all(HALF <= s < 2**32 for s in seeds[1000:])  # evaluation: the upper one
    # the streams of one run differ from each other too
    assert len({int_seed(1, stream) for stream in Stream}) == len(Stream)


def test_a_run_trains_on_its_training_seeds_and_evaluates_on_the_same_seeds_each_time(tmp_path):
    RESETS.clear()
    config = tiny_config(
        tmp_path / "run", env=SEED_LOG, total_env_steps=80, eval_every=40, eval_episodes=3
    )
    train.train(train.create_run(config))
    evaluation = [first_eval_seed(3) + i for i in range(3)]
    training = [train_episode_seed(3, i) for i in range(4)]  # 20-step episodes
    expected = [
        *evaluation,  # env step 0
        *training[:2],
        *evaluation,  # env step 40
        *training[2:],
        *evaluation,  # env step 80, the final one
    ]
    assert RESETS == expected


def test_a_run_from_before_the_seed_streams_is_refused_on_resume(tmp_path):
    run_dir = tmp_path / "old"
    train.train(train.create_run(tiny_config(run_dir, total_env_steps=20, warmup_agent_steps=10)))
    payload = torch.load(run_dir / CHECKPOINT_NAME, weights_only=False)
    del payload["seed_scheme"]  # what every checkpoint written before it lacks
    torch.save(payload, run_dir / CHECKPOINT_NAME)
    with pytest.raises(SetupError, match=r"before seed streams.*seed \+ i.*Start a new run"):
        train.resume_run(run_dir, {"total_env_steps": 40})
