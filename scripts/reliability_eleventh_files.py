"""The eleventh reliability trial's cases: files (see reliability_trial.py)."""

CASES: list[dict] = []
