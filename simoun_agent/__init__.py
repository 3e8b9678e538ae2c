"""The reference Simoun SAC agent.

The torch parts load on first use (``simoun_agent.SimounAgent``, PEP 562), so importing the
torch-free configuration (:mod:`simoun_agent.config`) or the run directories' readers does not
import torch. The lab that used to live here is :mod:`simoun_lab` (:mod:`simoun_agent.moved`).
"""

import importlib
from typing import Any

import simoun_wrappers  # noqa: F401  (headless rendering defaults)
from simoun_agent import moved
from simoun_agent.config import AgentConfig
from simoun_wrappers._homes import missing_name

moved.install()  # the lab's former names (simoun_agent.study, ...) for one release

_LAZY = {
    "DualPathEncoder": "simoun_agent.models.encoder",
    "FlareEncoder": "simoun_agent.models.encoder",
    "FrameReplay": "simoun_agent.replay",
    "SimounAgent": "simoun_agent.agent",
    "SingleFrameEncoder": "simoun_agent.models.encoder",
    "StackedEncoder": "simoun_agent.models.encoder",
    "StructuralInteraction": "simoun_agent.models.interaction",
    "make_encoder": "simoun_agent.models.encoder",
}
"""Public name -> the module defining it, imported when the name is first read."""


def __getattr__(name: str) -> Any:
    if name == "encoders":
        return importlib.import_module("simoun_agent.models.encoder")
    if name not in _LAZY:
        raise missing_name(__name__, name)
    return getattr(importlib.import_module(_LAZY[name]), name)


def __dir__() -> list[str]:
    return sorted([*globals(), *__all__])


__all__ = ["AgentConfig", "encoders", *_LAZY]
