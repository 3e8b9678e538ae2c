"""Play a reloaded run (:func:`simoun_agent.run.load.load_run`) deterministically."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import gymnasium as gym
import numpy as np
import torch

from simoun_agent.agent import SimounAgent
from simoun_agent.config import SetupError
from simoun_agent.models.encoder import PixelEncoder
from simoun_agent.run.evaluate import check_players
from simoun_agent.run.rundir import make_output_dir
from simoun_wrappers._checks import is_int


@dataclass
class Episode:
    """One deterministic episode of the agent."""

    seed: int
    """the reset seed"""
    observations: np.ndarray
    """(T + 1, k, C, H, W) uint8: entry s is the triplet after s decisions (0: the reset one)"""
    actions: np.ndarray
    """(T, action_dim) the actions taken"""
    rewards: np.ndarray
    """(T,) the rewards received"""

    @property
    def length(self) -> int:
        """Decisions taken (T)."""
        return len(self.actions)


def play_episode(agent: SimounAgent, env: gym.Env, seed: int) -> Episode:
    """One episode from ``reset(seed=seed)`` with deterministic actions."""
    example = "e.g. play_episode(run.agent, run.env, run.first_seed) for run = load_run(path)"
    check_players(agent, env, "play_episode", example)
    if not (is_int(seed) and seed >= 0):
        raise (ValueError if is_int(seed) else TypeError)(
            f"play_episode(seed=...) must be an int >= 0 (the episode's reset seed), got "
            f"{type(seed).__name__} {seed!r:.60}; {example}"
        )
    obs, _ = env.reset(seed=seed)
    observations, actions, rewards = [obs["frames"]], [], []
    done = False
    with torch.random.fork_rng():
        while not done:
            action = agent.act(obs["frames"], True)
            obs, reward, terminated, truncated, _ = env.step(action)
            observations.append(obs["frames"])
            actions.append(action)
            rewards.append(reward)
            done = terminated or truncated
    return Episode(seed, np.stack(observations), np.stack(actions), np.asarray(rewards, np.float64))


def prepare_output(out: Path, names: list[str], overwrite: bool, flag: str = "--out") -> None:
    """Create ``out``; refuse when it cannot be written, when it already holds one of ``names``
    (glob patterns) and ``overwrite`` is off, or when one of them is something else than a file
    (a directory), which the write after the work would fail on."""
    existing = (
        sorted(p.name for pattern in names for p in out.glob(pattern)) if out.is_dir() else []
    )
    if existing and not overwrite:
        shown = ", ".join(existing[:3]) + (" ..." if len(existing) > 3 else "")
        raise SetupError(
            f"{out} already holds results ({shown}); pass --overwrite to replace them, or "
            f"another {flag}"
        )
    make_output_dir(out, flag, names)


def check_encoder(encoder: object, function: str) -> None:
    """A TypeError naming ``function``'s ``encoder`` unless it is a PixelEncoder: an agent, or
    the observations in its place, would fail inside torch."""
    if isinstance(encoder, PixelEncoder):
        return
    hint = (
        "pass its encoder, agent.encoder"
        if isinstance(getattr(encoder, "encoder", None), PixelEncoder)
        else "pass a run's encoder, load_run(path).agent.encoder"
    )
    raise TypeError(
        f"{function}(encoder=...) must be a PixelEncoder, got {type(encoder).__name__}; {hint}, "
        f"e.g. {function}(run.agent.encoder, observations)"
    )


OBSERVATIONS_EXAMPLE = "np.stack([run.env.reset(seed=s)[0]['frames'] for s in range(8)])"
"""A batch of observations as the analyses take them, for their errors."""

CHANNELS = (1, 3, 4)
"""Channel counts of frames (grey, RGB, RGBA), to tell a channel-last layout."""


def _rank_hint(shape: tuple[int, ...]) -> str:
    """How to make a batch ``(N, k, C, H, W)`` of an array of ``shape``."""
    if len(shape) == 4:
        return "for one observation (k, C, H, W) add the batch axis, observations[None]"
    if len(shape) == 3:
        return (
            "this is one frame (C, H, W): an observation is the env's k frames (k, C, H, W), "
            f"and the batch stacks observations, e.g. {OBSERVATIONS_EXAMPLE}"
        )
    return f"e.g. {OBSERVATIONS_EXAMPLE}"


def observation_batch(
    observations: object, function: str, argument: str = "observations"
) -> torch.Tensor:
    """``function``'s ``observations`` as a CPU uint8 tensor ``(N, k, C, H, W)`` (a numpy
    array or a torch tensor, as the env and :func:`play_episode` give them); a TypeError or
    ValueError naming the argument for float frames, another rank or a channel-last layout,
    which the encoder would read as other pixels or fail on inside torch."""
    where = f"{function}({argument}=...)"
    if isinstance(observations, np.ndarray):
        batch = torch.from_numpy(np.ascontiguousarray(observations))
    elif isinstance(observations, torch.Tensor):
        batch = observations.detach().cpu()
    else:
        raise TypeError(
            f"{where} must be a uint8 array (N, k, C, H, W) of observations (numpy or torch), "
            f"got {type(observations).__name__} {observations!r:.60}; e.g. {OBSERVATIONS_EXAMPLE}"
        )
    shape = tuple(batch.shape)
    if batch.ndim != 5:
        raise ValueError(
            f"{where} must be a batch (N, k, C, H, W): N observations of k frames of C x H x W "
            f"pixels, as the env's 'frames', got shape {shape}; {_rank_hint(shape)}"
        )
    if shape[-1] in CHANNELS and shape[-3] not in CHANNELS:
        raise ValueError(
            f"{where} must be channel-first (N, k, C, H, W), got shape {shape}, channel-last "
            "(N, k, H, W, C); put the channels before the height, e.g. "
            "observations.permute(0, 1, 4, 2, 3) (np.transpose(observations, (0, 1, 4, 2, 3)) "
            "for a numpy array)"
        )
    if batch.dtype != torch.uint8:
        dtype = observations.dtype
        raise TypeError(
            f"{where} must be uint8 pixels in 0..255, as the env gives them, got {dtype}: "
            "the analysis divides by 255 itself, so frames in [0, 1] would read as near-black; "
            f"pass the env's frames, e.g. {OBSERVATIONS_EXAMPLE}, or "
            "(x * 255).round() as uint8 for frames x in [0, 1]"
        )
    if shape[0] == 0:
        raise ValueError(
            f"{where} holds no observation (shape {shape}); e.g. {OBSERVATIONS_EXAMPLE}"
        )
    return batch


def check_fits(
    encoder: PixelEncoder,
    batch: torch.Tensor,
    function: str,
    layers: Callable[[PixelEncoder, torch.Tensor], object] | None = None,
) -> None:
    """A ValueError naming ``function``'s ``observations`` when their frames do not fit
    ``encoder`` (another frame count, channel count or size than the run's), found on one
    observation through the encoder, and ``layers(encoder, observations)`` when given, before
    the whole batch goes through them."""
    shape = tuple(batch.shape)
    device = next(encoder.parameters()).device
    one = batch[:1].to(device)
    try:
        with torch.inference_mode():
            # the encoder's own checks first: they name what it reads (the dual's three frames)
            encoder(one)
            if layers is not None:
                layers(encoder, one)
    except (RuntimeError, IndexError, ValueError) as error:
        reason = str(error).splitlines()[0][:200]
        raise ValueError(
            f"{function}(observations=...) of shape {shape} ({shape[1]} frames of "
            f"{shape[2]} x {shape[3]} x {shape[4]}) do not fit this {type(encoder).__name__} "
            f"({reason}); pass observations of the run's own env, whose frames are those the "
            f"encoder was trained on (run.env.observation_space['frames'].shape), e.g. "
            f"{OBSERVATIONS_EXAMPLE}"
        ) from None


def check_batch_size(batch_size: object, function: str) -> None:
    """``function``'s ``batch_size``: an int >= 1."""
    if not (is_int(batch_size) and batch_size >= 1):
        raise (ValueError if is_int(batch_size) else TypeError)(
            f"{function}(batch_size=...) must be an int >= 1 (observations per forward pass), "
            f"got {type(batch_size).__name__} {batch_size!r:.60}; e.g. batch_size=64"
        )
