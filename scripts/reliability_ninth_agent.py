"""The ninth reliability trial's cases: agent (see reliability_trial.py)."""

CASES: list[dict] = []
