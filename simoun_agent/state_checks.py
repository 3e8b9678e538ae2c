"""What keeps a saved state from loading into a model, found before any of it is loaded.

``torch.nn.Module.load_state_dict`` copies tensor after tensor and stops at the first that does
not fit, and ``torch.optim.Optimizer.load_state_dict`` checks only the parameter counts: a state
of another model, or one edited by hand, would fail half-way through (a ``KeyError`` or a
``RuntimeError`` from torch) and leave a model half-loaded. Each function here returns the
problems of one part of a state as phrases (``"its critic lacks q1.0.weight"``), empty when it
fits, so a ``load_state_dict`` can check the whole state first and refuse it with every problem
named, or load all of it.
"""

from __future__ import annotations

import numbers
from collections.abc import Mapping
from typing import Any

import numpy as np
import torch

__all__ = [
    "count_problems",
    "module_problems",
    "optimizer_problems",
    "tensor_problems",
]


def described(value: Any) -> str:
    """``value``'s type as a user names it: ``numpy.ndarray``, ``dict``, ``NoneType``."""
    kind = type(value)
    return f"{kind.__module__}.{kind.__name__}" if kind.__module__ == "numpy" else kind.__name__


def tensor_problems(name: str, own: torch.Tensor, saved: Any) -> list[str]:
    """Whether ``saved`` can replace ``own``: a torch tensor of its shape, floating point where
    ``own`` is."""
    if not isinstance(saved, torch.Tensor):
        return [f"its {name} is a {described(saved)}, not a torch tensor"]
    if tuple(saved.shape) != tuple(own.shape):
        return [f"{name} is {tuple(saved.shape)} there, {tuple(own.shape)} here"]
    if saved.is_floating_point() != own.is_floating_point():
        return [f"{name} holds {saved.dtype} values, not {own.dtype}"]
    return []


def module_problems(name: str, module: torch.nn.Module, saved: Any) -> list[str]:
    """What keeps ``saved`` from loading into ``module``: no dict, keys missing or unknown, a
    value that is no tensor, or a tensor of another shape."""
    if not isinstance(saved, Mapping):
        return [f"its {name} is a {described(saved)}, not a state dict"]
    own = module.state_dict()
    problems = []
    lacking = [key for key in own if key not in saved]
    if lacking:
        problems.append(f"its {name} lacks {', '.join(lacking)}")
    unknown = [str(key) for key in saved if key not in own]
    if unknown:
        problems.append(f"its {name} holds {', '.join(unknown)}, which this {name} has not")
    for key, tensor in own.items():
        if key in saved:
            problems += tensor_problems(f"{name}.{key}", tensor, saved[key])
    return problems


def _hyperparameter_fits(own: Any, saved: Any) -> bool:
    """A saved optimizer hyperparameter of the kind of this one's: a number (or a one-element
    tensor) for a number, a tuple of as many numbers for a tuple (Adam's betas)."""
    if isinstance(own, bool) or own is None:
        return True
    if isinstance(own, numbers.Real):
        if isinstance(saved, torch.Tensor):
            return saved.numel() == 1
        return isinstance(saved, numbers.Real) and not isinstance(saved, bool)
    if isinstance(own, tuple):
        return (
            isinstance(saved, (tuple, list))
            and len(saved) == len(own)
            and all(_hyperparameter_fits(a, b) for a, b in zip(own, saved, strict=True))
        )
    return True


def _group_problems(name: str, index: int, own: dict[str, Any], saved: Any) -> list[str]:
    """What keeps the saved parameter group ``index`` from replacing this optimizer's: its
    parameter list and its numeric hyperparameters (flags, which torch fills in when a state
    predates them, may be missing)."""
    where = f"its {name} parameter group {index}"
    if not isinstance(saved, Mapping) or not isinstance(saved.get("params"), (list, tuple)):
        return [f"{where} is no dict with a params list"]
    if len(saved["params"]) != len(own["params"]):
        return [f"{where} holds {len(saved['params'])} parameters, this one {len(own['params'])}"]
    problems = []
    for key, value in own.items():
        if key == "params" or isinstance(value, bool) or value is None:
            continue
        if key not in saved:
            problems.append(f"{where} lacks {key}")
        elif not _hyperparameter_fits(value, saved[key]):
            problems.append(f"{where} has {key} {saved[key]!r}, not a value like {value!r}")
    return problems


def _slot_problems(name: str, key: Any, slots: Any, shape: tuple[int, ...]) -> list[str]:
    """What keeps the saved per-parameter state ``slots`` (Adam's step, exp_avg, exp_avg_sq) of
    a parameter of ``shape`` from loading: tensors, the step a single number, the others of the
    parameter's shape."""
    where = f"its {name} state of parameter {key!r}"
    if not isinstance(slots, Mapping):
        return [f"{where} is a {described(slots)}, not a dict"]
    problems = []
    for slot, value in slots.items():
        if not isinstance(value, torch.Tensor):
            problems.append(f"{where}: {slot} is a {described(value)}, not a torch tensor")
        elif slot == "step" and value.numel() != 1:
            problems.append(f"{where}: step holds {value.numel()} values, not one")
        elif slot != "step" and tuple(value.shape) != shape:
            problems.append(f"{where}: {slot} is {tuple(value.shape)} there, {shape} here")
    return problems


def optimizer_problems(name: str, optimizer: torch.optim.Optimizer, saved: Any) -> list[str]:
    """What keeps ``saved`` from loading into ``optimizer``: no dict, ``state`` or
    ``param_groups`` missing, groups of other sizes or hyperparameters, or a parameter's state
    of another shape (torch would load that and fail at the next step)."""
    if not isinstance(saved, Mapping):
        return [f"its {name} is a {described(saved)}, not an optimizer state dict"]
    lacking = [key for key in ("state", "param_groups") if key not in saved]
    if lacking:
        return [f"its {name} lacks {', '.join(lacking)}"]
    groups, state = saved["param_groups"], saved["state"]
    own_groups = optimizer.param_groups
    if not isinstance(groups, (list, tuple)) or len(groups) != len(own_groups):
        count = len(groups) if isinstance(groups, (list, tuple)) else described(groups)
        return [f"its {name} has {count} parameter groups, this one {len(own_groups)}"]
    if not isinstance(state, Mapping):
        return [f"its {name} state is a {described(state)}, not a dict"]
    problems = []
    shapes: dict[Any, tuple[int, ...]] = {}
    for index, (group, own) in enumerate(zip(groups, own_groups, strict=True)):
        found = _group_problems(name, index, own, group)
        problems += found
        if not found:
            shapes.update(
                zip(group["params"], (tuple(p.shape) for p in own["params"]), strict=True)
            )
    if problems:
        return problems
    for key, slots in state.items():
        if key not in shapes:
            problems.append(f"its {name} holds state of parameter {key!r}, which no group has")
        else:
            problems += _slot_problems(name, key, slots, shapes[key])
    return problems


def count_problems(name: str, value: Any) -> list[str]:
    """A counter: an int >= 0 (a Python, numpy or 0-d torch integer)."""
    if isinstance(value, torch.Tensor) and value.numel() == 1 and not value.is_floating_point():
        value = value.item()
    if isinstance(value, numbers.Integral) and not isinstance(value, (bool, np.bool_)):
        if value >= 0:
            return []
    return [f"its {name} is {value!r}, not an int >= 0"]
