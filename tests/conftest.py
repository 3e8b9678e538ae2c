"""Shared fixtures. Importing simoun_wrappers first sets the headless rendering defaults."""

import simoun_wrappers  # noqa: F401
