"""Agent recipes (simoun, drq, drqv2, rad, curl, sac, Fig. 6 encoders), the random shift and the
generic nested config: each recipe builds the losses, networks and augmented views it promises
and no others; DrQ's K/M averaging and target encoder and DrQ-v2's deterministic actor are
checked against values computed here."""

import copy
import dataclasses
import io
import json
import re

import numpy as np
import pytest
import torch
import torch.nn.functional as F
from test_train_resume import TINY

from simoun_agent import AgentConfig, FrameReplay, SimounAgent
from simoun_agent.config import RECIPES, SetupError, from_dict, resolve, to_dict
from simoun_agent.config.keys import config_sections
from simoun_agent.config.shapes import ENCODER_SHAPES
from simoun_agent.models.actors import DeterministicActor
from simoun_agent.models.encoder import ENCODERS
from simoun_agent.run import train
from simoun_lab.sweep.report import with_defaults
from simoun_wrappers.augment import random_shift, shift_pad

FRAME = (3, 24, 24)
SMALL = dict(batch_size=6, hidden_dim=32, aux_hidden_dim=16, num_filters=8, feature_dim=16)
AUX_LOSSES = {"transition_loss", "contrastive_loss", "reward_loss"}


def recipe_agent(name: str, **overrides) -> SimounAgent:
    config = resolve(None, {"agent.recipe": name}).agent
    # the reducing convs are set only where the encoder has them (elsewhere they are refused)
    reduce = {"reduce_stride": 2} if ENCODER_SHAPES[config.encoder].interactive else {}
    config = dataclasses.replace(config, **SMALL, **reduce, **overrides)
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


def random_replay() -> FrameReplay:
    """A replay of one 30-step episode of random frames, actions and rewards (seed 0)."""
    rng = np.random.default_rng(0)
    replay = FrameReplay(100, FRAME, 2, seed=0)
    replay.start_episode(rng.integers(0, 256, FRAME, dtype=np.uint8))
    for _ in range(30):
        frame = rng.integers(0, 256, FRAME, dtype=np.uint8)
        replay.add(rng.uniform(-1, 1, 2), rng.normal(), frame, False, False)
    return replay


def losses_of(agent: SimounAgent) -> set[str]:
    return set(agent.update_window(*window(), step=0)) & AUX_LOSSES


@pytest.mark.parametrize(
    ("name", "expected"),
    [
        ("simoun", AUX_LOSSES),
        ("drq", set()),
        ("drqv2", set()),
        ("rad", set()),
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


def test_sac_sees_unshifted_frames_and_rad_shifted_ones_with_the_next_obs_shifted_apart():
    frames, *_ = window()
    sac, rad = recipe_agent("sac"), recipe_agent("rad")
    plain, shifted = sac.augment(frames, None), rad.augment(frames, None)
    assert torch.equal(plain.windows[0], frames)
    assert torch.equal(plain.next_obs[0], frames[:, 1:4]) and plain.shared == 1
    assert not torch.equal(shifted.windows[0], frames)
    assert rad.shift_pad == shift_pad(FRAME[1]) == 1
    # RAD's curl_sac.py crops obs and next_obs by separate calls: the next triplet has its own
    # offset, so the critic's encoder pass cannot give it (shared 0)
    assert shifted.shared == 0 and shifted.next_obs[0].shape == frames[:, 1:4].shape
    assert not torch.equal(shifted.next_obs[0], shifted.windows[0][:, 1:4])
    assert torch.equal(random_shift(frames[:, 1:4], 0), frames[:, 1:4])


def test_rad_is_rad_s_published_sac():
    """RadSacAgent of RAD's curl_sac.py with train.py's values: the defaults' SAC (temperature
    init 0.1, lr 1e-4, beta1 0.5; critic tau 0.01, EMA target encoder 0.05 read by the TD
    target), delta-orthogonal conv init, obs and next_obs augmented independently."""
    expected = {"encoder": "stacked", "augmentation": "shift", "transition_weight": 0.0}
    expected.update(contrastive_weight=0.0, reward_weight=0.0, curiosity=False)
    expected.update(conv_init="delta_orthogonal", independent_next_shift=True)
    assert RECIPES["rad"].values == expected
    rad = resolve(None, {"agent.recipe": "rad"}).agent
    assert (rad.critic_augmentations, rad.target_augmentations) == (1, 1)
    assert (rad.next_state_encoder, rad.actor, rad.n_step) == ("target", "gaussian", 1)
    assert (rad.init_temperature, rad.alpha_lr, rad.alpha_beta) == (0.1, 1e-4, 0.5)
    assert (rad.critic_tau, rad.encoder_tau) == (0.01, 0.05)


@pytest.mark.parametrize("name", ["drq", "drqv2", "rad", "curl", "sac"])
def test_each_baseline_cites_its_paper_and_names_its_deviations(name):
    recipe = RECIPES[name]
    assert re.search(r"\([A-Z][^()]* (et al\. |& [A-Z]\w+ )?(19|20)\d\d[;)]", recipe.description)
    assert recipe.deviations and all(len(item) > 20 for item in recipe.deviations)
    # the published file and function it follows
    assert re.search(r"\w+\.py", recipe.description) and "hidden" in " ".join(recipe.deviations)
    if name in ("rad", "curl"):  # the crop of 100x100 renders the papers use
        assert any("random crop of 100x100" in item for item in recipe.deviations)


def perturb(module: torch.nn.Module, seed: int) -> None:
    gen = torch.Generator().manual_seed(seed)
    with torch.no_grad():
        for p in module.parameters():
            p.add_(torch.randn(p.shape, generator=gen) * 0.2)


def drq_critic_loss_by_hand(agent, frames, action, reward, discount, seed, value_encoder):
    """DrQ's critic loss written out: K = 2 next states, each shifted by an offset of its own
    (drq.py's next_obs and next_obs_aug), each through ``value_encoder`` for the target Q heads
    and the online encoder for the actor, their targets averaged; M = 2 shifted current states,
    each against that target, the losses averaged."""
    agent = copy.deepcopy(agent)
    torch.manual_seed(seed)
    views = [random_shift(frames, agent.shift_pad) for _ in range(2)]  # the update's draws
    next_views = [random_shift(frames[:, 1:], agent.shift_pad) for _ in range(2)]
    gamma, alpha = agent.config.discount, float(agent.alpha.detach())
    with torch.no_grad():
        next_obs = torch.cat(next_views)
        next_action, log_prob = agent.actor(agent.encoder(next_obs).state)
        q1_bar, q2_bar = agent.critic_target(value_encoder(agent)(next_obs).state, next_action)
        value = (torch.min(q1_bar, q2_bar) - alpha * log_prob)[:, 0].view(2, -1)
        targets = reward + gamma * discount * value  # (K, B): one target per next view
        y = targets.mean(0)
        q1, q2 = agent.critic(agent.encoder(torch.cat([v[:, :3] for v in views])).state,
                              torch.cat([action, action]))  # fmt: skip
    y = torch.cat([y, y])[:, None]
    loss = F.mse_loss(q1, y) + F.mse_loss(q2, y)
    return float(loss), views, targets


def test_drq_averages_two_augmented_targets_through_the_target_encoder_and_two_critic_views():
    agent = recipe_agent("drq")
    perturb(agent.encoder_target, seed=1)  # the target encoder differs from the online one
    frames, action, reward, _ = window()
    discount = torch.tensor([1.0, 0.0, 1.0, 1.0, 0.0, 1.0])
    target_encoder, online_encoder = (lambda a: a.encoder_target), (lambda a: a.encoder)
    expected, views, targets = drq_critic_loss_by_hand(
        agent, frames, action, reward, discount, 4, target_encoder
    )
    with_online, _, _ = drq_critic_loss_by_hand(
        agent, frames, action, reward, discount, 4, online_encoder
    )
    assert not torch.equal(views[0], views[1])  # two independent shifts of the window
    assert not torch.allclose(targets[0], targets[1])  # two different targets are averaged
    torch.manual_seed(4)
    metrics = agent.update_window(frames, action, reward, discount, step=0)
    assert float(metrics["critic_loss"]) == pytest.approx(expected, rel=1e-5)
    assert abs(with_online - expected) > 1e-3 * abs(expected)  # the test tells them apart


def test_drq_values_are_drq_s_published_ones():
    drq = resolve(None, {"agent.recipe": "drq"}).agent
    assert (drq.critic_augmentations, drq.target_augmentations) == (2, 2)
    assert (drq.next_state_encoder, drq.encoder_tau, drq.critic_tau) == ("target", 0.01, 0.01)
    assert (drq.init_temperature, drq.alpha_lr, drq.alpha_beta) == (0.1, 1e-3, 0.9)
    assert (drq.encoder, drq.augmentation, drq.actor, drq.n_step) == (
        "stacked", "shift", "gaussian", 1,
    )  # fmt: skip
    assert (drq.actor_update_every, drq.target_update_every) == (2, 2)
    with pytest.raises(ValueError, match="augmentation shift"):
        AgentConfig(encoder="stacked", curiosity=False, critic_augmentations=2)


def test_drqv2_has_no_temperature_and_acts_deterministically_at_evaluation():
    agent = recipe_agent("drqv2")
    assert isinstance(agent.actor, DeterministicActor)
    assert agent.log_alpha is None and agent.alpha is None
    assert "log_alpha" not in agent.state_dict() and "alpha_optimizer" not in agent.state_dict()
    frames, action, reward, discount = window()
    metrics = agent.update_window(frames, action, reward, discount, step=0)
    assert not {"alpha", "entropy"} & set(metrics) and "actor_loss" in metrics
    obs = frames[0, :3].numpy()
    with torch.no_grad():
        mu = agent.actor(agent.encoder(frames[:1, :3]).state)[0].numpy()
    evaluation = [agent.act(obs, deterministic=True) for _ in range(2)]
    np.testing.assert_allclose(evaluation[0], mu, rtol=1e-6)
    np.testing.assert_array_equal(evaluation[0], evaluation[1])
    assert not np.allclose(agent.act(obs), mu)  # exploration adds noise


def test_drqv2_noise_std_follows_the_linear_schedule_of_the_env_step():
    agent = recipe_agent("drqv2")
    config = agent.config
    assert (config.exploration_std_start, config.exploration_std_end) == (1.0, 0.1)
    # cartpole-swingup is one of DrQ-v2's easy tasks (cfgs/task/cartpole_swingup.yaml)
    assert (config.exploration_steps, config.noise_clip) == (200_000, 0.3)
    schedule = {0: 1.0, 50_000: 0.775, 100_000: 0.55, 200_000: 0.1, 3_000_000: 0.1}
    for step, std in schedule.items():
        assert agent.actor.std(step) == pytest.approx(std)
    with torch.no_grad():  # mu = 0, so the action is the clamped noise itself
        agent.actor.trunk[-1].weight.zero_()
        agent.actor.trunk[-1].bias.zero_()
    state = torch.zeros(20_000, agent.encoder.repr_dim)
    torch.manual_seed(0)
    for step in (160_000, 200_000):  # stds 0.28 and 0.1: the clamp at +-1 hardly matters
        noise = agent.actor.act(state, deterministic=False, step=step)
        assert float(noise.detach().std()) == pytest.approx(agent.actor.std(step), rel=0.02)
    # act() without a step uses the step of the latest update; the trainer passes its own
    frames, action, reward, discount = window()
    agent.update_window(frames, action, reward, discount, step=200_000)
    obs = frames[0, :3].numpy()
    samples = np.stack([agent.act(obs) for _ in range(400)])
    assert samples.std() == pytest.approx(0.1, rel=0.15)
    samples = np.stack([agent.act(obs, step=0) for _ in range(400)])
    assert samples.std() > 0.5


def test_drqv2_easy_is_drqv2_with_the_schedule_of_drqv2s_easy_tasks_alone():
    """drqv2 takes each task's schedule from DrQ-v2's cfgs/task/*.yaml: the easy one (that of
    drqv2_easy) on cartpole-swingup, the medium one on cheetah-run; drqv2_easy the easy one
    everywhere."""
    differ = {}
    for task in ("cartpole-swingup", "cheetah-run"):
        env = {"env": f"dm_control/{task}-v0"}
        drqv2 = to_dict(resolve("cpu", {**env, "agent.recipe": "drqv2"}))["agent"]
        easy = to_dict(resolve("cpu", {**env, "agent.recipe": "drqv2_easy"}))["agent"]
        differ[task] = {key for key in drqv2 if drqv2[key] != easy[key]}
        assert easy["exploration_steps"] == 200_000
        assert drqv2["exploration_steps"] == {"cartpole-swingup": 200_000}.get(task, 1_000_000)
    assert differ == {
        "cartpole-swingup": {"recipe"},
        "cheetah-run": {"recipe", "exploration_steps"},
    }
    agent = recipe_agent("drqv2_easy")
    schedule = {0: 1.0, 100_000: 0.55, 200_000: 0.1, 1_000_000: 0.1}
    for step, std in schedule.items():
        assert agent.actor.std(step) == pytest.approx(std)


def test_drqv2_target_and_actor_loss_read_min_q_at_the_clipped_noisy_action():
    """TD target r + gamma d min(Qbar)(s', clamp(mu(s') + clip(std eps, +-0.3))) through the
    online encoder on o_{t+1} under a shift of its own, no entropy term (Qbar: the critic
    target with its own EMA trunk); actor loss -min Q(s, clamp(mu(s) + clip(std eps)))."""
    agent = recipe_agent("drqv2")
    perturb(agent.encoder_target, seed=1)  # never read: DrQ-v2's target uses the online one
    perturb(agent.critic_target.trunk, seed=2)  # the target's trunk is its own
    frames, action, reward, discount = window()
    discount[1] = 0.0
    step, gamma = 100_000, agent.config.discount
    std = agent.actor.std(step)
    by_hand = copy.deepcopy(agent)
    torch.manual_seed(5)
    with torch.no_grad():
        shifted = random_shift(frames, by_hand.shift_pad)
        next_state = by_hand.encoder(random_shift(frames[:, 1:], by_hand.shift_pad)).state
        mu = by_hand.actor(next_state)
        noise = (std * torch.randn_like(mu)).clamp(-0.3, 0.3)
        q1_bar, q2_bar = by_hand.critic_target(next_state, (mu + noise).clamp(-1, 1))
        y = (reward + gamma * discount * torch.min(q1_bar, q2_bar)[:, 0])[:, None]
        state = by_hand.encoder(shifted[:, :3]).state
        q1, q2 = by_hand.critic(state, action)
    expected_critic = float(F.mse_loss(q1, y) + F.mse_loss(q2, y))
    critic = copy.deepcopy(agent)
    torch.manual_seed(5)
    metrics = critic.update_window(frames, action, reward, discount, step=step)
    assert float(metrics["critic_loss"]) == pytest.approx(expected_critic, rel=1e-5)
    assert float(metrics["exploration_std"]) == pytest.approx(std)

    state = torch.randn(6, agent.encoder.repr_dim)
    torch.manual_seed(6)
    with torch.no_grad():
        mu = agent.actor(state)
        noise = (std * torch.randn_like(mu)).clamp(-0.3, 0.3)
        expected_actor = -float(torch.min(*agent.critic(state, (mu + noise).clamp(-1, 1))).mean())
    assert float(noise.abs().max()) == pytest.approx(0.3)  # the clip was active
    torch.manual_seed(6)
    assert float(agent.update_actor(state, step)["actor_loss"]) == pytest.approx(
        expected_actor, rel=1e-5
    )


def test_drqv2_steps_critic_actor_and_targets_together_on_3_step_returns_every_2nd_decision():
    """DrQV2Agent.update: one critic, one actor and one EMA step per gradient step, which the
    training loop takes at every 2nd agent step (update_every_steps)."""
    agent = recipe_agent("drqv2")
    assert agent.config.n_step == 3 and agent.config.lr == 1e-4
    assert agent.config.update_every_steps == 2
    replay = random_replay()
    moved = []
    for step in range(4):
        before = {name: copy.deepcopy(getattr(agent, name)) for name in ("actor", "critic_target")}
        agent.update(replay, step)
        moved.append(
            {
                name
                for name, old in before.items()
                if any(
                    not torch.equal(a, b)
                    for a, b in zip(
                        old.parameters(), getattr(agent, name).parameters(), strict=True
                    )
                )
            }
        )
    assert moved == [{"actor", "critic_target"}] * 4


def test_a_run_saved_as_the_old_drq_loads_with_this_version_s_defaults():
    """config.json of a run made when 'drq' was SAC + shift: its values load as saved, the keys
    it predates take this version's defaults, which are its behaviour (one view, online next
    state, Gaussian actor); simoun-report's with_defaults relabels it 'rad', what it ran."""
    saved = to_dict(resolve("cpu", {"agent.recipe": "rad"}))
    saved["agent"]["recipe"] = "drq"
    new_keys = ("critic_augmentations", "target_augmentations", "next_state_encoder", "actor")
    new_keys += ("exploration_std_start", "exploration_std_end", "exploration_steps")
    for key in (*new_keys, "noise_clip"):
        del saved["agent"][key]
    config = from_dict(json.loads(json.dumps(saved)))
    assert config.agent.recipe == "drq" and config.agent.augmentation == "shift"
    assert (config.agent.critic_augmentations, config.agent.target_augmentations) == (1, 1)
    assert (config.agent.next_state_encoder, config.agent.actor) == ("online", "gaussian")
    report = with_defaults(saved)
    assert report["agent"]["critic_augmentations"] == 1 and report["agent"]["recipe"] == "rad"
    faithful = to_dict(resolve("cpu", {"agent.recipe": "drq"}))
    assert with_defaults(faithful)["agent"]["recipe"] == "drq"
    SimounAgent(FRAME, 2, dataclasses.replace(config.agent, **SMALL), device="cpu")


def test_curl_key_is_an_independent_shift_of_the_unshifted_stack():
    torch.manual_seed(0)
    agent = recipe_agent("curl", shift_pad=3)
    frames, *_ = window()
    views = agent.augment(frames, None)
    anchor_input, key = views.windows[0][:, :-1], views.key
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
    config = resolve("cpu", {"agent.recipe": "rad", "agent.alpha_lr": 5e-4})
    assert config.agent.encoder == "stacked" and config.agent.augmentation == "shift"
    assert config.agent.alpha_lr == 5e-4  # the user's value wins over the recipe's 1e-3
    assert config.agent.batch_size == 64  # the preset's value stays
    assert not config.agent.curiosity and config.agent.recipe == "rad"


def test_recipe_is_saved_and_reloaded_with_the_run(tmp_path):
    config = resolve(None, {**TINY, "agent.recipe": "curl", "run_dir": str(tmp_path / "run")})
    run = train.create_run(config)
    saved = json.loads((tmp_path / "run" / "config.json").read_text())
    assert saved["agent"]["recipe"] == "curl"
    assert saved["agent"]["contrastive_view"] == "shift"
    run.env.close()
    run.eval_env.close()


@pytest.mark.parametrize(
    ("name", "changed"),
    [
        ("simoun_no_curiosity", {"curiosity": False}),
        ("simoun_no_interaction", {"encoder": "dual"}),
        (
            "simoun_no_aux",
            {"transition_weight": 0.0, "contrastive_weight": 0.0, "reward_weight": 0.0},
        ),
    ],
)
def test_each_simoun_ablation_differs_from_simoun_in_its_part_alone(name, changed):
    simoun = to_dict(resolve("cpu", {"agent.recipe": "simoun"}))["agent"]
    ablation = to_dict(resolve("cpu", {"agent.recipe": name}))["agent"]
    differing = {key for key in simoun if simoun[key] != ablation[key]}
    assert differing == set(changed) | {"recipe"}
    assert {key: ablation[key] for key in changed} == changed
    assert simoun["n_step"] == ablation["n_step"] == 3 and ablation["augmentation"] == "shift"


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


@pytest.mark.parametrize("name", ["drq", "drqv2"])
def test_state_dict_resumes_drq_and_drqv2_bit_exactly(name):
    """Their extra state: DrQ's target encoder, DrQ-v2's env step (act()'s default schedule
    step) and its lack of a temperature."""
    replay = random_replay()
    agent = recipe_agent(name)
    for step in range(2):
        agent.update(replay, 1000 * step)
    checkpoint = io.BytesIO()  # as simoun-train's checkpoints do
    torch.save(agent.state_dict(), checkpoint)
    saved = torch.get_rng_state(), copy.deepcopy(replay)
    runs = []
    for candidate in (agent, recipe_agent(name)):
        checkpoint.seek(0)
        candidate.load_state_dict(torch.load(checkpoint, weights_only=False))
        torch.set_rng_state(saved[0])
        again = copy.deepcopy(saved[1])
        assert candidate.env_step == 1000
        actions = [candidate.act(again.sample(1)["obs"][0])]
        candidate.update(again, 2000)
        actions.append(candidate.act(again.sample(1)["obs"][0]))
        runs.append(
            (actions, [p.clone() for n in candidate.modules().values() for p in n.parameters()])
        )
    assert all(np.array_equal(a, b) for a, b in zip(runs[0][0], runs[1][0], strict=True))
    assert all(torch.equal(a, b) for a, b in zip(runs[0][1], runs[1][1], strict=True))


def test_an_agent_config_naming_a_recipe_carries_the_recipe_s_values():
    config = AgentConfig(recipe="drqv2")
    for key, value in RECIPES["drqv2"].values.items():
        assert getattr(config, key) == value, key
    agent = SimounAgent((3, 32, 32), 1, dataclasses.replace(config, batch_size=8), device="cpu")
    assert isinstance(agent.actor, DeterministicActor)
    assert AgentConfig("drq").critic_augmentations == 2  # the recipe given by position


def test_fields_given_beside_a_recipe_override_it_as_on_the_command_line():
    config = AgentConfig(recipe="drqv2", lr=3e-4, actor="gaussian")
    assert (config.lr, config.actor, config.n_step) == (3e-4, "gaussian", 3)
    overrides = {"agent.recipe": "drqv2", "agent.lr": 3e-4}
    anywhere = resolve(None, {**overrides, "env": "Pendulum-v1"}).agent
    assert AgentConfig(recipe="drqv2", lr=3e-4) == anywhere
    # a DMC task's own values come with resolve: DrQ-v2's easy schedule on cartpole-swingup
    assert resolve(None, overrides).agent.exploration_steps == 200_000


def test_a_saved_config_lacking_a_key_takes_the_default_not_the_recipe_s_value():
    saved = to_dict(resolve("cpu", {"agent.recipe": "drqv2"}))
    del saved["agent"]["update_every_steps"]  # as if saved before the key existed
    assert from_dict(json.loads(json.dumps(saved))).agent.update_every_steps == 1


@pytest.mark.parametrize(
    "task",
    ["cartpole-swingup", "cartpole_swingup", "dm_control/cartpole-swingup-v0", "Cartpole-Swingup"],
)
def test_values_for_matches_a_task_by_its_env_id_and_spellings(task):
    assert RECIPES["drqv2"].values_for(task)["exploration_steps"] == 200_000


@pytest.mark.parametrize("task", [None, "simoun/PointReach-v0", "cartpole-swingup_sparse"])
def test_values_for_gives_the_base_values_on_any_other_env(task):
    assert RECIPES["drqv2"].values_for(task) == RECIPES["drqv2"].values


def test_values_for_names_a_task_one_typo_away():
    with pytest.raises(ValueError, match=r"values_for\('cartpol-swingup'\).*'cartpole-swingup'"):
        RECIPES["drqv2"].values_for("cartpol-swingup")


def test_a_recipe_with_a_space_is_quoted_with_the_match():
    with pytest.raises(ValueError, match=r"--agent\.recipe 'drq ' .*did you mean 'drq'\?"):
        AgentConfig(recipe="drq ")
