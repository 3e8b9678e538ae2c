"""The features that set pyproject.toml's dependency floors, used as the code uses them; with
SIMOUN_FLOORS=core or =extras (scripts/test_floors.sh, in .venv-floors) also that every direct
dependency of the package and its dev extra, or of the optional extras, is installed at exactly
its floor, so the runs there prove the floors true."""

import os
from importlib import metadata

import gymnasium as gym
import numpy as np
import pytest
import torch
from packaging.requirements import Requirement
from packaging.version import Version

from simoun_agent.cli import train as train_cli
from simoun_agent.run.logger import CURVE_PNG

EXTRAS = ("dmc", "highway", "minigrid", "multiagent", "sb3")
"""The extras scripts/test_floors.sh installs at their floors (lab pins ray exactly)."""


def floors(kind: str) -> dict[str, Version]:
    """Direct dependency -> its ``>=`` floor, as the installed package declares them: the
    package's own and its dev extra's (``"core"``), or those of :data:`EXTRAS` (``"extras"``)."""
    extras = ("dev",) if kind == "core" else EXTRAS
    found = {}
    for text in metadata.requires("simoun"):
        requirement = Requirement(text)
        marker = requirement.marker
        if marker is None and kind != "core":
            continue
        if marker is not None and not any(marker.evaluate({"extra": e}) for e in extras):
            continue
        if requirement.name == "simoun":  # the "all" extra
            continue
        lows = [s.version for s in requirement.specifier if s.operator == ">="]
        assert lows, f"{text!r} has no >= floor"
        found[requirement.name] = Version(lows[0])
    return found


@pytest.mark.skipif(not os.environ.get("SIMOUN_FLOORS"), reason="only in .venv-floors")
def test_every_direct_dependency_is_installed_at_its_floor():
    wanted = floors(os.environ["SIMOUN_FLOORS"])
    assert {name: Version(metadata.version(name)) for name in wanted} == wanted


def test_fused_adam_steps_on_the_cpu():
    """torch >= 2.4: the agent's three optimisers are fused Adam on whatever device it uses."""
    weight = torch.nn.Parameter(torch.ones(3))
    optimizer = torch.optim.Adam([weight], lr=0.1, fused=True)
    weight.sum().backward()
    optimizer.step()
    np.testing.assert_allclose(weight.detach().numpy(), np.full(3, 0.9), rtol=1e-5)


def test_numpy_trapezoid_and_gymnasium_autoreset_modes():
    """numpy >= 2.0 (np.trapezoid, the report's AUC) and gymnasium >= 1.1 (AutoresetMode, the
    background env process and the vector wrappers)."""
    assert np.trapezoid([0.0, 1.0, 1.0], [0.0, 1.0, 2.0]) == pytest.approx(1.5)
    modes = {mode.name for mode in gym.vector.AutoresetMode}
    assert {"NEXT_STEP", "SAME_STEP", "DISABLED"} <= modes


def test_a_tiny_training_run_draws_resizes_logs_and_records(tmp_path):
    """opencv resizes the frames, matplotlib draws the curve, tensorboard logs, imageio and
    imageio-ffmpeg write the video, tqdm is imported by the loop, tyro parses the command line."""
    run_dir = tmp_path / "run"
    argv = [
        "--env", "simoun/PointReach-v0", "--image-size", "24", "--total-env-steps", "16",
        "--warmup-agent-steps", "8", "--eval-every", "16", "--eval-episodes", "1",
        "--checkpoint-every", "16", "--device", "cpu", "--torch-threads", "1",
        "--agent.batch-size", "4", "--agent.num-filters", "4", "--agent.feature-dim", "8",
        "--agent.hidden-dim", "16", "--agent.aux-hidden-dim", "16", "--run-dir", str(run_dir),
        "--no-progress", "--video",
    ]  # fmt: skip
    assert train_cli.main(argv) == 0
    assert (run_dir / CURVE_PNG).stat().st_size > 1000
    assert (run_dir / "video.mp4").stat().st_size > 0
    assert any(path.name.startswith("events.out.tfevents") for path in (run_dir / "tb").iterdir())
