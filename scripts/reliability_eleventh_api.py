"""The eleventh reliability trial's cases: api (see reliability_trial.py)."""

CASES: list[dict] = []
