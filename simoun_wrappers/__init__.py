"""Gymnasium and PettingZoo wrappers for the Simoun method."""

from simoun_wrappers import _headless  # noqa: F401  (must run before dm_control/pygame load)
