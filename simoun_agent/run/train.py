"""The training loop behind ``simoun-train`` (:mod:`simoun_agent.cli.train`): train the Simoun
agent on any pixel or renderable Gymnasium env.

    simoun-train --env dm_control/cartpole-swingup-v0 --preset cpu
    simoun-train --preset walker-walk --agent.encoder dual --agent.curiosity false
    simoun-train --resume runs/cartpole-swingup-cpu-s1-20260101-120000

A run directory holds ``config.json`` (the resolved config, written once set-up has
succeeded), ``eval.csv`` / ``train.csv`` / ``tb/`` (logs), ``learning_curve.png`` (redrawn at
each evaluation), ``checkpoint.pt`` + ``replay-<step>.npz`` (the latest checkpoint),
``video.mp4`` (an evaluation episode) and ``summary.json`` (written only when the run ends);
the names live in :mod:`simoun_agent.run.layout`.
Episodes and every random stream come from the run's seed (:mod:`simoun_agent.run.seeds`).

Ctrl-C or SIGTERM (a scheduler's preemption, ``kill``), in any phase (warm-up, training, an
evaluation, the final video), is acknowledged at once on stderr; the run finishes its step (an
evaluation is abandoned, and runs again on resume), writes a checkpoint atomically, prints how
to resume and exits with status **130** after Ctrl-C or **143** after SIGTERM (128 + the signal
number); a second signal stops at once (:mod:`simoun_agent.run.signals`). ``--resume``
continues. During set-up there is nothing to save: a signal stops it at once. One trainer at a
time holds a run directory (:mod:`simoun_agent.run.rundir`); ``--overwrite`` starts over a run
that stopped before its first checkpoint.

Other ends of a run that keep a checkpoint to resume from: a non-finite reward from the env,
in training or in an evaluation, stops it (exit 1) with a checkpoint from before that step,
naming the step, the value and the env; a NaN or infinite loss (or intrinsic reward) of the
updates stops it (exit 1) naming them, keeping the checkpoint from before; a full disk is the
rule of :data:`CHECKPOINT_TRIES` (exit 75).
"""

from __future__ import annotations

import contextlib
import functools
import json
import math
import os
import random
import signal
import time
import warnings
import zipfile
from collections.abc import Callable, Iterator, Sequence
from dataclasses import asdict, replace
from datetime import datetime, timezone
from pathlib import Path
from typing import Any, NoReturn

import gymnasium as gym
import numpy as np
import torch

from simoun_agent import SimounAgent
from simoun_agent.config import SetupError, TrainConfig, from_dict, to_dict
from simoun_agent.config.envs import PAPER_ACTION_REPEAT, dmc_task, env_label, split_env_id
from simoun_agent.config.train import RESUMABLE_FIELDS, check_train_config
from simoun_agent.replay import FrameReplay
from simoun_agent.run.arguments import (
    asked_signal,
    call_hook,
    check_callbacks,
    check_config_arg,
    check_config_check,
    check_metrics,
    check_run_arg,
)
from simoun_agent.run.atomic import NO_SPACE_EXIT, atomic_write
from simoun_agent.run.callback import TrainCallback
from simoun_agent.run.checkpoint import (
    SPACE_ERRNOS,
    NoSpace,
    check_config,
    check_replay_mark,
    check_seed_scheme,
    load_checkpoint,
    remove_leftovers,
    restore_rng,
    save_checkpoint,
)
from simoun_agent.run.env_runner import EnvRunner, make_runner
from simoun_agent.run.evaluate import EvaluationStopped, NonFiniteReward, evaluate, metrics_json
from simoun_agent.run.kept import (
    Damaged,
    binary_problem,
    broken_link,
    kind_problem,
    packed_problem,
    present,
    read_text,
    summary_problem,
)
from simoun_agent.run.layout import (
    CHECKPOINT_NAME,
    CONFIG_NAME,
    CURVE_PNG,
    EVAL_CSV,
    SUMMARY_NAME,
    TRAIN_CSV,
    VIDEO_NAME,
)
from simoun_agent.run.logger import RunLogger, damaged_log, read_log
from simoun_agent.run.make_env import check_decisions, episode_limit, make_env, video_fps
from simoun_agent.run.progress import Progress
from simoun_agent.run.rundir import (
    check_run_dir,
    folder_kind,
    make_output_dir,
    not_a_simoun_run,
    study_of,
    study_run_refusal,
    take_run_dir,
)
from simoun_agent.run.seeds import Stream, first_eval_seed, int_seed, stream, train_episode_seed
from simoun_agent.run.signals import Stopped, deferred_stop
from simoun_agent.run.state import Counters, Run
from simoun_agent.run.video import write_video
from simoun_wrappers._checks import check_bool, check_path, is_int

ConfigCheck = Callable[[TrainConfig], object]
"""A check of the optional parts on a run's config, run before any env is built; raises
SetupError (e.g. :func:`simoun_agent.generalization.check_eval_distractions`)."""

CHECKPOINT_TRIES = 3
"""A checkpoint that does not fit on the disk (:class:`~simoun_agent.run.checkpoint.NoSpace`)
leaves the previous one intact and training goes on, to try again at the next checkpoint: space
freed meanwhile saves all the work. After this many failures in a row, or when the checkpoint of
a stop or of the run's end fails, the run stops with :data:`NO_SPACE_EXIT` (training on would
only add work that cannot be saved) and ``--resume`` continues from the last checkpoint. A log
write that fails for lack of space stops it the same way."""


class TrainingError(RuntimeError):
    """The run stopped for a reason the user must fix (a NaN reward, a full disk), after writing
    what could be written; ``simoun-train`` prints the message and exits with ``exit_code``."""

    def __init__(self, message: str, exit_code: int) -> None:
        super().__init__(message)
        self.exit_code = exit_code

    def __reduce__(self) -> tuple:
        # Ray copies a trial's exception to report it: rebuild it with its exit code
        return type(self), (str(self), self.exit_code)


def default_run_dir(config: TrainConfig) -> Path:
    """``runs/<task>-<preset>-s<seed>-<UTC time>``, e.g. ``runs/cartpole-swingup-cpu-s1-...``."""
    stamp = datetime.now(timezone.utc).strftime("%Y%m%d-%H%M%S")
    return (
        Path("runs")
        / f"{env_label(config.env)}-{config.preset or 'default'}-s{config.seed}-{stamp}"
    )


def build(
    config: TrainConfig, check: ConfigCheck | None = None
) -> tuple[EnvRunner, gym.Env, SimounAgent, FrameReplay]:
    """The training env's runner (in this process or a background one), the evaluation env,
    the agent and an empty replay; each random stream seeded from its child of the run's
    ``SeedSequence`` (:mod:`simoun_agent.run.seeds`). ``check(config)`` runs first, after
    the config's own rules (checked again: it may have been changed since it was built)."""
    check_config_rules(config)
    seed = config.seed
    if config.torch_threads:
        torch.set_num_threads(config.torch_threads)
    random.seed(int_seed(seed, Stream.GLOBAL))
    np.random.seed(int_seed(seed, Stream.GLOBAL))  # noqa: NPY002  (for libraries that draw from it)
    if check is not None:
        check(config)
    env, eval_env = make_runner(config), make_env(config)
    train_space_seed, eval_space_seed = stream(seed, Stream.ACTION_SPACES).generate_state(2)
    env.action_space.seed(int(train_space_seed))
    eval_env.action_space.seed(int(eval_space_seed))
    frame_shape = env.observation_space["frames"].shape[1:]
    action_dim = env.action_space.shape[0]
    torch.manual_seed(int_seed(seed, Stream.NETWORK_INIT))
    agent = SimounAgent(frame_shape, action_dim, config.agent, device=config.device)
    torch.manual_seed(int_seed(seed, Stream.TORCH))
    replay = FrameReplay(
        config.replay_capacity,
        frame_shape,
        action_dim,
        num_frames=config.agent.num_frames,
        seed=int_seed(seed, Stream.REPLAY),
    )
    return env, eval_env, agent, replay


def check_config_rules(config: TrainConfig) -> None:
    """The config's own rules (:func:`check_train_config`) as a SetupError: a field changed
    after the config was built (``config.total_env_steps = 0``) is named as the field."""
    try:
        check_train_config(config)
    except ValueError as err:
        raise SetupError(str(err)) from None


def create_run(
    config: TrainConfig, overwrite: bool = False, check: ConfigCheck | None = None
) -> Run:
    """Set up a new run; the run directory gets ``config.json`` only once all of it worked.

    ``overwrite`` starts over in a directory whose run stopped before its first checkpoint;
    ``check(config)`` (:data:`ConfigCheck`) runs before any env is built.
    """
    check_config_arg(config, "create_run")
    check_bool(overwrite, "create_run(overwrite=...)")
    check_config_check(check, "create_run")
    if config.run_dir:
        check_path(config.run_dir, "TrainConfig.run_dir", "run_dir='runs/my-run'")
        config.run_dir = os.fspath(config.run_dir)  # a Path set after the config was built
    run_dir = Path(config.run_dir) if config.run_dir else default_run_dir(config)
    if run_dir.is_dir():  # fail fast, before the envs are built: another trainer, an old run
        check_run_dir(run_dir, overwrite=overwrite)
    check_config_rules(config)
    check_budget(config)
    env, eval_env, agent, replay = build(config, check)
    try:
        check_decisions(config, episode_limit(eval_env))
    except SetupError:
        env.close()
        eval_env.close()
        raise
    make_output_dir(run_dir, "--run-dir")
    lock = take_run_dir(run_dir, overwrite=overwrite)
    rng = np.random.default_rng(stream(config.seed, Stream.WARMUP_ACTIONS))
    run = Run(config, run_dir, env, eval_env, agent, replay, rng, Counters(), lock)
    with closed_on_error(run):
        remove_leftovers(run_dir)
        config.run_dir = str(run_dir)
        write_config(run_dir, config)
    return run


@contextlib.contextmanager
def closed_on_error(run: Run) -> Iterator[None]:
    """Close ``run`` (its envs and its directory's lock) when its set-up fails after taking
    the directory, so that a second try in this process is not refused as a live run's."""
    try:
        yield
    except BaseException:
        run.close()
        raise


def check_budget(config: TrainConfig) -> None:
    """SetupError when one agent decision (``action_repeat`` env steps) is longer than the
    whole run: the run would take that one decision, overrun ``total_env_steps`` and learn
    nothing."""
    total = config.total_env_steps
    if not (is_int(total) and total >= 1):  # the advice below needs a budget to divide
        raise SetupError(
            f"--total-env-steps {total!r} (TrainConfig.total_env_steps) must be an int >= 1, "
            "the env steps the run trains for; e.g. --total-env-steps 100000"
        )
    repeat = config.resolved_action_repeat()
    if repeat <= config.total_env_steps:
        return
    if config.action_repeat is not None:
        given = ""
    elif dmc_task(config.env) in PAPER_ACTION_REPEAT:
        given = ", the paper's value for this task"
    else:
        given = ", the default"
    raise SetupError(
        f"--action-repeat {repeat} (TrainConfig.action_repeat{given}) is longer than the whole "
        f"run (--total-env-steps {config.total_env_steps}, TrainConfig.total_env_steps): each "
        f"agent decision takes {repeat} env steps, so the run would take one decision and "
        f"overrun its budget; set --action-repeat {config.total_env_steps} or less, or "
        f"--total-env-steps many times {repeat}"
    )


class UntrainedRunWarning(UserWarning):
    """A run whose warm-up (or batch size) takes all its agent decisions: it ends before its
    first update, and its agent is the untrained one it started with."""


def budget_warning(config: TrainConfig) -> str | None:
    """A warning when the warm-up, or the first batch, takes every agent decision of the run,
    so that it ends before its first update; else None."""
    repeat = config.resolved_action_repeat()
    decisions = config.total_env_steps // repeat
    batch = config.agent.batch_size
    if decisions == 0 or max(config.warmup_agent_steps, batch) < decisions:
        return None  # no decision at all: check_budget refuses
    run = f"the run's {decisions} agent decisions (--total-env-steps {config.total_env_steps} at "
    run += f"action repeat {repeat})"
    if config.warmup_agent_steps >= decisions:
        cause = f"--warmup-agent-steps {config.warmup_agent_steps} takes all {run}"
        fix = f"lower --warmup-agent-steps (TrainConfig.warmup_agent_steps) below {decisions}"
    else:
        cause = (
            f"--agent.batch-size {batch}: the first update needs that many stored transitions, "
            f"more than {run} give"
        )
        fix = f"lower --agent.batch-size (AgentConfig.batch_size) below {decisions}"
    return (
        f"{cause}: it ends before its first update and the agent learns nothing (its "
        f'summary.json says "trained": false); {fix}, or raise --total-env-steps '
        "(TrainConfig.total_env_steps)"
    )


def warn_if_untrained(run: Run) -> None:
    """Warn (:class:`UntrainedRunWarning`) when ``run`` has not updated yet and will not before
    its end: its final metrics would read as a trained agent's."""
    message = budget_warning(run.config)
    if message and run.counters.updates == 0:
        warnings.warn(message, UntrainedRunWarning, stacklevel=3)


def write_config(run_dir: Path, config: TrainConfig) -> None:
    text = json.dumps(to_dict(config), indent=2) + "\n"
    atomic_write(run_dir / CONFIG_NAME, lambda tmp: tmp.write_text(text))


def not_a_file(path: Path) -> SetupError:
    """The error for a kept file of a run that is a directory (or another thing, not a file)."""
    return SetupError(
        f"{path} is not a file; move it aside (mv {path} {path}.damaged), restore the file "
        "from a copy, and resume again"
    )


def damaged_config(path: Path, problem: str) -> SetupError:
    """The error for a run's damaged ``config.json`` or ``summary.json``: nothing was changed,
    and the file comes back from a copy."""
    return SetupError(
        f"{path} is damaged: {problem}. Nothing in the run was changed. Restore the file from a "
        "copy (simoun-train writes UTF-8 JSON), or start a new run"
    )


def changes(saved: Any, key: str, value: Any, run_dir: Path) -> bool:
    """Whether the override ``key``: ``value`` of a resumed run changes a fixed key of its
    ``saved`` config (``config.json`` as read); a key given its saved value changes nothing,
    and ``run_dir`` is the same directory however it is spelled."""
    if key in RESUMABLE_FIELDS:
        return False
    kept = saved
    for part in key.split("."):
        if not isinstance(kept, dict) or part not in kept:
            return True
        kept = kept[part]
    if key == "run_dir" and isinstance(value, str) and isinstance(kept, str):
        return Path(value).resolve() != run_dir.resolve()
    return json.dumps(value, sort_keys=True, default=str) != json.dumps(
        kept, sort_keys=True, default=str
    )


def saved_spellings(saved: Any, overrides: dict[str, Any]) -> dict[str, Any]:
    """``overrides`` less the values that are the ``saved`` run's own, spelled another way:
    ``--env MODULE:ID`` of the run's ID (its module the run's ``env_module``, or one the run
    did without), an ``--env-module`` equal to the run's, and an ``--action-repeat`` equal to
    the one the run resolved (a dm_control task's paper value when it saved none)."""
    if not isinstance(saved, dict):
        return overrides
    kept = dict(overrides)
    env = kept.get("env")
    if isinstance(env, str):
        module, env_id = split_env_id(env)
        if module and env_id == saved.get("env") and saved.get("env_module") in (None, module):
            del kept["env"]
    if "env_module" in kept and kept["env_module"] == saved.get("env_module"):
        del kept["env_module"]
    repeat = kept.get("action_repeat")
    if (
        repeat is not None
        and saved.get("action_repeat") is None
        and isinstance(saved.get("env"), str)
    ):
        if repeat == PAPER_ACTION_REPEAT.get(dmc_task(saved["env"]), 1):
            del kept["action_repeat"]
    return kept


def resume_run(run_dir: Path, overrides: dict[str, Any], check: ConfigCheck | None = None) -> Run:
    """Reload a run from its directory; ``overrides`` may only change resumable fields;
    ``check(config)`` (:data:`ConfigCheck`) runs before any env is built."""
    check_path(run_dir, "resume_run(run_dir=...)", "resume_run('runs/my-run', {})")
    if not isinstance(overrides, dict):
        raise TypeError(
            f"resume_run(overrides=...) must be a dict of config keys, got "
            f"{type(overrides).__name__} {overrides!r:.60}; e.g. {{'total_env_steps': 200000}}, "
            "or {} to resume as saved"
        )
    check_config_check(check, "resume_run")
    run_dir = Path(run_dir)
    config_path = run_dir / CONFIG_NAME
    if not run_dir.is_dir():
        why = "is a file, not a directory" if run_dir.exists() else "does not exist"
        raise SetupError(
            f"--resume {run_dir} {why}; pass the directory that simoun-train created (its "
            "path is printed as 'run directory: ...' when a run starts)"
        )
    check_packed_files(run_dir)
    if foreign := not_a_simoun_run(run_dir, "--resume"):
        raise foreign
    study = study_of(run_dir)
    if study is not None and not present(run_dir / CHECKPOINT_NAME):  # nothing written there
        raise study_run_refusal(run_dir, study)
    for name in (CONFIG_NAME, EVAL_CSV, TRAIN_CSV, SUMMARY_NAME):  # before anything is changed
        path = run_dir / name
        if path.exists() and not path.is_file():
            raise not_a_file(path)
        problem = broken_link(path)
        if problem and name in (EVAL_CSV, TRAIN_CSV):
            raise damaged_log(path, problem)
        if problem:
            raise damaged_config(path, problem)
    if not config_path.is_file() and (kind := folder_kind(run_dir)) is not None:
        raise SetupError(
            f"--resume {run_dir} is {kind}, not a run directory; pass the directory of one of "
            "its runs that holds checkpoint.pt"
        )
    if not config_path.is_file():
        raise SetupError(
            f"{run_dir} is not a simoun run directory (no {CONFIG_NAME}); pass the directory "
            "that simoun-train created"
        )
    try:
        saved = json.loads(read_text(config_path))
    except (Damaged, json.JSONDecodeError) as err:
        raise damaged_config(config_path, str(err)) from None
    if isinstance(saved, dict) and (problem := kind_problem(CONFIG_NAME, list(saved))):
        raise damaged_config(config_path, problem)
    overrides = saved_spellings(saved, overrides)
    fixed = [key for key, value in overrides.items() if changes(saved, key, value, run_dir)]
    if fixed:
        raise SetupError(
            f"a resumed run keeps its config; only {', '.join(RESUMABLE_FIELDS)} may change, "
            f"but {', '.join(fixed)} was given another value than the run's. Drop it, or start a "
            "new run to change it."
        )
    # the saved device need not exist here when another is given: a run trained on a GPU goes
    # on with --device cpu (the given one is checked below, as a flag)
    config = from_dict(
        {**saved, "device": None} if "device" in overrides else saved, str(config_path)
    )
    as_saved = to_dict(config)
    for log in (EVAL_CSV, TRAIN_CSV):
        if (run_dir / log).exists():
            read_log(run_dir / log)
    for key, value in overrides.items():
        setattr(config, key, value)
    try:  # a resumed run's new values keep their fields' rules, as a new run's do
        check_train_config(config)
    except ValueError as err:
        raise SetupError(str(err)) from None
    config.run_dir = str(run_dir)
    check_run_dir(run_dir, resume=True)  # fail fast; held from the end of set-up on
    payload = load_checkpoint(run_dir)
    check_seed_scheme(payload, run_dir)
    check_config(payload, as_saved, run_dir, saved=config_path)
    check_config(payload, to_dict(config), run_dir)
    done = payload["state"]["env_step"]
    check_logs_reach(run_dir, payload["state"])
    finished = (run_dir / SUMMARY_NAME).exists()
    if finished and config.total_env_steps == done:
        check_end_mark(run_dir / SUMMARY_NAME)
    # At its last step without summary.json, a run stopped in its final evaluation or video.
    if config.total_env_steps < done or (config.total_env_steps == done and finished):
        is_finished = " and is finished" if finished else ""
        raise SetupError(
            f"--total-env-steps {config.total_env_steps}: this run is at env step {done}"
            f"{is_finished}, so there is nothing to continue; pass a larger --total-env-steps "
            f"(e.g. --total-env-steps {done + config.eval_every}) to train it further"
        )
    if not payload["replay_path"].is_file():
        raise SetupError(missing_replay(payload["replay_path"]))
    env, eval_env, agent, empty = build(config, check)
    try:
        agent.load_state_dict(payload["agent"])
    except (RuntimeError, KeyError, ValueError) as err:
        raise SetupError(
            f"the checkpoint in {run_dir} does not fit this agent ({type(err).__name__}: "
            f"{err}); start a new run"
        ) from None
    try:
        replay = FrameReplay.load(payload["replay_path"])
    except (KeyError, ValueError, OSError, EOFError, zipfile.BadZipFile) as err:
        problem = binary_problem(payload["replay_path"])
        if problem.startswith("it cannot be read"):
            problem += f": {type(err).__name__}: {err}"
        raise SetupError(
            f"{payload['replay_path']} (the replay of the checkpoint) is damaged: {problem}; the "
            "run cannot continue exactly. Restore it from a copy, or start a new run"
        ) from None
    shapes = ("capacity", "frame_shape", "action_dim", "num_frames")
    differ = [key for key in shapes if getattr(replay, key) != getattr(empty, key)]
    if differ:
        found = "; ".join(
            f"{key} {getattr(replay, key)} in the file, {getattr(empty, key)} in the run's config"
            for key in differ
        )
        raise SetupError(
            f"{payload['replay_path']} (the replay of the checkpoint) is damaged: it holds another "
            f"run's transitions ({found}), so it was copied from another run. Restore this run's "
            "own replay and checkpoint from a copy, or start a new run"
        )
    check_replay_mark(payload, replay)
    restore_rng(payload["rng"])
    rng = np.random.default_rng()
    rng.bit_generator.state = payload["state"]["trainer_rng"]
    counters = Counters(**payload["state"]["counters"])
    lock = take_run_dir(run_dir, resume=True)
    run = Run(config, run_dir, env, eval_env, agent, replay, rng, counters, lock)
    with closed_on_error(run):
        remove_leftovers(run_dir, payload["replay_file"])
        # trained further, the run is whole again only when it reaches its new end
        (run_dir / SUMMARY_NAME).unlink(missing_ok=True)
        write_config(run_dir, config)
    return run


def check_end_mark(path: Path) -> None:
    """SetupError for a run's damaged ``summary.json`` (:func:`summary_problem`), the mark that
    the run ended, when a resume would rely on it to call the run finished."""
    problem = summary_problem(path)
    if problem:
        raise SetupError(
            f"{path} is damaged: {problem}, so it cannot say whether the run ended. Remove it "
            f"(rm {path}) and resume again: the run's end is written again from its checkpoint "
            "and last evaluation, without training; or restore the file from a copy"
        )


def missing_replay(path: Path) -> str:
    """The refusal for the checkpoint's replay missing at ``path``: where a compressed copy
    lies beside it (the replay packed by hand to save space), the command that unpacks it."""
    packed = packed_problem(path, " (the replay of the checkpoint)")
    if packed is not None:
        return f"{packed} and resume again; the run reads the replay as it was saved"
    return (
        f"{path} (the replay of the checkpoint) is missing; the run cannot continue exactly. "
        "Restore it from a copy, or start a new run."
    )


def check_packed_files(run_dir: Path) -> None:
    """Refuse a resumed run whose config.json or a log is missing while a compressed copy lies
    beside it: the run would go on with a new log from its checkpoint (the rows before lost for
    good) or be taken for no run, where unpacking the file lets it resume whole."""
    for name in (CONFIG_NAME, EVAL_CSV, TRAIN_CSV, CHECKPOINT_NAME):
        packed = packed_problem(run_dir / name)
        if packed is not None:
            raise SetupError(f"{packed} and resume again. Nothing in the run was changed")


def check_logs_reach(run_dir: Path, state: dict[str, Any]) -> None:
    """Refuse a log that ends before the last row the checkpoint had logged (``state``'s
    ``logged``): a copy older than the checkpoint, whose missing rows the resumed run would
    never write again. A log moved aside is started anew, as :func:`damaged_log` says."""
    done = state["env_step"]
    for name, logged in state.get("logged", {}).items():
        path = run_dir / name
        if logged is None or not path.is_file():
            continue
        steps = [int(row["env_step"]) for row in read_log(path)[1]]
        last = max((step for step in steps if step <= done), default=None)
        if last is not None and last >= logged:
            continue
        ends = "holds no row" if last is None else f"ends at env step {last}"
        raise SetupError(
            f"{path} {ends}, but the checkpoint (env step {done}) had logged rows up to env "
            f"step {logged}: the file is an older copy or was cut short, and the rows in between "
            f"would be lost for good. Nothing in the run was changed. Restore the newer {name} "
            f"from a copy; or, to go on without those rows, move it aside (mv {path} "
            f"{path}.old) and resume again: the run writes a new {name} from env step {done}"
        )


def checkpoint(run: Run, logged: dict[str, int | None] | None = None) -> None:
    """Write the run's checkpoint (raises :class:`~simoun_agent.run.checkpoint.NoSpace`);
    ``logged``: the env step of each log's last row (:meth:`RunLogger.last_steps`), which a
    resumed run checks its logs against."""
    state = {
        "env_step": run.counters.env_step,
        "counters": asdict(run.counters),
        "trainer_rng": run.rng.bit_generator.state,
    }
    if logged is not None:
        state["logged"] = logged
    save_checkpoint(
        run.run_dir,
        config=to_dict(run.config),
        agent=run.agent,
        replay=run.replay,
        state=state,
    )


class WallClock:
    """Seconds of training-loop time, continuing from what a resumed run had already spent."""

    def __init__(self, already: float) -> None:
        self.already = already
        self.start = time.perf_counter()

    def total(self) -> float:
        return self.already + time.perf_counter() - self.start


class Trainer:
    """One call of :func:`train`: the run and what the loop keeps beside it (callbacks, logs,
    progress display, clock, the checkpoint rule's count)."""

    def __init__(self, run: Run, callbacks: Sequence[TrainCallback]) -> None:
        config, counters = run.config, run.counters
        self.run, self.callbacks = run, list(callbacks)
        self.clock = WallClock(counters.wall_time_s)
        title = f"{config.env} ({config.preset or 'default'} preset, seed {config.seed})"
        self.logger = RunLogger(run.run_dir, title, resume_step=counters.env_step or None)
        label = title.split(" ")[0]
        self.progress = Progress(config.total_env_steps, counters.env_step, label, config.progress)
        self.phase = self.step_phase()
        """what the run is doing, for the message of a stop"""
        self.saved: Counters | None = None
        """the counters of the latest checkpoint this trainer wrote (a state saved already is
        not written again: a stop right after a checkpoint, or in the final video)"""
        on_disk = (run.run_dir / CHECKPOINT_NAME).exists()  # a resumed run's
        self.last_saved_step = counters.env_step if on_disk else None
        """env step of the latest checkpoint on disk (None before the first)"""
        self.failed_checkpoints = 0
        """checkpoints in a row that did not fit (:data:`CHECKPOINT_TRIES`)"""
        run.stop.sources = [functools.partial(asked_signal, c, run) for c in self.callbacks]

    def evaluate(self, what: str = "an evaluation") -> dict[str, float]:
        """Evaluate the agent, let the callbacks see (and extend) the metrics, log them. A stop
        abandons it (:class:`EvaluationStopped`): nothing is logged, and ``eval_pending`` stays
        set in the checkpoint, so the resumed run plays it."""
        run, config, counters = self.run, self.run.config, self.run.counters
        self.phase = f"{what} (abandoned: it runs first on resume)"
        counters.eval_pending = True
        self.progress.evaluation_start(counters.env_step, config.eval_episodes)
        try:
            metrics, _ = evaluate(
                run.agent,
                run.eval_env,
                config.eval_episodes,
                first_eval_seed(config.seed),
                on_episode=self.progress.evaluation_episode,
                stop=run.stop.is_set,
            )
        except NonFiniteReward as err:
            # the agent is sound (the env's reward is not): save it, the evaluation still
            # pending, so a resume after the env is fixed plays this evaluation first
            self.checkpoint(required=f"before the evaluation at env step {counters.env_step}")
            raise TrainingError(
                f"{run.config.env}: {err}. Stopped at env step {counters.env_step} with a "
                f"checkpoint; once fixed, continue with: simoun-train --resume {run.run_dir}",
                1,
            ) from None
        for callback in self.callbacks:
            call_hook(callback, "on_evaluation", run, metrics)
            check_metrics(metrics, callback)
        counters.wall_time_s = self.clock.total()
        metrics["wall_time_s"] = counters.wall_time_s
        self.logger.evaluation(counters.env_step, metrics)
        counters.eval_pending = False
        self.phase = self.step_phase()
        for callback in self.callbacks:
            call_hook(callback, "on_logged", run, metrics)
        self.progress.evaluated(counters.env_step, metrics)
        return metrics

    def step_phase(self) -> str:
        """The phase of the run's next step."""
        counters, config = self.run.counters, self.run.config
        return "the warm-up" if counters.agent_step < config.warmup_agent_steps else "training"

    def checkpoint(self, required: str | None = None) -> None:
        """Write the checkpoint unless this state is saved already. One that does not fit is
        the rule of :data:`CHECKPOINT_TRIES`: when it is ``required`` (for a stop, the run's end:
        the reason) or the last try, :class:`TrainingError` is raised, else training goes on."""
        counters = self.run.counters
        if self.saved == counters:
            return
        counters.wall_time_s = self.clock.total()
        try:
            checkpoint(self.run, self.logger.last_steps())
        except NoSpace as err:
            self.failed_checkpoints += 1
            if required:
                raise self.no_space(f"{err}; the checkpoint {required} failed") from None
            if self.failed_checkpoints >= CHECKPOINT_TRIES:
                failed = f"{CHECKPOINT_TRIES} checkpoints in a row failed"
                raise self.no_space(f"{err}; {failed}") from None
            self.progress.write(
                f"simoun-train: {err}. The checkpoint at env step {counters.env_step} failed and "
                f"the previous one is intact; training goes on and tries again at the next "
                f"checkpoint ({self.failed_checkpoints} of {CHECKPOINT_TRIES} failures in a row "
                "stop the run)"
            )
            return
        self.failed_checkpoints = 0
        self.saved = replace(counters)
        self.last_saved_step = counters.env_step

    def no_space(self, what: str) -> TrainingError:
        """The error that ends a run for lack of space, saying where it can resume from."""
        run_dir = self.run.run_dir
        if self.last_saved_step is None:
            then = f"no checkpoint was written: start over with --run-dir {run_dir} --overwrite"
        else:
            then = (
                f"the latest checkpoint (env step {self.last_saved_step}) is intact: free space, "
                f"then continue with: simoun-train --resume {run_dir}"
            )
        step = self.run.counters.env_step
        return TrainingError(f"{what}. Stopped at env step {step}; {then}", NO_SPACE_EXIT)

    def loop(self) -> None:
        """Steps, updates, evaluations and checkpoints up to the last env step or a stop."""
        run, config, counters = self.run, self.run.config, self.run.counters
        agent, replay, env = run.agent, run.replay, run.env
        repeat = config.resolved_action_repeat()
        action_dim = env.action_space.shape[0]
        learning_starts = max(config.warmup_agent_steps, config.agent.batch_size)
        if counters.eval_pending:
            self.evaluate("the initial evaluation" if counters.env_step == 0 else "an evaluation")
        next_eval = _next(counters, config.eval_every)
        next_checkpoint = _next(counters, config.checkpoint_every)
        update_metrics: dict[str, Any] = {}
        obs = None  # an episode starts at the top of the loop, so checkpoints fall between episodes
        while counters.env_step < config.total_env_steps and not run.stop.is_set():
            if obs is None:
                episode_seed = train_episode_seed(config.seed, counters.episode)
                obs = env.reset(seed=episode_seed)
                replay.start_episode(obs["frames"][-1])
                episode_return, episode_length, episode_start = 0.0, 0, time.perf_counter()
            self.phase = self.step_phase()
            if counters.agent_step < config.warmup_agent_steps:
                action = run.rng.uniform(-1.0, 1.0, action_dim).astype(np.float32)
            else:
                action = agent.act(obs["frames"], step=counters.env_step)
            # the environment steps (in a background process with env_process) while the agent
            # updates on the transitions before this one; both runners give the same results
            env.step_async(action)
            due = counters.agent_step % config.agent.update_every_steps == 0
            if counters.agent_step >= learning_starts and due:
                for _ in range(config.updates_per_step):
                    # Actor metrics come every actor_update_every updates: keep the latest of each.
                    update_metrics.update(agent.update(replay, counters.env_step + repeat))
                    counters.updates += 1
            obs, reward, terminated, truncated = env.step_wait()
            if not math.isfinite(reward):
                self.bad_reward(reward, episode_seed, episode_length)
            replay.add(action, reward, obs["frames"][-1], terminated, truncated)
            counters.agent_step += 1
            counters.env_step += repeat
            episode_return += float(reward)
            episode_length += 1
            self.progress.advance(repeat)

            if not (terminated or truncated):
                continue
            elapsed = time.perf_counter() - episode_start
            learned = {key: float(value) for key, value in update_metrics.items()}
            # read once an episode, where the values are synced for the log anyway
            if bad := {key: value for key, value in learned.items() if not math.isfinite(value)}:
                self.bad_update(bad)
            self.logger.train_episode(
                counters.env_step,
                {
                    "episode": counters.episode,
                    "return": episode_return,
                    "length": episode_length,
                    "env_steps_per_s": episode_length * repeat / elapsed,
                    **learned,
                },
            )
            counters.episode += 1
            if counters.env_step >= next_eval:
                self.evaluate()
                next_eval = _next(counters, config.eval_every)
            if counters.env_step >= next_checkpoint:
                self.checkpoint()
                next_checkpoint = _next(counters, config.checkpoint_every)
            self.progress.episode_end(episode_return)
            obs = None

    def bad_reward(self, reward: float, episode_seed: int, episode_length: int) -> NoReturn:
        """Stop with a checkpoint from before this step: a NaN would reach the Q targets and
        turn every weight NaN a few updates later."""
        run, counters = self.run, self.run.counters
        step = counters.env_step + run.config.resolved_action_repeat()
        self.checkpoint(required=f"before the non-finite reward at env step {step}")
        raise TrainingError(
            f"{run.config.env} returned the reward {reward} at env step {step} (step "
            f"{episode_length + 1} of training episode {counters.episode}, reset seed "
            f"{episode_seed}); rewards must be finite numbers. The run stopped with a checkpoint "
            f"at env step {counters.env_step}: fix the environment, then continue with: "
            f"simoun-train --resume {run.run_dir}",
            1,
        )

    def bad_update(self, bad: dict[str, float]) -> NoReturn:
        """Stop on a NaN or infinite loss (or intrinsic reward) of the updates: the weights it
        reached are no use, so the latest checkpoint, from before it, is kept, not overwritten."""
        run, step = self.run, self.run.counters.env_step
        values = ", ".join(f"{key} = {value}" for key, value in bad.items())
        if self.last_saved_step is None:
            then = f"no checkpoint was written yet: start over with --run-dir {run.run_dir}"
            then += " --overwrite"
        else:
            then = (
                f"the latest checkpoint (env step {self.last_saved_step}) is from before it: "
                f"simoun-train --resume {run.run_dir} continues from there"
            )
        raise TrainingError(
            f"the updates of the episode ending at env step {step} gave {values}: training "
            f"diverged (lower --agent.lr, or check the rewards' scale). Stopped; {then}",
            1,
        )

    def finish(self) -> dict[str, float]:
        """Final evaluation (unless the last one was at this step), checkpoint, video and
        ``summary.json``, the mark of a whole run; a run resumed here does only what is left."""
        run, config, counters = self.run, self.run.config, self.run.counters
        if counters.eval_pending or self.logger.last_eval_step != counters.env_step:
            self.evaluate("the final evaluation")
        final = self.logger.last_eval
        self.checkpoint(required="of the run's end")
        files = {"learning_curve": CURVE_PNG, "checkpoint": CHECKPOINT_NAME}
        if config.video:
            self.phase = "the final video (it is recorded on resume)"
            _, frames = evaluate(
                run.agent,
                run.eval_env,
                1,
                first_eval_seed(config.seed),
                record=True,
                stop=run.stop.is_set,
            )
            fps = video_fps(run.eval_env, config.resolved_action_repeat())
            write_video(run.run_dir / VIDEO_NAME, frames, fps)
            files["video"] = VIDEO_NAME
        summary = {
            "env_step": counters.env_step,
            "wall_time_s": counters.wall_time_s,
            "updates": counters.updates,
            "trained": counters.updates > 0,  # false: the final eval is of the initial agent
            "final_eval": final,
            "files": files,
        }
        text = metrics_json(summary)
        atomic_write(run.run_dir / SUMMARY_NAME, lambda tmp: tmp.write_text(text))
        return final

    def stopped(self) -> NoReturn:
        """Answer a stop: checkpoint, say how to resume, raise :class:`Stopped`."""
        run = self.run
        name = signal.Signals(run.stop.signum).name
        self.checkpoint(required=f"of the stop by {name}")
        self.progress.write(
            f"stopped by {name} during {self.phase} at env step "
            f"{run.counters.env_step}: checkpoint written; continue with: simoun-train --resume "
            f"{run.run_dir}"
        )
        raise Stopped(run.stop.signum)

    def close(self) -> None:
        self.progress.close()
        self.logger.close()


def train(run: Run, callbacks: Sequence[TrainCallback] = ()) -> dict[str, Any]:
    """The training loop; returns the final evaluation metrics.

    A stop (a first SIGINT/SIGTERM, a callback's ``stop_requested``) in any phase writes a
    checkpoint and raises :class:`Stopped`; a NaN reward or a full disk raises
    :class:`TrainingError` (see :data:`CHECKPOINT_TRIES`). The callbacks' ``on_start`` and
    ``on_end`` run whatever happens. The loop knows only the callbacks it is given: a config key
    that a callback carries out (:attr:`TrainCallback.serves`, such as ``eval_distraction``,
    served by :func:`simoun_agent.generalization.distraction_callbacks`) is refused without one.
    A run that ends before its first update (its warm-up takes every agent decision) warns with
    :class:`UntrainedRunWarning`, and its ``summary.json`` says ``"trained": false``.
    """
    check_run_arg(run, "train")
    check_callbacks(callbacks, "train")
    check_served(run.config, callbacks)
    warn_if_untrained(run)
    final = None
    # Entered after the envs were built, so a library that took the signals then (SDL) is found
    with deferred_stop(run.stop):
        trainer = Trainer(run, callbacks)
        try:
            for callback in trainer.callbacks:
                call_hook(callback, "on_start", run)
            try:
                trainer.loop()
                if not run.stop.is_set():
                    final = trainer.finish()
            except EvaluationStopped:
                pass
            if final is None:
                trainer.stopped()
            return final
        except OSError as err:  # a log, the learning curve, the video, summary.json
            if err.errno not in SPACE_ERRNOS:
                raise
            written = f" writing {Path(err.filename).name}" if err.filename else ""
            failed = f"no space left on {run.run_dir}: {err.strerror}{written}"
            raise trainer.no_space(failed) from None
        finally:
            trainer.close()
            release(run)
            end_callbacks(run, trainer.callbacks, final)


def check_served(config: TrainConfig, callbacks: Sequence[TrainCallback]) -> None:
    """Raise ValueError when ``config`` sets a key that only a callback carries out and none of
    ``callbacks`` serves it (the setting would be dropped silently)."""
    served = {key for callback in callbacks for key in callback.serves}
    if config.eval_distraction and "eval_distraction" not in served:
        raise ValueError(
            f"eval_distraction={list(config.eval_distraction)} needs a callback that plays the "
            "distracted episodes: pass simoun_agent.generalization.distraction_callbacks(config) "
            "to train()"
        )


def end_callbacks(
    run: Run, callbacks: Sequence[TrainCallback], final: dict[str, float] | None
) -> None:
    """Every callback's ``on_end``, even when an earlier one raises (each closes what it opened);
    the first error is raised after all have run."""
    error: BaseException | None = None
    for callback in callbacks:
        try:
            call_hook(callback, "on_end", run, final)
        except BaseException as err:  # re-raised below, once every callback has closed
            error = error or err
    if error is not None:
        raise error


def release(run: Run) -> None:
    """Let go of the run directory (the lock), once the run has written what it writes."""
    if run.lock is not None:
        run.lock.close()
        run.lock = None


def _next(counters: Counters, every: int) -> int:
    return (counters.env_step // every + 1) * every
