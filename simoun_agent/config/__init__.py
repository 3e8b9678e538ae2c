"""Configuration of the agent and of training runs: a leaf that imports no torch and nothing of
the agent, the models, the run layer or the command lines.

======================  ===================================================================
``agent``               ``AgentConfig`` and the rule of each field
``train``               ``TrainConfig`` and the rule of each field
``presets``             named ``TrainConfig`` overrides (``--preset cpu``)
``recipes``             named ``AgentConfig`` values: Simoun, its baselines, the Fig. 6 encoders
``resolve``             defaults -> preset -> recipe -> overrides; ``config.json`` round trip
``keys``                flat keys (``agent.lr``), typed ``--set`` values, unknown-key refusal
``key_match``           close matches of a misspelled key, by words and docstrings
``rules``               :class:`~simoun_agent.config.rules.Rule`, ``setting`` and the field check
``shapes``              encoder geometry and the smallest frame, in closed form
``envs``                environment ids: MODULE:ID, the paper's DMC tasks, highway-env
``device``              whether a ``--device`` is on this machine
``errors``              ``SetupError``, the error a user can fix
======================  ===================================================================

Example:
    >>> from simoun_agent.config import AgentConfig, resolve
    >>> resolve("cpu", {"agent.lr": 3e-4}).agent.lr == AgentConfig(lr=3e-4).lr
    True
"""

from simoun_agent.config.agent import AgentConfig
from simoun_agent.config.errors import SetupError
from simoun_agent.config.presets import PRESETS, Preset
from simoun_agent.config.recipes import RECIPES, Recipe
from simoun_agent.config.resolve import from_dict, resolve, to_dict
from simoun_agent.config.train import TrainConfig

__all__ = [
    "PRESETS",
    "RECIPES",
    "AgentConfig",
    "Preset",
    "Recipe",
    "SetupError",
    "TrainConfig",
    "from_dict",
    "resolve",
    "to_dict",
]
