"""Agent recipes (simoun, drq, curl, sac, Fig. 6 encoders), the random shift and the generic
nested config: each recipe builds the losses it promises and no others."""

import dataclasses
import json

import pytest
import torch
import torch.nn.functional as F
from test_train_resume import TINY

from simoun_agent import AgentConfig, SimounAgent
from simoun_agent.models.encoder import ENCODERS
from simoun_agent.recipes import RECIPES
from simoun_agent.run import train
from simoun_agent.run.presets import SetupError, config_sections, resolve
from simoun_wrappers.augment import random_shift, shift_pad

FRAME = (3, 24, 24)
SMALL = dict(batch_size=6, hidden_dim=32, aux_hidden_dim=16, num_filters=8, feature_dim=16)
AUX_LOSSES = {"transition_loss", "contrastive_loss", "reward_loss"}


def recipe_agent(name: str, **overrides) -> SimounAgent:
    config = resolve(None, {"agent.recipe": name}).agent
    config = dataclasses.replace(config, **SMALL, reduce_stride=2, **overrides)
    return SimounAgent(FRAME, 2, config, device="cpu")


def window(batch: int = 6, seed: int = 0) -> tuple[torch.Tensor, ...]:
    gen = torch.Generator().manual_seed(seed)
    frames = torch.randint(0, 256, (batch, 4, *FRAME), generator=gen, dtype=torch.uint8)
    return (
        frames,
        torch.rand(batch, 2, generator=gen) * 2 - 1,
        torch.randn(batch),
        torch.ones(batch),
    )


def losses_of(agent: SimounAgent) -> set[str]:
    return set(agent.update_window(*window(), step=0)) & AUX_LOSSES


@pytest.mark.parametrize(
    ("name", "expected"),
    [
        ("simoun", AUX_LOSSES),
        ("drq", set()),
        ("sac", set()),
        ("curl", {"contrastive_loss"}),
        *((name, AUX_LOSSES) for name in ("single", "stacked", "flare", "dual", "stacked_wide")),
    ],
)
def test_each_recipe_builds_the_losses_it_promises_and_no_others(name, expected):
    agent = recipe_agent(name)
    assert losses_of(agent) == expected
    built = {"transition", "similarity", "reward_model"} & set(agent.modules())
    wanted = {"transition_loss": "transition", "contrastive_loss": "similarity"}
    wanted["reward_loss"] = "reward_model"
    assert built == {wanted[loss] for loss in expected}


def test_single_path_encoders_train_l_tran_on_their_state():
    agent = recipe_agent("stacked")
    assert not agent.motion_path and agent.transition is not None
    before = [p.detach().clone() for p in agent.transition.parameters()]
    metrics = agent.update_window(*window(), step=0)
    assert metrics["transition_loss"] > 0
    after = agent.transition.parameters()
    assert any(not torch.equal(b, p) for b, p in zip(before, after, strict=True))


class Spy:
    """Records the uint8 windows the encoder is given (and the contrastive key views)."""

    def __init__(self, agent: SimounAgent) -> None:
        self.windows, self.keys = [], []
        encode, key = agent.encoder.encode_transition, agent.encoder_target.encode_key

        def spy_transition(w: torch.Tensor, **kwargs):
            self.windows.append(w)
            return encode(w, **kwargs)

        def spy_key(view: torch.Tensor) -> torch.Tensor:
            self.keys.append(view)
            return key(view)

        agent.encoder.encode_transition = spy_transition
        agent.encoder_target.encode_key = spy_key


def test_sac_sees_unshifted_frames_and_drq_shifted_ones():
    frames, *rest = window()
    sac, drq = recipe_agent("sac"), recipe_agent("drq")
    seen = {}
    for name, agent in (("sac", sac), ("drq", drq)):
        spy = Spy(agent)
        agent.update_window(frames, *rest, step=0)
        seen[name] = spy.windows[0]
    assert torch.equal(seen["sac"], frames)
    assert not torch.equal(seen["drq"], frames)
    assert drq.shift_pad == shift_pad(FRAME[1]) == 1


def test_curl_key_is_an_independent_shift_of_the_unshifted_stack():
    torch.manual_seed(0)
    agent = recipe_agent("curl", shift_pad=3)
    spy = Spy(agent)
    frames, *rest = window()
    agent.update_window(frames, *rest, step=0)
    anchor_input, key = spy.windows[0][:, :-1], spy.keys[0]
    assert key.shape == (6, 3, *FRAME)  # the whole stack, as floats in [0, 1]
    assert not torch.equal(key, anchor_input.float() / 255)  # its own offsets
    # every sample's key is the stack itself under one of the (2 pad + 1)^2 shifts
    padded = F.pad(frames[:, :-1].flatten(1, 2).float(), (3, 3, 3, 3), mode="replicate")
    for b in range(6):
        crops = [padded[b, :, i : i + 24, j : j + 24] for i in range(7) for j in range(7)]
        assert any(torch.equal(c / 255, key[b].flatten(0, 1)) for c in crops)


def test_shift_uses_one_offset_per_sample_so_residuals_stay_residuals():
    gen = torch.Generator().manual_seed(1)
    base = torch.randint(0, 200, (16, 1, 3, 20, 20), generator=gen, dtype=torch.uint8)
    frames = base + torch.arange(4, dtype=torch.uint8).view(1, 4, 1, 1, 1)
    shifted = random_shift(frames, pad=3, generator=gen)
    residuals = shifted[:, 1:].int() - shifted[:, :-1].int()
    assert torch.all(residuals == 1)  # a different offset per frame would mix positions
    assert not torch.equal(shifted, frames)


def test_random_shift_equals_replicate_pad_then_crop():
    frames = torch.randint(0, 256, (5, 2, 3, 10, 12), dtype=torch.uint8)
    shifted = random_shift(frames, 2, generator=torch.Generator().manual_seed(0))
    offsets = torch.randint(0, 5, (2, 5, 1), generator=torch.Generator().manual_seed(0))
    for b in range(5):
        padded = F.pad(frames[b].float(), (2, 2, 2, 2), mode="replicate")
        dy, dx = int(offsets[0, b]), int(offsets[1, b])
        assert torch.equal(padded[..., dy : dy + 10, dx : dx + 12].to(torch.uint8), shifted[b])


def test_recipe_applies_after_the_preset_and_before_user_overrides():
    config = resolve("cpu", {"agent.recipe": "drq", "agent.alpha_lr": 5e-4})
    assert config.agent.encoder == "stacked" and config.agent.augmentation == "shift"
    assert config.agent.alpha_lr == 5e-4  # the user's value wins over the recipe's 1e-3
    assert config.agent.batch_size == 64  # the preset's value stays
    assert not config.agent.curiosity and config.agent.recipe == "drq"


def test_recipe_is_saved_and_reloaded_with_the_run(tmp_path):
    config = resolve(None, {**TINY, "agent.recipe": "curl", "run_dir": str(tmp_path / "run")})
    run = train.create_run(config)
    saved = json.loads((tmp_path / "run" / "config.json").read_text())
    assert saved["agent"]["recipe"] == "curl"
    assert saved["agent"]["contrastive_view"] == "shift"
    run.env.close()
    run.eval_env.close()


def test_unknown_recipe_suggests_the_close_one():
    with pytest.raises(SetupError, match=r"--agent.recipe 'dqr' \(did you mean 'drq'\?\)"):
        resolve(None, {"agent.recipe": "dqr"})


def test_every_recipe_resolves_and_every_encoder_is_registered():
    for name in RECIPES:
        assert resolve(None, {"agent.recipe": name}).agent.encoder in ENCODERS
    with pytest.raises(ValueError, match="choose one of single, stacked"):
        AgentConfig(encoder="resnet")


def test_config_sections_are_found_from_the_dataclass_fields():
    sections = config_sections()
    assert set(sections) == {"", "agent."}
    config = resolve(None, {"env_kwargs": {"agent": {"lr": 1}}})
    assert config.env_kwargs == {"agent": {"lr": 1}}  # a dict value, not a section
