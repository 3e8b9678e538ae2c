"""The reference Simoun SAC agent."""

import simoun_wrappers  # noqa: F401  (headless rendering defaults)
from simoun_agent.agent import SimounAgent
from simoun_agent.config import AgentConfig
from simoun_agent.models import encoder as encoders
from simoun_agent.models.encoder import (
    DualPathEncoder,
    FlareEncoder,
    SingleFrameEncoder,
    StackedEncoder,
    make_encoder,
)
from simoun_agent.models.interaction import StructuralInteraction
from simoun_agent.replay import FrameReplay

__all__ = [
    "AgentConfig",
    "DualPathEncoder",
    "FlareEncoder",
    "FrameReplay",
    "SimounAgent",
    "SingleFrameEncoder",
    "StackedEncoder",
    "StructuralInteraction",
    "encoders",
    "make_encoder",
]
