"""The eleventh reliability trial's cases: agent (see reliability_trial.py)."""

CASES: list[dict] = []
