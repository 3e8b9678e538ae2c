"""Argument checks of the run layer's public functions (create_run, resume_run, train, the
distraction evaluation): each names the function's argument, what it takes and a call that
works, before anything is built. Without them a dict config, a lone callback or a str where a
list goes fails far from the call with Python's message, or is taken silently."""

from __future__ import annotations

import difflib
import signal
from collections.abc import Mapping
from typing import Any

from simoun_agent.config import TrainConfig
from simoun_agent.run.callback import TrainCallback
from simoun_agent.run.state import Run
from simoun_wrappers._checks import check_callable, is_int, is_real


def check_config_arg(config: Any, function: str) -> None:
    """A TypeError naming ``function``'s ``config`` unless it is a TrainConfig."""
    if isinstance(config, TrainConfig):
        return
    fix = (
        "build it from the dict with simoun_agent.config.from_dict(values)"
        if isinstance(config, Mapping)
        else "build one with simoun_agent.config.resolve(preset, overrides)"
    )
    raise TypeError(
        f"{function}(config=...) must be a TrainConfig, got {type(config).__name__} "
        f"{config!r:.60}; {fix}"
    )


def check_config_check(check: Any, function: str) -> None:
    """A TypeError naming ``function``'s ``check`` unless it is None or a function of the
    config."""
    if check is not None:
        check_callable(
            check,
            f"{function}(check=...)",
            "check(config) before any env is built",
            ("config",),
            "pass a function of the TrainConfig that raises SetupError to refuse it, e.g. "
            "check=simoun_agent.generalization.check_eval_distractions, or None",
        )


def check_run_arg(run: Any, function: str) -> None:
    """A TypeError naming ``function``'s ``run`` unless it is a Run."""
    if not isinstance(run, Run):
        raise TypeError(
            f"{function}(run=...) must be the Run of create_run(config) or "
            f"resume_run(run_dir, overrides), got {type(run).__name__} {run!r:.60}; e.g. "
            f"{function}(create_run(config))"
        )


def check_callbacks(callbacks: Any, function: str) -> None:
    """A TypeError naming ``function``'s ``callbacks`` unless it is a list (or tuple) of
    TrainCallback instances: a lone callback, its class, None or a plain function would
    otherwise fail at the first hook with Python's message, or run unbound."""
    example = f"e.g. {function}(run, [MyCallback()]), or leave callbacks out for none"
    if isinstance(callbacks, TrainCallback):
        raise TypeError(
            f"{function}(callbacks=...) takes a list of callbacks, got the one "
            f"{type(callbacks).__name__}; pass it in a list: [{type(callbacks).__name__}()]"
        )
    if not isinstance(callbacks, (list, tuple)):
        raise TypeError(
            f"{function}(callbacks=...) must be a list of TrainCallback instances, got "
            f"{type(callbacks).__name__} {callbacks!r:.60}; {example}"
        )
    for index, callback in enumerate(callbacks):
        if isinstance(callback, TrainCallback):
            check_hook_names(callback, function)
            continue
        if isinstance(callback, type) and issubclass(callback, TrainCallback):
            problem = f"the class {callback.__name__}, not an instance; pass {callback.__name__}()"
        else:
            problem = (
                f"{type(callback).__name__} {callback!r:.60}, not a TrainCallback; subclass "
                "simoun_agent.run.callback.TrainCallback and override its hooks"
            )
        raise TypeError(f"{function}(callbacks=...): item {index} is {problem}; {example}")


def check_metrics(metrics: dict[str, Any], callback: TrainCallback) -> None:
    """A TypeError naming ``callback`` and the metric it set that is no real number (or whose
    name is no str): eval.csv, TensorBoard and the learning curve take numbers only."""
    for key, value in metrics.items():
        if isinstance(key, str) and is_real(value):
            continue
        raise TypeError(
            f"{type(callback).__name__}.on_evaluation set the metric {key!r} to "
            f"{type(value).__name__} {value!r:.60}; metrics are numbers keyed by name (they go "
            f"to eval.csv, TensorBoard and the learning curve), e.g. metrics['my/score'] = 1.0"
        )


def asked_signal(callback: TrainCallback, run: Run) -> int | None:
    """``callback.stop_requested(run)`` checked: a signal number, or None. A bool is refused
    (``True`` is an int to Python, signal 1, SIGHUP), as is anything but a signal."""
    asked = callback.stop_requested(run)
    if asked is None:
        return None
    if is_int(asked) and int(asked) in signal.valid_signals():
        return int(asked)
    raise TypeError(
        f"{type(callback).__name__}.stop_requested returned {type(asked).__name__} "
        f"{asked!r:.60}; it must return a signal number to stop the run as that signal would "
        "(e.g. signal.SIGTERM) or None to go on"
    )


HOOKS = ("on_start", "on_evaluation", "on_logged", "on_end", "stop_requested")
"""The methods of TrainCallback the loop calls."""

SB3_HOOKS = (
    "on_step",
    "_on_step",
    "on_rollout_start",
    "on_rollout_end",
    "on_training_start",
    "on_training_end",
    "_on_rollout_start",
    "_on_rollout_end",
    "_on_training_start",
    "_on_training_end",
)
"""Stable-Baselines3's BaseCallback hooks, which a callback written for SB3 defines."""


def check_hook_names(callback: TrainCallback, function: str) -> None:
    """A TypeError when ``callback``'s class defines a method the loop never calls but that
    looks like a hook: a misspelt hook (``on_evalution``), Stable-Baselines3's ``on_step``, or
    any other ``on_*`` name. The loop calls only :data:`HOOKS`; the method would be skipped
    without a word."""
    hooks = ", ".join(HOOKS)
    for klass in type(callback).__mro__:
        if klass is TrainCallback or not issubclass(klass, TrainCallback):
            break
        for name, value in vars(klass).items():
            if not callable(value) or name in HOOKS or name.startswith("__"):
                continue
            close = difflib.get_close_matches(name, HOOKS, n=1, cutoff=0.8)
            if name in SB3_HOOKS:
                why = (
                    f"{name} is a hook of Stable-Baselines3's BaseCallback, which this loop "
                    "does not call; to act between steps override stop_requested(run) (polled "
                    "between steps), or on_evaluation(run, metrics) at each evaluation."
                )
            elif close:
                why = f"did you mean {close[0]}?"
            elif name.startswith("on_"):
                why = "it is no hook of TrainCallback."
            else:
                continue
            raise TypeError(
                f"{function}(callbacks=...): {klass.__name__} defines {name}, which the loop "
                f"never calls; {why} The hooks are {hooks} "
                "(simoun_agent.run.callback.TrainCallback)."
            )


def call_hook(callback: TrainCallback, hook: str, *args: Any) -> None:
    """``callback.hook(*args)``, refusing a value returned: the loop ignores it, so a hook
    returning True to stop the run (as some libraries' callbacks do) would go on silently."""
    returned = getattr(callback, hook)(*args)
    if returned is not None:
        raise TypeError(
            f"{type(callback).__name__}.{hook} returned {type(returned).__name__} "
            f"{returned!r:.60}, but the loop ignores what {hook} returns (it must return None). "
            "To stop the run, override stop_requested(run) to return a signal number, e.g. "
            "return signal.SIGINT once your condition holds (it is polled between steps)."
        )
