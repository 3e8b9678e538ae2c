"""The closed form of the smallest frame (simoun_agent.config.shapes) against the real encoders:
for every registered encoder, several interactive-module convs and several frame sizes, a frame
the closed form accepts builds and runs, and one it refuses fails in torch."""

import pytest
import torch

from simoun_agent.config import AgentConfig, SetupError, resolve
from simoun_agent.config.agent import ACTOR_NAMES
from simoun_agent.config.shapes import (
    ENCODER_SHAPES,
    TRUNK,
    conv_output_size,
    frame_fits,
    min_image_size,
)
from simoun_agent.models.actors import ACTORS
from simoun_agent.models.encoder import ENCODERS, conv_trunk, make_encoder

REDUCTIONS = [(3, 3), (5, 2), (1, 1), (4, 4)]
"""(reduce_kernel, reduce_stride) of the interactive module: the default, and others."""

CASES = [
    (name, kernel, stride)
    for name in ENCODERS
    for kernel, stride in (REDUCTIONS if ENCODER_SHAPES[name].interactive else [(3, 3)])
]


def _config(name: str, kernel: int, stride: int) -> AgentConfig:
    return AgentConfig(
        encoder=name,
        curiosity=ENCODERS[name].motion_path,
        num_filters=2,
        feature_dim=4,
        reduce_kernel=kernel,
        reduce_stride=stride,
    )


def _runs(config: AgentConfig, height: int, width: int) -> bool:
    """Whether the torch encoder builds and encodes one observation of height x width."""
    frames = torch.zeros(1, config.num_frames, 3, height, width, dtype=torch.uint8)
    try:
        with torch.no_grad():
            make_encoder(config, (3, height, width))(frames)
    except RuntimeError:
        return False
    return True


def test_the_registries_and_the_configuration_name_the_same_encoders_and_actors():
    assert list(ENCODERS) == list(ENCODER_SHAPES)
    assert all(ENCODERS[name].shape is ENCODER_SHAPES[name] for name in ENCODERS)
    assert set(ACTORS) == set(ACTOR_NAMES)


@pytest.mark.parametrize("size", [15, 19, 24, 48, 84])
def test_conv_output_size_is_the_side_of_the_built_trunk(size):
    maps = conv_trunk(3, 2)(torch.zeros(1, 3, size, size))
    assert maps.shape[-2:] == (conv_output_size(size, TRUNK),) * 2
    assert conv_output_size(84) == 35


@pytest.mark.filterwarnings("ignore:Initializing zero-element tensors")
@pytest.mark.parametrize(("name", "kernel", "stride"), CASES)
def test_the_smallest_size_builds_and_one_smaller_fails(name, kernel, stride):
    config = _config(name, kernel, stride)
    size = min_image_size(config)
    assert _runs(config, size, size), f"{name} at its smallest {size}x{size}"
    assert not _runs(config, size - 1, size - 1), f"{name} at {size - 1}x{size - 1}"
    assert not _runs(config, size - 1, 3 * size), "the height alone is too small"
    assert not _runs(config, size, size - 1), "the width alone is too small"


@pytest.mark.filterwarnings("ignore:Initializing zero-element tensors")
@pytest.mark.parametrize(("name", "kernel", "stride"), CASES)
def test_frame_fits_agrees_with_the_encoder_at_many_sizes(name, kernel, stride):
    config = _config(name, kernel, stride)
    for height, width in [(7, 7), (14, 14), (15, 15), (18, 30), (19, 19), (22, 23), (32, 96)]:
        assert frame_fits(config, height, width) == _runs(config, height, width), (height, width)


def test_the_closed_form_of_the_paper_encoders():
    assert min_image_size(AgentConfig()) == 19  # 19 -> 9 -> 7 -> 5 -> 3 -> 1 (reduce 3/3)
    assert min_image_size(AgentConfig(encoder="dual")) == 15  # 15 -> 7 -> 5 -> 3 -> 1
    assert min_image_size(AgentConfig(reduce_kernel=5, reduce_stride=2)) == 23


@pytest.mark.parametrize("cameras", [1, 3])
def test_a_train_config_is_refused_just_below_the_smallest_size(cameras):
    agent = {"agent.reduce_kernel": 5, "agent.reduce_stride": 2, "cameras": cameras}
    assert resolve(None, {**agent, "image_size": 23}).image_size == 23
    with pytest.raises(
        SetupError,
        match=r"--image-size 22 \(TrainConfig.image_size\): too small .* --image-size 23 "
        r"\(TrainConfig.image_size=23\) or more",
    ):
        resolve(None, {**agent, "image_size": 22})
