"""Consistency-guided curiosity (paper Sec. 3.3, Eq. 13): the shared numpy/torch core.

The agent (torch tensors on its device) and the Gymnasium reward wrappers (numpy arrays) both
compute the intrinsic reward through these functions, so there is one implementation of Eq. 13.
Only operations that numpy arrays and torch tensors both support are used, and torch is never
imported here: a torch tensor can only reach this module if the caller already imported torch,
in which case it is picked up from ``sys.modules``.

Example:
    >>> import numpy as np
    >>> f_m = np.array([[1.0, 2.0]], dtype=np.float32)
    >>> f_a = np.array([[[0.0, 0.0], [1.0, 1.0], [1.0, 3.0]]], dtype=np.float32)
    >>> d = consistency_distance(f_m, f_a)  # || [1, 2] - ([1, 1] + [0, 2]) ||_2 = 1
    >>> stats = RunningMax(r_e_max=1.0, r_i_max=1.0)
    >>> stats.update(np.array([2.0]), d)
    >>> consistency_reward(d, step=0, r_e_max=stats.r_e_max, r_i_max=stats.r_i_max)
    array([0.4], dtype=float32)
"""

from __future__ import annotations

import math
import sys
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, Protocol, runtime_checkable

import numpy as np

__all__ = [
    "FeatureSource",
    "RunningMax",
    "consistency_distance",
    "consistency_reward",
]


def _is_tensor(x: Any) -> bool:
    torch = sys.modules.get("torch")
    return torch is not None and isinstance(x, torch.Tensor)


def consistency_distance(f_m: Any, f_a: Any) -> Any:
    """The distance d in Eq. 13 between the two estimates of the temporal dynamics.

    ``d = || |f_m_t| - (|f_a_{t-1} - f_a_{t-2}| + |f_a_t - f_a_{t-1}|) ||_2``

    Args:
        f_m: motion features ``(B, D)`` of the triplet ending at t.
        f_a: appearance features ``(B, 3, D)`` of the frames t-2, t-1, t (in that order).

    Returns:
        ``(B,)`` distances, same array type (numpy or torch), dtype and device as the inputs.
    """
    if f_a.ndim != 3 or f_a.shape[-2] != 3:
        raise ValueError(
            f"f_a must have shape (B, 3, D) for the frames t-2, t-1, t; got {tuple(f_a.shape)}. "
            "Stack the three appearance vectors on axis 1."
        )
    if f_m.ndim != 2 or f_m.shape[0] != f_a.shape[0] or f_m.shape[-1] != f_a.shape[-1]:
        raise ValueError(
            f"f_m must have shape (B, D) = ({f_a.shape[0]}, {f_a.shape[-1]}) to match f_a "
            f"{tuple(f_a.shape)}; got {tuple(f_m.shape)}."
        )
    appearance_flow = abs(f_a[:, 1] - f_a[:, 0]) + abs(f_a[:, 2] - f_a[:, 1])
    return ((abs(f_m) - appearance_flow) ** 2).sum(-1) ** 0.5


def consistency_reward(
    distance: Any,
    step: Any,
    r_e_max: Any,
    r_i_max: Any,
    scale: float = 0.2,
    decay: float = 2e-5,
) -> Any:
    """Intrinsic reward of Eq. 13: ``r_i = C * exp(-lambda * t) * d * r_e_max / r_i_max``.

    Args:
        distance: ``d`` from :func:`consistency_distance`, ``(B,)`` numpy array or torch tensor.
        step: the global environment step t (python number or 0-d tensor).
        r_e_max: running maximum of the extrinsic reward magnitude (number or 0-d tensor).
        r_i_max: running maximum of the raw distance ``d`` (number or 0-d tensor, > 0).
        scale: the temperature weight C.
        decay: the exponential decay weight lambda, per environment step.

    Returns:
        ``(B,)`` intrinsic rewards of the same array type as ``distance``. Raising the running
        maxima with :meth:`RunningMax.update` before this call keeps
        ``r_i <= scale * exp(-decay * step) * r_e_max``.
    """
    if _is_tensor(step):
        weight = scale * (-decay * step).exp()
    else:
        weight = scale * math.exp(-decay * float(step))
    return weight * distance * (r_e_max / r_i_max)


def _size(x: Any) -> int:
    return x.numel() if _is_tensor(x) else np.size(x)


def _batch_max(x: Any) -> Any:
    return x.max() if _is_tensor(x) else np.max(x)


def _raise_to(current: Any, candidate: Any) -> Any:
    """max(current, candidate) for numbers, numpy scalars and 0-d tensors, without host syncs."""
    if _is_tensor(candidate) or _is_tensor(current):
        torch = sys.modules["torch"]
        like = candidate if _is_tensor(candidate) else current
        current = torch.as_tensor(current, dtype=like.dtype, device=like.device)
        candidate = torch.as_tensor(candidate, dtype=like.dtype, device=like.device)
        return torch.maximum(current, candidate)
    return max(float(current), float(candidate))


def _positive_number(value: Any) -> bool:
    """A finite Python or numpy number > 0 (not a bool, not a string)."""
    number = isinstance(value, (int, float, np.integer, np.floating))
    if not number or isinstance(value, (bool, np.bool_)):
        return False
    return math.isfinite(value) and value > 0


@dataclass
class RunningMax:
    """Running maxima ``r_e_max`` and ``r_i_max`` that normalise Eq. 13.

    ``r_e_max`` tracks the largest extrinsic reward *magnitude* ``|r_e|`` seen so far, so the
    intrinsic reward keeps a positive, meaningful scale on tasks whose rewards are all negative
    (e.g. Pendulum). ``r_i_max`` tracks the largest raw distance ``d`` (before scaling).

    The fields are python floats, or 0-d torch tensors after :meth:`to` (or after the first
    :meth:`update` with tensors): then every update stays on the device, with no host sync.
    NaN/inf inputs are rejected for numpy inputs; torch inputs are not checked, since that would
    need a host sync (``torch.maximum`` propagates a NaN, so it still shows up in the maxima).
    """

    r_e_max: Any = 1.0
    """Initial (and running) maximum of ``|r_e|``; must be > 0."""
    r_i_max: Any = 1.0
    """Initial (and running) maximum of the raw consistency distance; must be > 0."""

    def __post_init__(self) -> None:
        for name in ("r_e_max", "r_i_max"):
            value = getattr(self, name)
            if not _is_tensor(value) and not _positive_number(value):
                raise ValueError(
                    f"RunningMax.{name} must be a finite number > 0 (it divides or scales the "
                    f"intrinsic reward); got {value!r}. Pass e.g. {name}=1.0."
                )

    def update(self, extrinsic: Any, distance: Any) -> None:
        """Raise ``r_e_max`` to ``max |extrinsic|`` and ``r_i_max`` to ``max distance``.

        Call it with the batch *before* :func:`consistency_reward`, so ``d / r_i_max <= 1``.
        Empty batches leave the maxima unchanged.
        """
        for name, values in (("extrinsic reward", extrinsic), ("consistency distance", distance)):
            if not _is_tensor(values) and not np.all(np.isfinite(values)):
                raise ValueError(
                    f"RunningMax.update got a NaN or inf {name}: {values!r}. Check the env's "
                    "reward and the feature source's output; one bad value would poison the "
                    "running maximum for the rest of training."
                )
        if _size(extrinsic):
            self.r_e_max = _raise_to(self.r_e_max, _batch_max(abs(extrinsic)))
        if _size(distance):
            self.r_i_max = _raise_to(self.r_i_max, _batch_max(distance))

    def to(self, device: Any, dtype: Any = None) -> RunningMax:
        """Keep the maxima as 0-d torch tensors on ``device`` (float32 unless ``dtype``)."""
        import torch

        dtype = dtype or torch.float32
        self.r_e_max = torch.as_tensor(self.r_e_max, dtype=dtype, device=device)
        self.r_i_max = torch.as_tensor(self.r_i_max, dtype=dtype, device=device)
        return self

    def state_dict(self) -> dict[str, float]:
        """Both maxima as python floats (one host sync each when they live on a device)."""
        return {"r_e_max": float(self.r_e_max), "r_i_max": float(self.r_i_max)}

    @staticmethod
    def state_problems(state: Any) -> list[str]:
        """What keeps ``state`` from loading: no dict, or a maximum missing or not a finite
        number > 0 (a one-element tensor counts as a number)."""
        if not isinstance(state, Mapping):
            return [f"it is a {type(state).__name__}, not a dict of r_e_max and r_i_max"]
        problems = []
        for name in ("r_e_max", "r_i_max"):
            if name not in state:
                problems.append(f"it lacks {name}")
                continue
            value = state[name]
            if _is_tensor(value) and value.numel() == 1:
                value = value.item()
            if not _positive_number(value):
                problems.append(f"its {name} is {value!r:.60}, not a finite number > 0")
        return problems

    def load_state_dict(self, state: dict[str, float]) -> None:
        """Restore the maxima, keeping the current storage (float or tensor, device, dtype); a
        state without both as finite numbers > 0 is refused and nothing is loaded."""
        problems = self.state_problems(state)
        if problems:
            raise ValueError(
                f"RunningMax.load_state_dict cannot load this state: {'; '.join(problems)}; pass "
                "what RunningMax.state_dict() returned, e.g. {'r_e_max': 1.0, 'r_i_max': 1.0}. "
                "Nothing was loaded."
            )
        for name in ("r_e_max", "r_i_max"):
            current = getattr(self, name)
            if _is_tensor(current):
                setattr(self, name, _raise_to(current.new_zeros(()), state[name]))
            else:
                setattr(self, name, float(state[name]))


@runtime_checkable
class FeatureSource(Protocol):
    """Anything that maps a batch of frame triplets to Simoun's motion and appearance features.

    ``__call__(triplets)`` takes ``uint8 (B, 3, C, H, W)`` (frames t-2, t-1, t) and returns
    ``(f_m, f_a)``: numpy float32 ``(B, D)`` and ``(B, 3, D)``. The triplets are a numpy
    array, never a torch tensor: a torch module goes behind a function that converts them to a
    float tensor and its features back to numpy. Implementations:
    ``simoun_agent.curiosity_model.CuriosityModel`` (learns online) and
    ``simoun_agent.curiosity_model.AgentFeatures`` (a trained agent's encoder).

    Sources that learn online may also define, as rllte's intrinsic-reward modules do,
    ``watch(triplets, actions, next_triplets, terminated, truncated)`` (called by the wrappers
    after every env step, with batch axis first) and ``update()`` (called by the source itself or
    by the user); the wrappers call ``watch`` when it exists, and ``close()`` (e.g. to stop a
    training thread) from their own ``close()``.
    """

    def __call__(self, triplets: np.ndarray) -> tuple[np.ndarray, np.ndarray]: ...
