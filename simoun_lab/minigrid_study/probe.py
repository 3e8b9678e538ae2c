"""Does an intrinsic reward track novelty at all? A probe without a learner.

The study's consistency arm logged a reward nearly constant within each rollout (std 3-13 % of
its mean over the first 200k steps of DoorKey-6x6 seed 0) and correlated *negatively* with the
novelty ``1 / sqrt(N(s))`` of the state reached, where RND's correlated positively. Every change
to Eq. 13's constants or normalisation (C, lambda, the running maxima, a running mean taken off)
is an affine map of the distance d within a rollout and leaves that correlation as it is, so
only a change to the feature model that computes d could make the reward seek novel states.

This probe measures that correlation for an arm's wrapper and model under a uniformly random
policy (no PPO, so a variant costs minutes, not hours): the same pixel vector env as the study,
a probe seed disjoint from the study's training and evaluation seeds, and per block of
``n_envs x n_steps`` transitions the intrinsic reward's mean, std and Pearson correlation with
novelty (N counted over the probe so far, as the study's log counts it). RND is the positive
control: a probe that cannot find RND's novelty signal would say nothing about the others.
"""

from __future__ import annotations

import functools
import warnings
from collections import Counter
from collections.abc import Callable
from pathlib import Path

import numpy as np
import torch
from gymnasium.vector import VectorEnv

from simoun_agent import table
from simoun_agent.run.atomic import atomic_write
from simoun_lab.minigrid_study.arms import ARMS, consistency
from simoun_lab.minigrid_study.envs import STATE_KEY, SB3VecEnv, pixel_vector_env
from simoun_lab.minigrid_study.probe_settings import ProbeSettings, check_probes, check_settings

__all__ = ["PROBED", "ProbeSettings", "check_settings", "probe", "write_probe"]

PROBED: dict[str, Callable[[VectorEnv, int, torch.device], VectorEnv]] = {
    "consistency": ARMS["consistency"],
    "consistency_lr1e-4": functools.partial(consistency, lr=1e-4),
    "consistency_capacity10k": functools.partial(consistency, capacity=10_000),
    "consistency_no_interactive": functools.partial(consistency, interactive=False),
    "rnd": ARMS["rnd"],
}
"""probe name -> the wrapped vector env: the study's two intrinsic arms, and the consistency
model with one default changed each: RND's learning rate (1e-4 against 1e-3: features that move
slower than the policy's visits), a buffer of 10k transitions (10 rollouts of memory against
one), no structural interactive module (Eq. 4-6); the command line reads its names from
:data:`~simoun_lab.minigrid_study.probe_settings.PROBE_NAMES`"""

COLUMNS = (
    "probe",
    "seed",
    "env_step",
    "intrinsic_mean",
    "intrinsic_std",
    "novelty_corr",
    "still_fraction",
    "still_mean",
    "moving_mean",
    "novelty_corr_moving",
    "states_visited",
)


def pearson(x: np.ndarray, y: np.ndarray) -> float:
    """Pearson's r, NaN when either side is constant."""
    if x.std() == 0 or y.std() == 0:
        return float("nan")
    return float(np.corrcoef(x, y)[0, 1])


def probe(name: str, settings: ProbeSettings) -> list[dict[str, float | str]]:
    """One row per block of the probe ``name`` of :data:`PROBED` under a random policy."""
    pixels = pixel_vector_env(settings.env_id, settings.n_envs)
    envs = SB3VecEnv(PROBED[name](pixels, settings.seed, torch.device("cpu")))
    envs.seed(settings.seed)
    envs.reset()
    actions = np.random.default_rng(settings.seed)
    visits: Counter[tuple[int, ...]] = Counter()
    rows: list[dict[str, float | str]] = []
    try:
        for block in range(settings.steps // (settings.n_envs * settings.n_steps)):
            intrinsic, novelty, still = [], [], []
            for _ in range(settings.n_steps):
                obs, _, _, infos = envs.step(
                    actions.integers(envs.action_space.n, size=envs.num_envs)
                )
                for i, info in enumerate(infos):
                    state = tuple(int(v) for v in info[STATE_KEY])
                    visits[state] += 1
                    intrinsic.append(float(info["reward_intrinsic"]))
                    novelty.append(visits[state] ** -0.5)
                    frames = info.get("terminal_observation", obs[i]).reshape(3, -1)
                    still.append(bool(np.all(frames == frames[:1])))
            reward, novel, stood = np.array(intrinsic), np.array(novelty), np.array(still)
            moved = ~stood
            rows.append(
                {
                    "probe": name,
                    "seed": settings.seed,
                    "env_step": (block + 1) * settings.n_envs * settings.n_steps,
                    "intrinsic_mean": float(reward.mean()),
                    "intrinsic_std": float(reward.std()),
                    "novelty_corr": pearson(reward, novel),
                    "still_fraction": float(stood.mean()),
                    "still_mean": float(reward[stood].mean()) if stood.any() else np.nan,
                    "moving_mean": float(reward[moved].mean()) if moved.any() else np.nan,
                    "novelty_corr_moving": pearson(reward[moved], novel[moved]),
                    "states_visited": len(visits),
                }
            )
    finally:
        envs.close()
    return rows


def write_probe(settings: ProbeSettings, names: list[str], out: Path) -> Path:
    """Probe each of ``names`` and write ``out/probe.csv`` (every block) and ``out/probe.md``
    (per probe, means over blocks, the first left out: the reward's correlation with novelty
    over all and over moving transitions, its std / mean, its still / moving mean)."""
    check_settings(settings)
    check_probes(names)
    rows = [row for name in names for row in probe(name, settings)]
    out.mkdir(parents=True, exist_ok=True)

    table.write_csv(out / "probe.csv", COLUMNS, rows)
    lines = [
        f"# Intrinsic rewards against novelty under a random policy ({settings.env_id})",
        "",
        f"{settings.steps} env steps a probe, {settings.n_envs} envs, seed {settings.seed}; "
        f"blocks of {settings.n_envs * settings.n_steps} transitions, the first left out.",
        "",
        "corr: Pearson's r of the reward with the novelty 1/sqrt(N(s)) of the state reached, "
        "over every transition of a block and over its moving ones (a still triplet, three "
        "equal frames, re-visits the state it stands in, so a reward that pays still triplets "
        "more correlates negatively with novelty for that reason alone); block means.",
        "",
    ]
    summary = []
    for name in names:
        blocks = [r for r in rows if r["probe"] == name][1:]

        def column(key: str, blocks: list[dict[str, float | str]] = blocks) -> np.ndarray:
            return np.array([b[key] for b in blocks], dtype=float)

        corr, mean = column("novelty_corr"), column("intrinsic_mean")
        with warnings.catch_warnings():  # a zero reward (RND's warm-up): no ratio
            warnings.simplefilter("ignore", RuntimeWarning)
            cv = np.nanmean(np.where(mean > 0, column("intrinsic_std") / mean, np.nan))
            ratio = np.nanmean(column("still_mean") / column("moving_mean"))
        summary.append(
            [
                name,
                f"{np.nanmean(corr):+.3f}",
                f"{int(np.sum(corr > 0))} of {len(corr)}",
                f"{np.nanmean(column('novelty_corr_moving')):+.3f}",
                f"{cv:.3f}",
                f"{ratio:.2f}",
                f"{np.mean(column('still_fraction')):.2f}",
            ]
        )
    headers = ["probe", "corr", "blocks with corr > 0", "corr, moving only", "std / mean"]
    headers += ["still / moving mean", "still share"]
    lines.append(table.markdown_table(headers, summary))
    atomic_write(out / "probe.md", lambda tmp: tmp.write_text("\n".join(lines) + "\n"))
    return out / "probe.md"
