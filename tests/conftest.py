"""Shared fixtures. Importing simoun_wrappers first sets the headless rendering defaults."""

import pytest

import simoun_wrappers  # noqa: F401


@pytest.fixture(autouse=True)
def one_torch_thread():
    """One torch thread per test: the suite runs on two xdist workers on two cores, and the
    tensors are small, so a second thread per worker only spin-waits (measured up to 10x slower)."""
    import torch

    threads = torch.get_num_threads()
    torch.set_num_threads(1)
    yield
    torch.set_num_threads(threads)
