"""The ninth reliability trial's cases: api (see reliability_trial.py)."""

CASES: list[dict] = []
