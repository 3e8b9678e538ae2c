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
from simoun_agent.models.encoder import ENCODERS, conv_trunk

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
    """Whether the torch encoder builds and encodes one observation of height x width: built
    as make_encoder builds it, less make_encoder's own check of the frame (the closed form
    under test)."""
    frames = torch.zeros(1, config.num_frames, 3, height, width, dtype=torch.uint8)
    try:
        encoder = ENCODERS[config.encoder].build(config, (3, height, width))
        encoder.pixel_offset = config.pixel_offset
        with torch.no_grad():
            encoder(frames)
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


def test_a_reducing_kernel_too_wide_for_the_frames_names_every_setting_that_fixes_it():
    with pytest.raises(SetupError) as error:
        resolve(None, {"image_size": 32, "agent.reduce_kernel": 41})
    message = str(error.value)
    assert message.startswith(
        "--image-size 32 (TrainConfig.image_size): too small for the conv trunk of encoder "
        "'dual_interactive' with --agent.reduce-kernel 41 (AgentConfig.reduce_kernel=41); set "
    )
    for fix in (
        "--image-size 95 (TrainConfig.image_size=95) or more",
        "--agent.reduce-kernel 9 (AgentConfig.reduce_kernel=9) or less",
        "--agent.encoder dual (AgentConfig.encoder='dual')",
    ):
        assert fix in message
    # each fix it names works: 32 -> 15 -> 13 -> 11 -> 9 through the trunk
    assert resolve(None, {"image_size": 95, "agent.reduce_kernel": 41}).image_size == 95
    assert resolve(None, {"image_size": 32, "agent.reduce_kernel": 9}).agent.reduce_kernel == 9
    # the dual encoder reads no reducing kernel, so that fix puts the kernel back too
    assert (
        "--agent.encoder dual (AgentConfig.encoder='dual'), which has no reducing conv and "
        "--agent.reduce-kernel 3 (AgentConfig.reduce_kernel=3)"
    ) in message
    assert resolve(None, {"image_size": 32, "agent.encoder": "dual"}).agent.encoder == "dual"


def test_a_frame_the_trunk_alone_cannot_take_is_answered_with_the_image_size_only():
    with pytest.raises(SetupError) as error:
        resolve(None, {"image_size": 12})
    assert "--agent.reduce-kernel" not in str(error.value).partition("; set ")[2].split(" (")[0]
    assert "--image-size 19 (TrainConfig.image_size=19) or more" in str(error.value)
    assert "--agent.encoder dual" not in str(error.value)


def test_a_random_conv_kernel_wider_than_the_frames_is_refused_before_training():
    with pytest.raises(SetupError) as error:
        resolve(None, {"image_size": 32, "agent.random_conv_kernel": 33})
    message = str(error.value)
    assert message.startswith(
        "--agent.random-conv-kernel 33 (AgentConfig.random_conv_kernel): the random convolution"
    )
    for fix in (
        "--agent.random-conv-kernel 3 (AgentConfig.random_conv_kernel=3)",
        "any odd value up to 31",
        "--image-size 33 (TrainConfig.image_size=33) or more",
        "--agent.contrastive-view shift",
    ):
        assert fix in message
    assert resolve(None, {"image_size": 32, "agent.random_conv_kernel": 31}).image_size == 32
    assert resolve(None, {"image_size": 33, "agent.random_conv_kernel": 33}).image_size == 33
    # a kernel nothing runs (L_con off, or its positive a shift) is refused as unread
    for unused in ({"agent.contrastive_weight": 0.0}, {"agent.contrastive_view": "shift"}):
        with pytest.raises(SetupError, match="would change nothing"):
            resolve(None, {"image_size": 32, "agent.random_conv_kernel": 33, **unused})
        assert resolve(None, {"image_size": 32, **unused}).agent.random_conv_kernel == 3


def test_the_agent_refuses_frames_its_random_convolution_or_reducing_conv_cannot_take():
    from simoun_agent import SimounAgent

    small = AgentConfig(batch_size=8, num_filters=4, random_conv_kernel=33)
    with pytest.raises(ValueError, match=r"random_conv_kernel=33 is wider than the 32x32 frames"):
        SimounAgent((3, 32, 32), 1, small)
    wide = AgentConfig(batch_size=8, num_filters=4, reduce_kernel=41)
    with pytest.raises(ValueError, match=r"lower AgentConfig.reduce_kernel=41 to 9 or less"):
        SimounAgent((3, 32, 32), 1, wide)
