"""The reference Simoun SAC agent."""

import simoun_wrappers  # noqa: F401  (headless rendering defaults)
