"""The eleventh reliability trial's cases: lab (see reliability_trial.py)."""

CASES: list[dict] = []
