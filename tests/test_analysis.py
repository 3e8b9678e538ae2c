"""simoun-analyze: the estimator of Kowal et al., the pairs, the structure-mask pictures and the
bias report, on tiny runs trained in the test."""

import json

import gymnasium as gym
import imageio.v2 as imageio
import numpy as np
import pytest
import torch
from test_train_failures import named_unwritten_file, under_file_size_limit
from test_train_resume import TINY as RESUME_TINY

from simoun_agent.config import AgentConfig, resolve
from simoun_agent.models.encoder import ENCODERS, DualPathEncoder, make_encoder
from simoun_agent.run import train
from simoun_agent.run.make_env import make_env
from simoun_lab.analysis import masks as mask_pictures
from simoun_lab.analysis.bias import information_bias
from simoun_lab.analysis.layers import layer_activations
from simoun_lab.analysis.pairs import make_pairs
from simoun_lab.analysis.recolour import dm_control_physics, replay_recoloured
from simoun_lab.cli.analyze import main
from simoun_wrappers import SimounObservation

TINY = {**RESUME_TINY, "total_env_steps": 60}
"""tests/test_train_resume.py's tiny run, cut to one evaluation interval."""


def tiny_run(run_dir, encoder):
    curiosity = ENCODERS[encoder].motion_path
    overrides = {"run_dir": str(run_dir), "agent.encoder": encoder, "agent.curiosity": curiosity}
    run = train.create_run(resolve(None, {**TINY, **overrides}))
    train.train(run)
    return run_dir


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    root = tmp_path_factory.mktemp("runs")
    return {name: tiny_run(root / name, name) for name in ("dual_interactive", "stacked")}


def synthetic_pairs(n=600, seed=0):
    """Inputs with three latent signals: s (kept by static pairs, redrawn by dynamic ones), d
    (kept by dynamic pairs, redrawn by static ones) and j (kept by both, like where a moving
    object is). Units 0-9 copy s, 10-19 copy d, 20-29 copy j, 30-39 are noise, 40 is dead."""
    rng = np.random.default_rng(seed)

    def units(s, d, j):
        copies = [np.repeat(v[:, None], 10, axis=1) for v in (s, d, j)]
        noise = rng.normal(size=(len(s), 10))
        signal = np.concatenate([*copies, noise, np.zeros((len(s), 1))], axis=1)
        return signal + 0.2 * rng.normal(size=signal.shape) * (np.arange(41) < 40)

    def draw():
        return rng.normal(size=n)

    s, d, j = draw(), draw(), draw()
    static = (units(s, d, j), units(s, draw(), j))
    dynamic = (units(s, d, j), units(draw(), d, j))
    return {"static": static, "dynamic": dynamic}


def test_estimator_finds_the_known_structure():
    estimate = information_bias(synthetic_pairs())
    static, dynamic = estimate.unit_scores["static"], estimate.unit_scores["dynamic"]
    assert np.all(static[:10] > 0.8) and np.all(dynamic[:10] < 0.2)
    assert np.all(dynamic[10:20] > 0.8) and np.all(static[10:20] < 0.2)
    assert np.all(static[20:30] > 0.8) and np.all(dynamic[20:30] > 0.8)
    assert np.all(np.abs(static[30:]) < 0.2) and np.all(np.abs(dynamic[30:]) < 0.2)
    assert estimate.categories == {"static": 10, "dynamic": 10, "joint": 10, "residual": 11}
    assert sum(estimate.factor_units.values()) == estimate.units == 41
    assert estimate.layer_scores["static"] == pytest.approx(estimate.layer_scores["dynamic"], 0.2)


def test_estimator_layer_share_follows_the_units():
    pairs = synthetic_pairs()
    static_only = {k: (a[:, :10], b[:, :10]) for k, (a, b) in pairs.items()}
    estimate = information_bias(static_only)
    assert estimate.factor_units["static"] > estimate.factor_units["dynamic"]
    assert estimate.category_percent()["static"] == 100.0
    with pytest.raises(ValueError, match="same shape"):
        information_bias({"static": static_only["static"], "dynamic": pairs["dynamic"]})


def pointreach_observations(count=24):
    env = SimounObservation(gym.make("simoun/PointReach-v0"), size=32, motion=False)
    obs, _ = env.reset(seed=0)
    observations = []
    rng = np.random.default_rng(0)
    while len(observations) < count:
        obs, _, terminated, truncated, _ = env.step(rng.uniform(-1, 1, 2).astype(np.float32))
        observations.append(obs["frames"])
        if terminated or truncated:
            obs, _ = env.reset()
    return np.stack(observations)


def test_dynamic_pairs_change_pixels_and_keep_motion():
    x = pointreach_observations()
    first, recoloured = make_pairs(x, seed=1)["dynamic"]
    assert first is x and recoloured.shape == x.shape and recoloured.dtype == np.uint8
    # a convolution without bias leaves PointReach's black background black: look at the rest
    lit = x != 0
    assert np.mean(recoloured[lit] != x[lit]) > 0.5
    # one kernel for the three frames: where a pixel's 3x3 neighbourhood did not change between
    # two frames, the recoloured pixel does not change either, so the motion is kept
    still = (x[:, 1:] == x[:, :-1]).all(axis=2)
    padded = np.pad(~still, ((0, 0), (0, 0), (1, 1), (1, 1)))
    moved = np.zeros_like(still)
    for dr in range(3):
        for dc in range(3):
            moved |= padded[:, :, dr : dr + still.shape[2], dc : dc + still.shape[3]]
    same = (recoloured[:, 1:] == recoloured[:, :-1]).all(axis=2)
    assert np.all(same[~moved])
    assert (~moved).any() and moved.any()


def test_static_pairs_shuffle_the_same_frames():
    x = pointreach_observations()
    first, shuffled = make_pairs(x, seed=1)["static"]
    assert first is x
    for original, other in zip(x, shuffled, strict=True):
        rows = sorted(f.tobytes() for f in original)
        assert rows == sorted(f.tobytes() for f in other)
    distinct = np.array([len({f.tobytes() for f in o}) == 3 for o in x])
    assert distinct.any()
    assert np.all((shuffled[distinct] != x[distinct]).any(axis=(1, 2, 3, 4)))


@pytest.mark.parametrize("name", sorted(ENCODERS))
def test_every_encoder_has_path_and_state_layers(name):
    motion = ENCODERS[name].motion_path
    config = AgentConfig(encoder=name, num_filters=8, feature_dim=16, curiosity=motion)
    encoder = make_encoder(config, (3, 32, 32))
    layers = layer_activations(encoder, torch.as_tensor(pointreach_observations(5)))
    expected = {"motion path", "appearance path"} if motion else {"path"}
    assert set(layers) == expected | {"fused state"}
    assert all(v.shape[0] == 5 and torch.isfinite(v).all() for v in layers.values())


def test_masks_of_multi_camera_frames_cover_the_whole_image(tmp_path):
    encoder = DualPathEncoder((3, 32, 96), num_filters=8, feature_dim=16)
    obs = np.random.default_rng(0).integers(0, 256, (2, 3, 3, 32, 96), dtype=np.uint8)
    heats = mask_pictures.heat_maps(
        mask_pictures.structure_masks(encoder, obs), (32, 96), query=(10, 80)
    )
    assert {name: h.shape for name, h in heats.items()} == dict.fromkeys(heats, (2, 32, 96))
    path = mask_pictures.draw_figure(
        tmp_path / "wide.png", obs[0, -1], {k: v[0] for k, v in heats.items()}, "wide", (10, 80)
    )
    height, width = imageio.imread(path).shape[:2]
    assert height > width  # one panel per row for wide frames


def test_masks_command_writes_pictures_and_heat_maps(runs, tmp_path, capsys):
    out = tmp_path / "masks"
    args = ["masks", str(runs["dual_interactive"]), "--steps", "2,10", "--query", "16,5"]
    assert main([*args, "--video", "--out", str(out)]) == 0
    for step in (2, 10):
        picture = imageio.imread(out / f"ep0-step{step:04d}.png")
        assert picture.ndim == 3 and picture.shape[1] > 3 * picture.shape[0] > 3 * 32
        heats = np.load(out / f"ep0-step{step:04d}.npz")
        assert heats["frame"].shape == (3, 32, 32)
        for name in ("motion", "appearance", "attention"):
            assert heats[name].shape == (32, 32)
            assert np.ptp(heats[name]) > 0, name  # not constant
    gif = imageio.mimread(out / "masks-ep0.gif")
    assert len(gif) == 21  # reset + 20 decisions of PointReach
    before = (out / "ep0-step0002.png").stat().st_mtime_ns
    with pytest.raises(SystemExit) as exit_info:
        main([*args, "--out", str(out)])
    assert exit_info.value.code == 2
    assert "--overwrite" in capsys.readouterr().err
    assert (out / "ep0-step0002.png").stat().st_mtime_ns == before


def test_a_mask_picture_that_does_not_fit_is_named_with_the_fix_and_left_unwritten(runs, tmp_path):
    args = ["masks", str(runs["dual_interactive"]), "--steps", "1", "--out", str(tmp_path)]
    done = under_file_size_limit("simoun_lab.cli.analyze", args)
    path = named_unwritten_file(done, "simoun-analyze", "pass --out DIR on another disk")
    assert path == tmp_path / "ep0-step0001.png" and not path.exists()


def test_masks_command_refuses_bad_input(runs, tmp_path, capsys):
    run = str(runs["dual_interactive"])
    (tmp_path / "file").write_text("")
    cases = {
        "stacked": (["masks", str(runs["stacked"])], "encoder=dual_interactive", "analyze bias"),
        "beyond": (["masks", run, "--steps", "5,21"], "--steps 21", "up to 20"),
        "no checkpoint": (["masks", str(tmp_path)], "no checkpoint", "run directory"),
        "query": (["masks", run, "--query", "40,1"], "outside", "0 <= ROW < 32"),
        "unwritable": (
            ["masks", run, "--out", str(tmp_path / "file" / "out")],
            "writable",
            "--out",
        ),
    }
    for name, (argv, *expected) in cases.items():
        with pytest.raises(SystemExit) as exit_info:
            main(argv)
        err = capsys.readouterr().err
        assert exit_info.value.code == 2, name
        assert all(text in err for text in expected), (name, err)
        assert "Traceback" not in err
    assert not (runs["dual_interactive"] / "analysis").exists()


def test_analyze_refuses_numbers_out_of_range_naming_the_flag(runs, tmp_path, capsys):
    run = str(runs["dual_interactive"])
    cases = {
        "--seed -1": ["bias", run, "--seed", "-1"],
        "--seed 9223372036854775808": ["bias", run, "--seed", str(2**63)],
        "--pairs 1": ["bias", run, "--pairs", "1"],
        "--episodes 0": ["masks", run, "--episodes", "0"],
        "--query -1,5": ["masks", run, "--query", "-1,5"],
        "--steps count": ["masks", run, "--steps", "-2,4"],
    }
    for expected, argv in cases.items():
        with pytest.raises(SystemExit) as exit_info:
            main([*argv, "--out", str(tmp_path / "out")])
        err = capsys.readouterr().err
        assert exit_info.value.code == 2, expected
        assert expected in err and "Traceback" not in err, (expected, err)
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("command", ["bias", "masks"])
def test_analyze_blames_a_bad_device_on_the_flag_not_the_run(command, runs, tmp_path, capsys):
    run = str(runs["dual_interactive"])
    with pytest.raises(SystemExit) as exit_info:
        main([command, run, "--device", "gpu", "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert exit_info.value.code == 2
    assert "--device gpu: device type 'gpu' is not supported here; use cpu, cuda" in err
    assert "saved config" not in err
    assert not (tmp_path / "out").exists()


def test_bias_refuses_one_run_given_twice(runs, tmp_path, capsys):
    run = runs["stacked"]
    (tmp_path / "link").symlink_to(run)
    for second in (run, run / "checkpoint.pt", tmp_path / "link", run / ".." / run.name):
        with pytest.raises(SystemExit) as exit_info:
            main(["bias", str(run), str(second), "--out", str(tmp_path / "b"), "--pairs", "8"])
        err = capsys.readouterr().err
        assert exit_info.value.code == 2
        assert f"the same run ({run.resolve()}) given twice" in err and "give each run once" in err
    assert not (tmp_path / "b").exists()


def test_bias_command_compares_runs(runs, tmp_path):
    out = tmp_path / "bias"
    argv = ["bias", str(runs["dual_interactive"]), str(runs["stacked"]), "--pairs", "24"]
    assert main([*argv, "--out", str(out)]) == 0
    report = json.loads((out / "bias.json").read_text())
    encoders = [run["encoder"] for run in report["runs"]]
    assert encoders == ["dual_interactive", "stacked"]
    layers = report["runs"][0]["layers"]
    assert set(layers) == {"motion path", "appearance path", "fused state"}
    for layer in [*layers.values(), *report["runs"][1]["layers"].values()]:
        assert sum(layer["categories_percent"].values()) == pytest.approx(100.0)
        assert sum(layer["factor_percent"].values()) == pytest.approx(100.0)
    table = (out / "bias.md").read_text()
    assert "| stacked | path |" in table and "| dual_interactive | motion path |" in table
    assert imageio.imread(out / "bias.png").shape[0] > 100
    with pytest.raises(SystemExit):
        main(argv)  # several runs need --out


def test_recoloured_replay_keeps_physics_and_rewards():
    config = resolve(None, {"env": "dm_control/cartpole-swingup-v0", "image_size": 32})
    env = make_env(config)
    obs, _ = env.reset(seed=5)
    actions = np.random.default_rng(0).uniform(-1, 1, (9, 1)).astype(np.float32)
    observations, rewards = [obs["frames"]], []
    for action in actions:
        obs, reward, _, _, _ = env.step(action)
        observations.append(obs["frames"])
        rewards.append(reward)
    state = dm_control_physics(env, config.env).get_state().copy()
    env.close()
    rng = np.random.default_rng(1)
    recoloured, replayed_rewards, replayed_state = replay_recoloured(config, 5, actions, rng)
    np.testing.assert_array_equal(replayed_rewards, rewards)
    np.testing.assert_array_equal(replayed_state, state)
    changed = (recoloured != np.stack(observations)).any(axis=(1, 2)).mean(axis=(1, 2))
    assert np.all(changed > 0.3), changed  # sky, floor and bodies all change colour
    # one colour set per block of three decisions: the triplet at t = 2 repeats the frames
    # at 0, 1, 2 exactly, the one at t = 3 starts a new set
    np.testing.assert_array_equal(recoloured[2], recoloured[0:3, -1])
    assert (recoloured[3, -1] != recoloured[2, -1]).mean() > 0.3


def test_model_recolouring_of_a_non_mujoco_run_says_what_still_works(runs, tmp_path, capsys):
    out = tmp_path / "bias"
    with pytest.raises(SystemExit):
        main(["bias", str(runs["stacked"]), "--recolour", "model", "--out", str(out)])
    err = capsys.readouterr().err
    assert "not a dm_control task" in err and "--recolour conv" in err
    assert "simoun-analyze masks" in err
    assert not out.exists()


@pytest.mark.parametrize(
    ("change", "error", "message"),
    [
        (lambda p: [p["dynamic"], p["static"]], TypeError, r"dict factor -> \(z_a, z_b\)"),
        (lambda p: {**p, "motion": p["static"]}, ValueError, r"unknown \['motion'\]"),
        (
            lambda p: {k.title(): v for k, v in p.items()},
            ValueError,
            r"missing \['dynamic', 'static'\], unknown \['Static', 'Dynamic'\]",
        ),
        (lambda p: {**p, "static": p["static"] * 2}, ValueError, r"two arrays.*length 4"),
        (lambda p: {**p, "dynamic": p["dynamic"][0]}, ValueError, r"two arrays \(z_a, z_b\)"),
        (
            lambda p: {**p, "static": (p["static"][0], np.where(p["static"][1] > 3, np.nan, 0))},
            ValueError,
            r"pairs\['static'\]\[1\] has \d+ NaN or infinite activation",
        ),
    ],
)
def test_estimator_refuses_pairs_it_cannot_use(change, error, message):
    with pytest.raises(error, match=message):
        information_bias(change(synthetic_pairs(n=20)))


@pytest.mark.parametrize(
    ("threshold", "error", "message"),
    [
        (50, ValueError, r"threshold must lie in \(0, 1\).*50 looks like a percent: threshold=0.5"),
        (1.0, ValueError, r"threshold must lie in \(0, 1\)"),
        (0, ValueError, r"threshold must lie in \(0, 1\)"),
        ("0.5", TypeError, r"threshold must be a number"),
    ],
)
def test_estimator_refuses_a_threshold_outside_0_1(threshold, error, message):
    with pytest.raises(error, match=message):
        information_bias(synthetic_pairs(n=20), threshold=threshold)


def test_the_run_functions_check_their_arguments_and_name_a_swap():
    import simoun_agent.envs  # noqa: F401  (registers simoun/PointReach-v0)
    from simoun_agent import SimounAgent
    from simoun_lab.analysis.runs import play_episode
    from simoun_wrappers import SimounObservation

    config = AgentConfig(num_filters=4, feature_dim=8, hidden_dim=16, aux_hidden_dim=16)
    agent = SimounAgent((3, 32, 32), 2, config, device="cpu")
    env = SimounObservation(gym.make("simoun/PointReach-v0", render_mode="rgb_array"), size=32)
    with pytest.raises(TypeError, match="play_episode takes the agent first and the env second"):
        play_episode(env, agent, 0)
    with pytest.raises(ValueError, match=r"play_episode\(seed=\.\.\.\) must be an int >= 0"):
        play_episode(agent, env, -1)
    with pytest.raises(TypeError, match=r"layer_activations\(encoder=\.\.\.\).*agent\.encoder"):
        layer_activations(agent, torch.zeros(1, 3, 3, 32, 32, dtype=torch.uint8))
    with pytest.raises(TypeError, match=r"structure_masks\(encoder=\.\.\.\)"):
        mask_pictures.structure_masks(np.zeros((1, 3, 3, 32, 32), np.uint8), agent.encoder)
    with pytest.raises(
        TypeError, match=r"replay_recoloured\(config=\.\.\.\) must be a TrainConfig"
    ):
        replay_recoloured(agent, 0, np.zeros((1, 1)), np.random.default_rng(0))
    assert play_episode(agent, env, 0).length > 0


def small_encoder():
    config = AgentConfig(encoder="dual_interactive", num_filters=4, feature_dim=8)
    return make_encoder(config, (3, 32, 32))


OBSERVATIONS = np.random.default_rng(0).integers(0, 256, (4, 3, 3, 32, 32), dtype=np.uint8)
"""Four observations of three 3 x 32 x 32 uint8 frames, as the env gives them."""


@pytest.mark.parametrize(
    ("observations", "error", "message"),
    [
        (torch.rand(OBSERVATIONS.shape), TypeError, r"must be uint8 pixels.*got torch\.float32"),
        (OBSERVATIONS.astype(np.float32) / 255, TypeError, r"uint8 pixels.*got float32"),
        (OBSERVATIONS[0], ValueError, r"got shape \(3, 3, 32, 32\).*observations\[None\]"),
        (OBSERVATIONS[0, 0], ValueError, r"this is one frame \(C, H, W\)"),
        (
            OBSERVATIONS.transpose(0, 1, 3, 4, 2),
            ValueError,
            r"channel-last.*permute\(0, 1, 4, 2, 3\)",
        ),
        (
            OBSERVATIONS[:, 1:],
            ValueError,
            r"\(2 frames of 3 x 32 x 32\) do not fit.*needs 3 frames",
        ),
        (OBSERVATIONS[..., :16, :16], ValueError, r"3 x 16 x 16\) do not fit.*observation_space"),
        (OBSERVATIONS[:0], ValueError, r"holds no observation"),
        ([[1, 2]], TypeError, r"must be a uint8 array \(N, k, C, H, W\)"),
    ],
)
@pytest.mark.parametrize("function", [layer_activations, mask_pictures.structure_masks])
def test_the_layer_functions_check_their_observations_against_the_encoder(
    function, observations, error, message
):
    with pytest.raises(error, match=rf"{function.__name__}\(observations=\.\.\.\).*{message}"):
        function(small_encoder(), observations)


def test_the_layer_functions_take_numpy_or_torch_observations_and_check_batch_size():
    encoder = small_encoder()
    from_numpy = layer_activations(encoder, OBSERVATIONS, batch_size=3)
    from_torch = layer_activations(encoder, torch.as_tensor(OBSERVATIONS))
    assert all(torch.allclose(from_numpy[n], from_torch[n], atol=1e-5) for n in from_torch)
    assert len(mask_pictures.structure_masks(encoder, torch.as_tensor(OBSERVATIONS)).motion) == 4
    with pytest.raises(
        ValueError, match=r"layer_activations\(batch_size=\.\.\.\) must be an int >= 1"
    ):
        layer_activations(encoder, OBSERVATIONS, batch_size=0)
    with pytest.raises(TypeError, match=r"structure_masks\(batch_size=\.\.\.\)"):
        mask_pictures.structure_masks(encoder, OBSERVATIONS, batch_size=2.5)


@pytest.mark.parametrize(
    ("arguments", "error", "message"),
    [
        ({"observations": OBSERVATIONS / 255.0}, TypeError, r"observations=\.\.\.\) must be uint8"),
        ({"observations": OBSERVATIONS[0, 0]}, ValueError, r"one frame \(C, H, W\)"),
        ({"observations": OBSERVATIONS[:, :1]}, ValueError, r"need k >= 2 frames"),
        ({"seed": -1}, ValueError, r"make_pairs\(seed=\.\.\.\) must be an int in \[0, 2\*\*63\)"),
        ({"seed": 0.5}, TypeError, r"make_pairs\(seed=\.\.\.\)"),
        ({"recoloured": OBSERVATIONS[:2]}, ValueError, r"recoloured=\.\.\.\) must hold one recol"),
        ({"recoloured": OBSERVATIONS / 255.0}, TypeError, r"recoloured=\.\.\.\) must be uint8"),
    ],
)
def test_make_pairs_checks_its_arguments(arguments, error, message):
    with pytest.raises(error, match=message):
        make_pairs(**{"observations": OBSERVATIONS, "seed": 0, **arguments})


def test_make_pairs_takes_torch_observations_and_the_estimator_detaches_activations():
    pairs = make_pairs(torch.as_tensor(OBSERVATIONS), seed=0)
    assert pairs["static"][1].shape == OBSERVATIONS.shape
    z = torch.as_tensor(np.random.default_rng(0).normal(size=(50, 4))).requires_grad_()
    estimate = information_bias({"dynamic": (z, z * 2), "static": (z, -z)})
    assert estimate.categories["dynamic"] == 4
