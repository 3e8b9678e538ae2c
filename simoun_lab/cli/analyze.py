"""``simoun-analyze``: the paper's analyses for any trained run.

    simoun-analyze masks RUN_DIR [--steps 2,20,40] [--query 40,42] [--video]
    simoun-analyze bias RUN_A [RUN_B ...] --out DIR

``masks`` draws the structure masks X^m and X^a (Eq. 5, Fig. 7) over the frames of deterministic
evaluation episodes; ``bias`` counts static, dynamic, joint and residual units per layer
(Sec. 4, Fig. 5) with the estimator of Kowal et al. (CVPR 2022).
"""

from __future__ import annotations

import sys
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Literal, Union

import numpy as np
import tyro
from tyro.constructors import PrimitiveConstructorSpec

from simoun_agent.cli.command_flags import PATH
from simoun_agent.cli.flags import fail, names_full_disk, parse, quiet_pipe
from simoun_agent.cli.other_names import POSITIONAL
from simoun_agent.config import SetupError
from simoun_agent.config.device import device_problem
from simoun_agent.run.layout import CHECKPOINT_NAME

# The analyses' modules (torch, the agent, the envs) are imported by the functions that run
# them, once the flags are read: --help, --version and a bad flag are answered in about a second.
if TYPE_CHECKING:
    from simoun_agent.run.load import LoadedRun
    from simoun_lab.analysis.report import RunBias

MAX_BIAS_EPISODES = 200
"""Episodes the bias analysis plays at most to gather its observations."""


def parse_pair(text: str) -> tuple[int, int]:
    """``"40,42"`` -> ``(40, 42)``."""
    try:
        row, col = (int(part) for part in text.split(","))
    except ValueError:
        raise SetupError(f"--query expects ROW,COL (two integers), got {text!r}") from None
    return row, col


def parse_steps(text: str) -> list[int]:
    """``"2,20,40"`` -> ``[2, 20, 40]`` (non-negative)."""
    try:
        steps = sorted({int(part) for part in text.split(",")})
    except ValueError:
        raise SetupError(
            f"--steps expects comma-separated step numbers, e.g. 2,20,40, got {text!r}"
        ) from None
    if steps[0] < 0:
        raise SetupError(f"--steps count agent decisions from 0, got {steps[0]}")
    return steps


def _animation_format(args: list[str]) -> str:
    if len(args) > 1 or (args and args[0] not in ("gif", "mp4")):
        raise ValueError(f"expected gif or mp4 (or nothing: gif), got {' '.join(args)!r}")
    return args[0] if args else "gif"


VIDEO_FORMAT = PrimitiveConstructorSpec(
    nargs="*",  # --video alone means gif
    metavar="[gif|mp4]",
    instance_from_str=_animation_format,
    is_instance=lambda value: value in (None, "gif", "mp4"),
    str_from_instance=lambda value: [] if value is None else [value],
)
"""``--video`` takes an optional format: gif without one."""


OTHER_NAMES = {
    name: POSITIONAL for name in ("run-dir", "log-dir", "logdir", "checkpoint", "load-path")
}
"""Other flags for the run simoun-analyze takes as its positional RUN
(:mod:`simoun_agent.cli.other_names`)."""


@dataclass
class Output:
    """The options both analyses take."""

    out: Annotated[str | None, PATH] = None
    """output directory (none: <run dir>/analysis/<analysis>; required by bias with several
    runs)"""
    overwrite: Annotated[bool, tyro.conf.FlagCreatePairsOff] = False
    """replace results already in --out"""
    device: str | None = None
    """torch device (none: the run's)"""


@dataclass(kw_only=True)
class Masks(Output):
    """Play deterministic evaluation episodes of a dual_interactive run and write, for each
    chosen step, a PNG of frame o_t beside the heat maps of X^m and X^a (and the attention row
    of --query), plus the heat maps as .npz. Example: simoun-analyze masks
    runs/highway-highway-s1-... --steps 2,40 --query 42,126 --video"""

    run: Annotated[str, PATH, tyro.conf.Positional, tyro.conf.arg(metavar="RUN")]
    """a run directory or its checkpoint.pt"""
    episodes: int = 1
    """episodes to play"""
    steps: Annotated[str | None, tyro.conf.arg(metavar="STEPS")] = None
    """agent decisions after which to draw, comma-separated, e.g. 2,20,40 (step 0 is the reset
    observation; none: 4 steps spread over each episode from step 2)"""
    query: Annotated[str | None, tyro.conf.arg(metavar="ROW,COL")] = None
    """also draw the attention row X[q, :] (Eq. 4) of the reduced-map position q under this
    pixel; the queries of Eq. 4 come from frame t-1"""
    video: Annotated[Literal["gif", "mp4"] | None, VIDEO_FORMAT] = None
    """also write the first episode as an animation (gif without a format): o_t, X^m, X^a and
    the query's row, left to right (top to bottom for wide frames), each heat map scaled to its
    own range"""


@dataclass(kw_only=True)
class Bias(Output):
    """For each run: play deterministic evaluation episodes, build dynamic pairs (same frames
    under a random convolution) and static pairs (same frames in shuffled order), and estimate
    each layer with the estimator of Kowal et al. (CVPR 2022). Writes bias.png (one grouped bar
    chart), bias.json and bias.md. Example: simoun-analyze bias runs/stacked-... runs/flare-...
    runs/simoun-... --out docs/bias"""

    runs: Annotated[tuple[str, ...], PATH, tyro.conf.Positional, tyro.conf.arg(metavar="RUN")]
    """run directories (or checkpoint.pt files)"""
    pairs: int = 256
    """pairs per factor"""
    seed: int = 0
    """seed of the pairs"""
    recolour: Literal["conv", "model"] = "conv"
    """how dynamic pairs change appearance: conv, a random convolution of the frames (any env);
    model, the episode replayed in a twin env under new colours of the skybox, materials and
    bodies (dm_control tasks)"""


# typing.Union: tyro 1.0 does not read the `|` of two Annotated types as a union
Command = Union[  # noqa: UP007
    Annotated[Masks, tyro.conf.subcommand("masks")], Annotated[Bias, tyro.conf.subcommand("bias")]
]
"""The command line: one of the two analyses."""


def masks_command(args: Masks) -> list[Path]:
    """Play the episodes, then write one PNG (+ its heat maps as .npz) per chosen step."""
    from simoun_agent.run.atomic import atomic_write
    from simoun_agent.run.load import load_run
    from simoun_agent.run.make_env import video_fps
    from simoun_agent.run.video import write_video
    from simoun_lab.analysis import masks as mask_pictures
    from simoun_lab.analysis.runs import play_episode, prepare_output

    chosen = parse_steps(args.steps) if args.steps is not None else None
    query = parse_pair(args.query) if args.query is not None else None
    run = load_run(Path(args.run), args.device)
    mask_pictures.require_masks(run.agent.encoder, run.config.agent.encoder)
    size = tuple(run.env.observation_space["frames"].shape[-2:])
    if query is not None:  # before the episodes are played
        mask_pictures.query_index(query, size, (1, 1))
    episodes = [
        play_episode(run.agent, run.env, run.first_seed + e).observations
        for e in range(args.episodes)
    ]
    lengths = [len(episode) - 1 for episode in episodes]
    if chosen is not None and chosen[-1] > min(lengths):
        raise SetupError(
            f"--steps {chosen[-1]} is beyond the episode: the episodes played lasted "
            f"{', '.join(map(str, lengths))} agent decisions (steps 0..length); pick steps up to "
            f"{min(lengths)}"
        )
    out = Path(args.out) if args.out else run.run_dir / "analysis" / f"masks-{run.env_step}"
    prepare_output(out, ["ep*-step*.png", "ep*-step*.npz", "masks-ep0.*"], args.overwrite)
    written = []
    for e, episode in enumerate(episodes):
        steps = chosen if chosen is not None else mask_pictures.default_steps(lengths[e])
        every = list(range(len(episode))) if args.video and e == 0 else steps
        heats = mask_pictures.heat_maps(
            mask_pictures.structure_masks(run.agent.encoder, episode[every]), size, query
        )
        position = {step: i for i, step in enumerate(every)}
        for step in steps:
            one = {name: heat[position[step]] for name, heat in heats.items()}
            frame = episode[step, -1]
            stem = out / f"ep{e}-step{step:04d}"
            title = (
                f"{run.config.env}, {run.config.agent.encoder}, env step {run.env_step}\n"
                f"episode {e}, decision {step}"
            )
            written.append(
                mask_pictures.draw_figure(stem.with_suffix(".png"), frame, one, title, query)
            )
            npz = stem.with_suffix(".npz")
            atomic_write(npz, lambda tmp, one=one, frame=frame: np.savez(tmp, frame=frame, **one))
            written.append(npz)
        if args.video and e == 0:
            frames = [
                mask_pictures.composite(
                    episode[i, -1], {name: heat[i] for name, heat in heats.items()}
                )
                for i in range(len(episode))
            ]
            fps = video_fps(run.env, run.config.resolved_action_repeat())
            written.append(write_video(out / f"masks-ep0.{args.video}", frames, fps))
    run.env.close()
    return written


def bias_of_run(run: LoadedRun, count: int, seed: int, recolour: str = "conv") -> RunBias:
    """Play evaluation episodes until ``count`` usable observations, make the pairs (dynamic
    ones by ``recolour``: ``"conv"`` or ``"model"``), and estimate each layer."""
    import torch

    from simoun_lab.analysis.bias import information_bias
    from simoun_lab.analysis.layers import layer_activations
    from simoun_lab.analysis.pairs import make_pairs, sample_rows, usable_steps
    from simoun_lab.analysis.recolour import BLOCK, dm_control_physics, replay_recoloured
    from simoun_lab.analysis.report import RunBias
    from simoun_lab.analysis.runs import play_episode

    block = None
    if recolour == "model":
        dm_control_physics(run.env, run.config.env)
        block = BLOCK
    rng = np.random.default_rng(seed)
    firsts, seconds, available = [], [], 0
    while available < count:
        if len(firsts) == MAX_BIAS_EPISODES:
            raise SetupError(
                f"{MAX_BIAS_EPISODES} episodes of {run.config.env} gave only {available} usable "
                f"observations; pass a smaller --pairs (at most {available})"
            )
        episode = play_episode(run.agent, run.env, run.first_seed + len(firsts))
        steps = usable_steps(episode.length, block)
        firsts.append(episode.observations[steps])
        if block is not None:
            replayed = replay_recoloured(run.config, episode.seed, episode.actions, rng)[0]
            seconds.append(replayed[steps])
        available += len(steps)
    rows = sample_rows(available, count, seed)
    observations = np.concatenate(firsts)[rows]
    recoloured = np.concatenate(seconds)[rows] if seconds else None
    activations = {}
    for factor, (first, second) in make_pairs(observations, seed, recoloured).items():
        both = layer_activations(
            run.agent.encoder, torch.as_tensor(np.concatenate([first, second]))
        )
        activations[factor] = {
            name: (v[:count].numpy(), v[count:].numpy()) for name, v in both.items()
        }
    layers = {
        name: information_bias({factor: activations[factor][name] for factor in activations})
        for name in activations["dynamic"]
    }
    run.env.close()
    return RunBias(
        str(run.run_dir),
        run.config.agent.encoder,
        run.config.env,
        run.env_step,
        count,
        recolour,
        layers,
    )


def bias_command(args: Bias) -> list[Path]:
    """The estimates of every run, then one chart, JSON and Markdown for all of them."""
    from simoun_agent.run.load import load_run
    from simoun_lab.analysis.recolour import dm_control_physics
    from simoun_lab.analysis.report import write_report
    from simoun_lab.analysis.runs import prepare_output

    if not args.runs:  # tyro accepts no value for a variable number of them
        raise SetupError("give the runs to compare: run directories (or checkpoint.pt files)")
    if args.out is None and len(args.runs) > 1:
        raise SetupError("several runs need one output directory: pass --out DIR")
    runs = [load_run(Path(path), args.device) for path in args.runs]
    if args.recolour == "model":
        for run in runs:
            dm_control_physics(run.env, run.config.env)
    out = Path(args.out) if args.out else runs[0].run_dir / "analysis" / "bias"
    prepare_output(out, ["bias.json", "bias.md", "bias.png"], args.overwrite)
    results = [bias_of_run(run, args.pairs, args.seed, args.recolour) for run in runs]
    return write_report(out, results, args.seed)


MAX_SEED = 2**63
"""--seed seeds numpy's and torch's generators: torch takes at most a 64-bit integer"""


def check_device(device: str | None) -> None:
    """SetupError naming ``--device`` when this machine has no such device, before any run is
    loaded (the run's saved config would otherwise be blamed for it)."""
    if device is not None and (problem := device_problem(device)):
        raise SetupError(f"--device {device}: {problem}")


def check_numbers(args: Masks | Bias) -> None:
    """SetupError naming the first numeric flag out of range, before any run is loaded."""
    if isinstance(args, Masks):
        if args.episodes < 1:
            raise SetupError(f"--episodes {args.episodes}: must be at least 1; e.g. --episodes 1")
        if args.steps is not None:
            parse_steps(args.steps)
        if args.query is not None:
            row, col = parse_pair(args.query)
            if row < 0 or col < 0:
                raise SetupError(
                    f"--query {args.query}: a pixel's row and column count from 0; e.g. --query 0,0"
                )
        return
    if args.pairs < 2:
        raise SetupError(f"--pairs {args.pairs}: must be at least 2; e.g. --pairs 256")
    if not 0 <= args.seed < MAX_SEED:
        raise SetupError(f"--seed {args.seed}: seeds lie in [0, 2**63); e.g. --seed 0")


def run_key(path: str) -> Path:
    """The checkpoint file ``path`` (a run directory or its checkpoint.pt) stands for, with
    links and ``..`` resolved: two paths to one run give one key."""
    given = Path(path)
    return (given / CHECKPOINT_NAME if given.is_dir() else given).resolve()


def check_distinct_runs(runs: Sequence[str]) -> None:
    """SetupError when two of ``runs`` are one run (the same directory, the directory and its
    checkpoint.pt, or a link to it): its rows would be counted twice."""
    seen: dict[Path, str] = {}
    for path in runs:
        key = run_key(path)
        if key in seen:
            both = f"{path} is" if path == seen[key] else f"{seen[key]} and {path} are"
            raise SetupError(
                f"{both} the same run ({key.parent}) given twice: its results would be counted "
                "twice; give each run once"
            )
        seen[key] = path


PROG = "simoun-analyze"

DESCRIPTION = (
    "The paper's analyses for a trained run: structure masks (Fig. 7) and the "
    "information-bias analysis (Fig. 5)."
)


@names_full_disk(PROG, "pass --out DIR on another disk")
@quiet_pipe
def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``simoun-analyze``."""
    args = parse(Command, argv, PROG, DESCRIPTION, other_names=OTHER_NAMES)
    name = "masks" if isinstance(args, Masks) else "bias"
    try:
        check_device(args.device)
        check_numbers(args)
        if isinstance(args, Bias):
            check_distinct_runs(args.runs)
    except SetupError as err:
        fail(f"{PROG} {name}", err)
    try:
        written = masks_command(args) if isinstance(args, Masks) else bias_command(args)
    except SetupError as err:
        fail(f"{PROG} {name}", err)
    for path in written:
        print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
