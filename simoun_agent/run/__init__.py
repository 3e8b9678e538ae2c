"""Running the agent: configs and presets, environments, the training loop, evaluation,
checkpoints, logs and videos."""
