"""The distraction suite: DMC-GB's four test modes (and ``train``) as env wrappers.

Each mode names how to wrap the bare env that :func:`simoun_agent.run.make_env.make_env` builds
for a run (its ``distractor`` hook), so a distracted env is the run's own stack, action repeat,
cameras and image size included, with only the appearance changed.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from functools import partial
from pathlib import Path
from typing import Any

import gymnasium as gym

from simoun_agent.config import SetupError, TrainConfig
from simoun_agent.config.rules import closest_name
from simoun_wrappers import ColorShift, MovingBackground

DISTRACTIONS: dict[str, tuple[type[gym.Wrapper], str] | None] = {
    "train": None,
    "color_easy": (ColorShift, "easy"),
    "color_hard": (ColorShift, "hard"),
    "video_easy": (MovingBackground, "easy"),
    "video_hard": (MovingBackground, "hard"),
}
"""Mode name -> (wrapper, level); ``train`` is the run's own env. As in DMC-GB, ``color_*``
recolour the sky, floor and body at each episode and ``video_*`` play a moving background
behind the sky (easy) or the sky and the floor (hard)."""

DISTRACTION_SEED = 0
"""Seed of every distractor: with the evaluation's reset seeds it fixes the colours and
backgrounds of each episode, so two runs evaluated on the same seeds see the same ones."""


NO_DISTRACTION_WORDS = ("none", "null", "off", "no", "clean")
"""What a user types for "no distraction", answered with how a command gives it."""


def parse_distractions(
    text: str | Sequence[str],
    flag: str = "--distraction",
    modes: Sequence[str] = tuple(DISTRACTIONS),
    undistracted: str = "--distraction train",
) -> list[str]:
    """Mode names from ``"color_easy,video_hard"`` (or a list), checked against ``modes`` (the
    ones ``flag`` takes), duplicates dropped; ``undistracted`` says how ``flag``'s command is
    given no distraction.

    Raises SetupError for an unknown name, suggesting the closest one, and TypeError for
    ``text`` that is neither a string nor a list of strings.
    """
    parts = _mode_texts(text, "parse_distractions(text=...)")
    names = [part.strip() for part in parts if part.strip()]
    if not names:
        raise SetupError(f"{flag} is empty; pass modes from {', '.join(modes)}")
    for name in names:
        if name in modes:
            continue
        if name.lower() in NO_DISTRACTION_WORDS:
            hint = f"for no distraction, {undistracted}; "
        else:
            close = closest_name(name, list(modes), cutoff=0.5)
            hint = f"did you mean {close!r}? " if close else ""
        raise SetupError(
            f"unknown distraction {name!r} in {flag}; {hint}choose from "
            f"{', '.join(modes)} (comma-separated, e.g. {flag} color_easy,video_hard)"
        )
    return list(dict.fromkeys(names))


def _mode_texts(text: Any, argument: str) -> list[str]:
    """The names of ``text`` (``"color_easy,video_hard"`` or a list of names) still to check;
    TypeError naming ``argument`` for anything else, where ``.strip()`` or iteration would
    fail with Python's message."""
    example = "e.g. 'color_easy,video_hard' or ['color_easy', 'video_hard']"
    if isinstance(text, str):
        return text.split(",")
    if not isinstance(text, (list, tuple)):
        raise TypeError(
            f"{argument} takes mode names, as one comma-separated str or a list of str, got "
            f"{type(text).__name__} {text!r:.60}; {example}"
        )
    for index, part in enumerate(text):
        if not isinstance(part, str):
            raise TypeError(
                f"{argument}: item {index} of the list is {type(part).__name__} {part!r:.40}, "
                f"not a mode name (a str); choose from {', '.join(DISTRACTIONS)}; {example}"
            )
    return list(text)


def check_mode_list(modes: Any, argument: str, allowed: Sequence[str]) -> list[str]:
    """``modes``, a list (or tuple) of names from ``allowed``, as a list; a TypeError naming
    ``argument`` for a str (which ``list()`` would read letter by letter) or another type, and
    a SetupError for an unknown name, with the closest one."""
    if isinstance(modes, str):
        raise TypeError(
            f"{argument} takes a list of mode names, got the str {modes!r}; pass it in a list, "
            f"e.g. {argument.split('(')[0]}(..., [{modes!r}], ...)"
        )
    names = _mode_texts(modes, argument)
    for name in names:
        if name not in allowed:
            close = closest_name(name, list(allowed), cutoff=0.5)
            hint = f"did you mean {close!r}? " if close else ""
            raise SetupError(
                f"{argument}: unknown mode {name!r}; {hint}choose from {', '.join(allowed)}"
            )
    return list(names)


def check_run_config(config: Any, function: str) -> None:
    """A TypeError naming ``function``'s ``config`` when it is not a run's TrainConfig (an env
    id given in its place, say)."""
    if not isinstance(config, TrainConfig):
        raise TypeError(
            f"{function}(config=...) takes the run's TrainConfig (e.g. run.config of "
            f"simoun_agent.run.load.load_run(RUN_DIR)), got {type(config).__name__} "
            f"{config!r:.60}; for an env id, build a config first: "
            "simoun_agent.config.resolve(None, {'env': ENV_ID})"
        )


def distractor(name: str, videos: str | Path | None = None) -> Callable[[gym.Env], gym.Env] | None:
    """The wrapper of mode ``name`` for ``make_env(config, distractor)``; None for ``train``.

    ``videos`` is a folder of video files played by the ``video_*`` modes instead of the
    procedural background (DMC-GB's video folders, or DAVIS clips as mp4).
    """
    if not isinstance(name, str):
        raise TypeError(
            f"distractor(name=...) takes one mode name (a str), got {type(name).__name__} "
            f"{name!r:.60}; choose from {', '.join(DISTRACTIONS)}"
        )
    if "," in name:
        raise SetupError(
            f"distractor(name=...) takes one mode, got {name!r}; call it once per mode "
            "(parse_distractions(text) splits a comma-separated list)"
        )
    (name,) = parse_distractions([name])
    entry = DISTRACTIONS[name]
    if entry is None:
        return None
    wrapper, level = entry
    if wrapper is MovingBackground:
        return partial(MovingBackground, level=level, videos=videos, seed=DISTRACTION_SEED)
    return partial(wrapper, level=level, seed=DISTRACTION_SEED)


def check_supported(
    config: TrainConfig, names: Sequence[str], videos: str | Path | None = None
) -> None:
    """Raise SetupError unless every mode in ``names`` can wrap the env of ``config``.

    The distractors change a MuJoCo scene, so any mode but ``train`` needs a dm_control task;
    a ``videos`` folder must hold a readable video. Checked before any episode is played.
    """
    check_run_config(config, "check_supported")
    if not names:
        return
    distracted = [name for name in parse_distractions(names) if DISTRACTIONS[name] is not None]
    if distracted and not config.env.startswith("dm_control/"):
        raise SetupError(
            f"distraction {distracted[0]!r} needs a dm_control task (it recolours or re-renders a "
            f"MuJoCo scene), but this run trained on {config.env}; evaluate it with --distraction "
            f"train, or randomise its appearance with simoun_wrappers.RandomConvolution."
        )
    if videos is not None and any(name.startswith("video_") for name in distracted):
        from simoun_wrappers.distractors.backgrounds import VideoBackground

        try:
            VideoBackground(videos)
        except ValueError as err:
            raise SetupError(f"--videos {videos}: {err}") from None


def make_distracted_env(
    config: TrainConfig, name: str, videos: str | Path | None = None
) -> gym.Env:
    """The run's env stack for ``config`` under distraction mode ``name``.

    Raises SetupError when the mode does not fit the run (see :func:`check_supported`).
    """
    from simoun_agent.run.make_env import make_env

    check_run_config(config, "make_distracted_env")
    check_supported(config, [name], videos)
    return make_env(config, distractor(name, videos))


def check_eval_distractions(config: TrainConfig, flag: str = "--eval-distraction") -> list[str]:
    """``config.eval_distraction`` checked (names, a dm_control task); SetupError otherwise,
    naming ``flag``, where the modes were given (a sweep's ``--grid eval_distraction``).

    ``train`` is refused: it is the run's own evaluation, which always runs.
    """
    check_run_config(config, "check_eval_distractions")
    if "train" in config.eval_distraction:
        raise SetupError(
            f"{flag} train is the run's own evaluation, which always runs; name distraction "
            f"modes only, e.g. {flag} video_hard"
        )
    modes = [name for name, entry in DISTRACTIONS.items() if entry is not None]
    undistracted = f"leave {flag} out (the run's own evaluation always runs)"
    names = (
        parse_distractions(config.eval_distraction, flag, modes, undistracted)
        if config.eval_distraction
        else []
    )
    if names and not config.env.startswith("dm_control/"):
        raise SetupError(
            f"{flag} {names[0]} needs a dm_control task (it recolours or re-renders a MuJoCo "
            f"scene), but this run trains on {config.env}; leave {names[0]} out of {flag} (the "
            "run's own evaluation always runs), or train on a dm_control task"
        )
    return names
