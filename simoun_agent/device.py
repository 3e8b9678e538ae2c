"""The torch device used when none is named: the GPU when torch sees one, else the CPU."""

from __future__ import annotations

import torch

from simoun_agent.config.device import device_problem


def default_device(device: str | torch.device | None = None) -> torch.device:
    """``device`` when given, else ``cuda`` when torch sees a CUDA GPU, else ``cpu``.

    A device this machine does not have, or that is no device, is refused naming ``device``.
    """
    if device is None:
        return torch.device("cuda" if torch.cuda.is_available() else "cpu")
    if not isinstance(device, (str, torch.device)):
        raise TypeError(
            f"device must be a str or torch.device, got {type(device).__name__} {device!r}; "
            "e.g. device='cpu' or 'cuda:0', or None for cuda when there is one"
        )
    # "meta" is torch's shape-only device, on which the memory estimate builds the agent
    problem = None if str(device) == "meta" else device_problem(str(device))
    if problem is not None:
        raise ValueError(f"device {str(device)!r}: {problem}")
    return torch.device(device)
