"""The training environment stepped in a background process: the same run as in-process, and a
dead environment process reported instead of hung on."""

import time

import pytest
import torch
from test_train_resume import tiny_config, weights, without_wall_time

from simoun_agent.run import train
from simoun_agent.run.env_runner import BackgroundEnv, EnvProcessError
from simoun_agent.run.logger import read_csv


def test_background_env_process_gives_the_same_run_as_stepping_in_process(tmp_path):
    runs = {}
    for background in (False, True):
        run_dir = tmp_path / f"background-{background}"
        run = train.create_run(tiny_config(run_dir, env_process=background))
        assert isinstance(run.env, BackgroundEnv) == background
        try:
            train.train(run)
        finally:
            run.env.close()
            run.eval_env.close()
        runs[background] = run
    inline, background = weights(runs[False].agent), weights(runs[True].agent)
    assert [k for k in inline if not torch.equal(inline[k], background[k])] == []
    assert runs[False].counters == runs[True].counters
    curves = [
        [without_wall_time(row) for row in read_csv(tmp_path / f"background-{b}" / "eval.csv")]
        for b in (False, True)
    ]
    assert curves[0] == curves[1]


def test_a_dead_environment_process_is_reported_not_hung_on(tmp_path):
    runner = BackgroundEnv(tiny_config(tmp_path / "run"), timeout_s=20)
    try:
        runner.reset(seed=0)
        runner.vector.processes[0].kill()
        runner.vector.processes[0].join()
        start = time.perf_counter()
        with pytest.raises(EnvProcessError, match="--env-process false"):
            runner.step_async(runner.action_space.sample())
            runner.step_wait()
        assert time.perf_counter() - start < 20
    finally:
        runner.vector.close(terminate=True)
