"""Running the agent: configs and presets, environments, the training loop, evaluation,
checkpoints, logs and videos."""

from simoun_wrappers._homes import missing_name


def __getattr__(name: str) -> object:
    raise missing_name(__name__, name)
