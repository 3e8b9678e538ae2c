"""Whether a ``--device`` value names a device this machine has.

The form (cpu, cuda, cuda:N, mps) is checked as text; only a GPU device makes this module ask
torch whether the machine has it, so configs that name no GPU (the defaults, ``--device cpu``,
every run directory ``simoun-report`` reads) load without importing torch.

Two spellings of one device compare equal through :func:`same_device` (``cpu`` and ``cpu:0``;
``cuda`` and ``cuda:N`` of the current GPU), wherever a saved device meets a given one.

Example:
    >>> device_problem("cpu") is None, device_problem("gpu")
    (True, "device type 'gpu' is not supported here; use cpu, cuda, cuda:N or mps")
    >>> same_device("cpu:0", "cpu"), same_device("cpu", "cuda:0")
    (True, False)
"""

from __future__ import annotations

import re
from typing import Any

DEVICE_FORM = re.compile(r"(?P<type>[a-z_]+)(?::(?P<index>\d+))?")
"""A torch device string: a type and an optional index (``cuda:1``)."""


def device_problem(device: str) -> str | None:
    """Why torch cannot use ``device`` on this machine, or None when it can."""
    form = DEVICE_FORM.fullmatch(device)
    if form is None:
        return "not a torch device (expected TYPE or TYPE:N); use cpu, cuda, cuda:N or mps"
    kind, index = form["type"], form["index"]
    if kind not in ("cpu", "cuda", "mps"):
        return f"device type {kind!r} is not supported here; use cpu, cuda, cuda:N or mps"
    if kind == "cpu":
        return None
    return gpu_problem(kind, None if index is None else int(index))


def gpu_problem(kind: str, index: int | None) -> str | None:
    """Why this machine has no ``kind`` ("cuda" or "mps") device ``index``, or None."""
    import torch  # only a config naming a GPU needs torch: it alone knows the machine's GPUs

    if kind == "mps":
        if not torch.backends.mps.is_available():
            return "MPS is not available on this machine; use --device cpu (device='cpu')"
        return None
    if not torch.cuda.is_available():
        return (
            f"this torch ({torch.__version__}) sees no CUDA GPU; use --device cpu (device='cpu'), "
            "or leave the device unset (none) to pick cuda only when there is one"
        )
    count = torch.cuda.device_count()
    if index is not None and index >= count:
        return f"there are {count} CUDA device(s), numbered 0..{count - 1}; use one of them"
    return None


def device_key(device: Any) -> Any:
    """``device`` as torch means it, so that two spellings of one device compare equal: the CPU
    and MPS are one device each whatever their index (``cpu:0`` is ``cpu``), and ``cuda``
    without an index is the current GPU (``cuda:0`` on a machine without one). Anything that
    is no device string (None, a typo) is returned as it is."""
    form = DEVICE_FORM.fullmatch(device) if isinstance(device, str) else None
    if form is None:
        return device
    kind, index = form["type"], form["index"]
    if kind in ("cpu", "mps"):
        return kind
    if kind == "cuda":
        return f"cuda:{int(index) if index is not None else current_gpu()}"
    return device


def current_gpu() -> int:
    """The index torch gives ``cuda`` without one: the current GPU, 0 where torch sees none."""
    import torch  # only a device naming a GPU needs torch

    return torch.cuda.current_device() if torch.cuda.is_available() else 0


def same_device(first: Any, second: Any) -> bool:
    """Whether two device values (strings, as configs keep them) name the same device."""
    return device_key(first) == device_key(second)


def same_setting(key: str, first: Any, second: Any) -> bool:
    """Whether two values of the config key ``key`` are the same setting: equal, or, for a
    ``device`` key, two spellings of one device (:func:`same_device`)."""
    if key.rpartition(".")[2] == "device":
        return same_device(first, second)
    return first == second


def device_keys(value: Any) -> Any:
    """``value`` (a spec or config as JSON) with each ``device`` key's value, at any depth, as
    :func:`device_key` gives it, so that two records compare equal whatever the spelling of
    their device."""
    if isinstance(value, dict):
        return {
            key: device_key(item) if key == "device" else device_keys(item)
            for key, item in value.items()
        }
    if isinstance(value, list):
        return [device_keys(item) for item in value]
    return value
