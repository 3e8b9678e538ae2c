"""Reference drivers for highway-env runs, played through the agent's own evaluation.

A learned driver's return and driving measures mean little alone: highway-env pays at least 0.67
a decision for staying on the road, so even a car that never touches the controls scores. These
policies have the agent's ``act(frames, deterministic)`` signature, so
:func:`~simoun_agent.run.evaluate.evaluate` plays them on the same episodes, through the same
environment stack, with the same metric code (:mod:`simoun_agent.run.driving_metrics`):

- ``random``: uniform actions in [-1, 1]^2 (:class:`~simoun_agent.run.evaluate.RandomPolicy`);
- ``zero``: no acceleration, no steering: the car keeps its lane and its initial speed;
- ``lane-keeping``: :class:`LaneKeeper`, a scripted controller that reads the simulator's state.

    python -m simoun_agent.run.driving_reference --episodes 20 --seed 1000

prints their table on the ``highway-cpu`` preset, one episode per seed from ``--seed`` on;
``--video docs/driving/lane-keeping.gif`` also writes the lane-keeping driver's first episode as
the agent sees it (the frames ``simoun-eval --video`` writes for a learned driver);
``--json DIR/references.json`` also writes every driver's metrics with the command that measured
them, which a driving study's report (DIR: its study directory) shows beside the learned drivers.
"""

from __future__ import annotations

import difflib
import math
import shlex
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Protocol

import gymnasium as gym
import numpy as np

from simoun_agent import table
from simoun_agent.cli.flags import fail, parse
from simoun_agent.config import PRESETS, SetupError, TrainConfig, resolve
from simoun_agent.config.envs import is_highway
from simoun_agent.run.atomic import atomic_write
from simoun_agent.run.driving_metrics import columns
from simoun_agent.run.evaluate import RandomPolicy, evaluate, metrics_json
from simoun_agent.run.kept import Damaged, broken_link, not_a_file, present, read_json_object
from simoun_agent.run.make_env import make_env, video_fps
from simoun_agent.run.rundir import make_output_dir
from simoun_agent.run.video import write_video


class Policy(Protocol):
    def act(self, frames: np.ndarray, deterministic: bool = False) -> np.ndarray: ...


class ZeroPolicy:
    """Action 0 (no acceleration, no steering): highway-env's car keeps its speed and heading."""

    def __init__(self, action_dim: int) -> None:
        self.action_dim = action_dim

    def act(self, frames: np.ndarray, deterministic: bool = False) -> np.ndarray:
        return np.zeros(self.action_dim, dtype=np.float32)


class LaneKeeper:
    """A scripted driver on highway-env's state: PD steering on its lane's centre line and an
    IDM-like speed and gap control behind the car ahead; it never changes lane.

    It reads ``env.unwrapped`` (the ego vehicle, its lane, the car ahead in that lane), not the
    frames, and returns ``[acceleration, steering]`` in [-1, 1] scaled to the env's
    ``ContinuousAction`` ranges. The gains are for 5 decisions per second; the speed and gap
    terms are the Intelligent Driver Model's (Treiber et al. 2000).

    Example:
        >>> import highway_env, gymnasium as gym
        >>> env = gym.make("highway-fast-v0", config={"action": {"type": "ContinuousAction"}})
        >>> _ = env.reset(seed=0)
        >>> action = LaneKeeper(env).act(None)
        >>> action.shape, bool(np.all(np.abs(action) <= 1))
        ((2,), True)
    """

    def __init__(
        self,
        env: gym.Env,
        target_speed: float = 30.0,
        time_gap: float = 1.5,
        min_gap: float = 10.0,
        lateral_gain: float = 0.05,
        heading_gain: float = 0.8,
    ) -> None:
        """Args:
        env: the highway-env env (any wrapper of it) whose ego vehicle to drive.
        target_speed: the free-road speed in m/s; 30 is the top of the reward's speed range.
        time_gap: seconds of headway kept to the car ahead (IDM's T).
        min_gap: metres kept to a stopped car ahead (IDM's s0), counted between centres.
        lateral_gain: steering angle in rad per metre off the lane centre.
        heading_gain: steering angle in rad per rad of heading error to the lane.
        """
        self.env = env
        self.target_speed = target_speed
        self.time_gap = time_gap
        self.min_gap = min_gap
        self.lateral_gain = lateral_gain
        self.heading_gain = heading_gain

    def act(self, frames: np.ndarray | None, deterministic: bool = False) -> np.ndarray:
        base = self.env.unwrapped
        vehicle = base.vehicle
        lane = base.road.network.get_lane(vehicle.lane_index)
        longitudinal, lateral = lane.local_coordinates(vehicle.position)
        heading_error = (lane.heading_at(longitudinal) - vehicle.heading + math.pi) % (
            2 * math.pi
        ) - math.pi
        steering = -self.lateral_gain * lateral + self.heading_gain * heading_error
        acceleration = self._idm(base, vehicle)
        low_a, high_a = base.action_type.acceleration_range
        low_s, high_s = base.action_type.steering_range
        action = [
            2 * (acceleration - low_a) / (high_a - low_a) - 1,
            2 * (steering - low_s) / (high_s - low_s) - 1,
        ]
        return np.clip(np.asarray(action, dtype=np.float32), -1.0, 1.0)

    def _idm(self, base, vehicle) -> float:
        """IDM acceleration (m/s^2): free-road term, and the gap term when a car is ahead."""
        max_accel, comfort_brake = 3.0, 5.0
        speed = vehicle.speed
        acceleration = max_accel * (1 - (max(speed, 0.0) / self.target_speed) ** 4)
        ahead, _ = base.road.neighbour_vehicles(vehicle, vehicle.lane_index)
        if ahead is not None:
            gap = max(vehicle.lane_distance_to(ahead), 1e-3)
            closing = speed - ahead.speed
            braking = speed * closing / (2 * math.sqrt(max_accel * comfort_brake))
            wanted = self.min_gap + max(0.0, speed * self.time_gap + braking)
            acceleration -= max_accel * (wanted / gap) ** 2
        return acceleration


REFERENCES = ("random", "zero", "lane-keeping")


def reference_policy(name: str, env: gym.Env, seed: int) -> Policy:
    """The reference driver ``name`` (one of :data:`REFERENCES`) for ``env``."""
    if name == "random":
        return RandomPolicy(env.action_space.shape[0], seed)
    if name == "zero":
        return ZeroPolicy(env.action_space.shape[0])
    if name == "lane-keeping":
        return LaneKeeper(env)
    raise ValueError(f"unknown reference driver {name!r}; choose one of {', '.join(REFERENCES)}")


def reference_metrics(
    config: TrainConfig, episodes: int, seed: int, video: Path | None = None
) -> dict[str, dict]:
    """Each reference driver's evaluation metrics on ``episodes`` episodes seeded from ``seed``;
    with ``video``, the lane-keeping driver's first episode is written there (``.gif``/``.mp4``)."""
    env = make_env(config)
    try:
        metrics = {}
        for name in REFERENCES:
            record = video is not None and name == "lane-keeping"
            policy = reference_policy(name, env, seed)
            metrics[name], frames = evaluate(policy, env, episodes, seed, record=record)
            if record:
                write_video(video, frames, video_fps(env, config.resolved_action_repeat()))
        return metrics
    finally:
        env.close()


COLUMNS = columns(
    "return_mean",
    "return_std",
    "crash_rate",
    "distance_m",
    "mean_speed",
    "mean_abs_steer",
    "length_mean",
)
"""The table's columns: metric key, header, format."""


def markdown_table(metrics: dict[str, dict]) -> str:
    """One row per driver, the columns of :data:`COLUMNS`."""
    headers = ["driver"] + [header for _, header, _ in COLUMNS]
    rows = [
        [name] + [format(row[key], spec) for key, _, spec in COLUMNS]
        for name, row in metrics.items()
    ]
    return table.markdown_table(headers, rows)


@dataclass
class DrivingReferenceCommand:
    """What ``python -m simoun_agent.run.driving_reference`` is asked."""

    episodes: int = 20
    """episodes each driver plays"""
    seed: int = 1000
    """seed of the first episode (the others follow it)"""
    preset: str = "highway-cpu"
    """a highway-env preset: highway-cpu or highway"""
    video: Path | None = None
    """write the lane-keeping driver's first episode here (.gif or .mp4)"""
    json: Path | None = None
    """also write every driver's metrics here (.json), with this command, for a study's report
    (its study directory's references.json)"""


PROG = "python -m simoun_agent.run.driving_reference"

VIDEO_SUFFIXES = (".gif", ".mp4")


def check_output(flag: str, path: Path, what: str, suffixes: tuple[str, ...], example: str) -> None:
    """SetupError when ``path``, the value of ``flag``, has none of ``suffixes`` or its folder
    does not exist or cannot be written."""
    if path.suffix not in suffixes:
        raise SetupError(
            f"{flag} {path}: {what} is written as {' or '.join(suffixes)}, not "
            f"{path.suffix or 'a name without a suffix'}; e.g. {flag} {example}"
        )
    if not path.parent.is_dir():
        raise SetupError(
            f"{flag} {path}: the folder {path.parent} does not exist; create it or pass a path "
            "in an existing folder"
        )
    make_output_dir(path.parent, flag)


def highway_presets() -> list[str]:
    """The presets this command takes: those made for highway-env."""
    return [name for name, preset in PRESETS.items() if preset.envs == "highway"]


def close_preset(name: str) -> str:
    """`` (did you mean 'x'?)`` for the highway preset closest to ``name`` in any case, else
    ``""``."""
    by_lower = {preset.lower(): preset for preset in highway_presets()}
    hint = difflib.get_close_matches(name.lower(), by_lower, n=1)
    return f" (did you mean {by_lower[hint[0]]!r}?)" if hint else ""


def check_command(args: DrivingReferenceCommand) -> TrainConfig:
    """The preset's config, with every value of ``args`` checked before an episode is played;
    SetupError naming the flag and a value that works."""
    if args.episodes < 1:
        raise SetupError(f"--episodes must be 1 or more, got {args.episodes}; e.g. --episodes 20")
    if args.seed < 0:
        raise SetupError(f"--seed must be 0 or more, got {args.seed}; e.g. --seed 1000")
    highway = highway_presets()
    if args.preset not in PRESETS:
        raise SetupError(f"--preset {args.preset!r}: unknown preset{close_preset(args.preset)}; "
                         f"choose one of {', '.join(highway)}")  # fmt: skip
    config = resolve(args.preset, {"device": "cpu"})
    if not is_highway(config.env):
        raise SetupError(
            f"--preset {args.preset} trains on {config.env}, not highway-env: the reference "
            f"drivers steer a highway-env car; choose one of {', '.join(highway)}"
        )
    if args.video is not None:
        check_output("--video", args.video, "a video", VIDEO_SUFFIXES, "lane-keeping.gif")
    if args.json is not None:
        check_output("--json", args.json, "the metrics file", (".json",), "references.json")
        check_replaceable(args.json)
    return config


def written_here(path: Path) -> bool:
    """Whether ``path`` holds a references file this command wrote (its ``command`` and
    ``drivers``), which a new measurement may replace."""
    try:
        record = read_json_object(path)
    except (Damaged, OSError):
        return False
    command = record.get("command")
    return (
        isinstance(command, str)
        and command.startswith(PROG)
        and isinstance(record.get("drivers"), dict)
    )


def check_replaceable(path: Path) -> None:
    """SetupError when ``--json`` names something that is there and is not a references file
    this command wrote: a run's config.json, a study's files or a directory are never written
    over."""
    if not present(path) or written_here(path):
        return
    what = not_a_file(path) or broken_link(path) or "it is a file this command did not write"
    raise SetupError(
        f"--json {path}: {what}, so writing the metrics there would destroy it; pass a new "
        "path, e.g. --json references.json in the study directory, or move it aside"
    )


def references_json(args: DrivingReferenceCommand, command: str, metrics: dict) -> str:
    """The ``--json`` file's text: ``command``, the preset, episodes and first seed, and
    ``drivers`` (driver -> its metrics; a crash speed without crashes is null)."""
    record = {
        "command": command,
        "preset": args.preset,
        "episodes": args.episodes,
        "seed": args.seed,
        "drivers": metrics,
    }
    return metrics_json(record)


def main(argv: Sequence[str] | None = None) -> int:
    """Print the reference drivers' table."""
    args = parse(DrivingReferenceCommand, argv, PROG, "Reference drivers' metrics on highway-env.")
    try:
        config = check_command(args)
    except SetupError as err:
        fail(PROG, err)
    metrics = reference_metrics(config, args.episodes, args.seed, args.video)
    print(markdown_table(metrics))
    if args.json is not None:
        words = sys.argv[1:] if argv is None else list(argv)
        text = references_json(args, shlex.join([*PROG.split(), *words]), metrics)
        atomic_write(args.json, lambda tmp: tmp.write_text(text))
    return 0


if __name__ == "__main__":
    sys.exit(main())
