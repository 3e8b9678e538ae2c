"""Whether a ``--device`` value names a device this machine has.

The form (cpu, cuda, cuda:N, mps) is checked as text; only a GPU device makes this module ask
torch whether the machine has it, so configs that name no GPU (the defaults, ``--device cpu``,
every run directory ``simoun-report`` reads) load without importing torch.

Example:
    >>> device_problem("cpu") is None, device_problem("gpu")
    (True, "device type 'gpu' is not supported here; use cpu, cuda, cuda:N or mps")
"""

from __future__ import annotations

import re

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
