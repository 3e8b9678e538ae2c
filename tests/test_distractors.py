"""ColorShift and MovingBackground: appearance changes, dynamics do not, on real dm_control."""

import gymnasium as gym
import imageio.v2 as imageio
import numpy as np
import pytest
import shimmy
from gymnasium.utils.env_checker import check_env

from simoun_wrappers import (
    ActionRepeat,
    ColorShift,
    MovingBackground,
    MultiCamera,
    SimounObservation,
)
from simoun_wrappers.distractors.color import SHIFT_RANGES

gym.register_envs(shimmy)

pytestmark = pytest.mark.filterwarnings("ignore::UserWarning")

SIZE = 32
STEPS = 4


def _cartpole() -> gym.Env:
    render = {"height": SIZE, "width": SIZE, "camera_id": 0}
    return gym.make("dm_control/cartpole-swingup-v0", render_mode="rgb_array", render_kwargs=render)


def _physics(env: gym.Env):
    return env.unwrapped._env.physics


DISTRACTORS = {
    "color_easy": lambda env: ColorShift(env, "easy", seed=0),
    "color_hard": lambda env: ColorShift(env, "hard", seed=0),
    "video_easy": lambda env: MovingBackground(env, "easy", seed=0),
    "video_hard": lambda env: MovingBackground(env, "hard", seed=0),
}


def _rollout(env: gym.Env, seed: int = 3) -> tuple[list, list, list, list]:
    """Rewards, terminations, physics states and frames of a fixed action sequence."""
    actions = np.linspace(-1, 1, STEPS, dtype=np.float32)[:, None]
    env.reset(seed=seed)
    rewards, dones, states, frames = [], [], [], [env.render()]
    for action in actions:
        _, reward, terminated, truncated, _ = env.step(action)
        rewards.append(reward)
        dones.append((terminated, truncated))
        states.append(_physics(env).get_state().copy())
        frames.append(env.render())
    return rewards, dones, states, frames


# Each wrapper and each level appears at least once across these two parametrizations.
@pytest.mark.parametrize("name", ["color_easy", "video_hard"])
def test_same_dynamics_different_pixels(name):
    plain = _rollout(_cartpole())
    distracted = _rollout(DISTRACTORS[name](_cartpole()))
    assert distracted[0] == plain[0]
    assert distracted[1] == plain[1]
    for ours, theirs in zip(distracted[2], plain[2], strict=True):
        np.testing.assert_array_equal(ours, theirs)
    for ours, theirs in zip(distracted[3], plain[3], strict=True):
        assert ours.shape == theirs.shape and ours.dtype == np.uint8
        assert np.abs(ours.astype(int) - theirs).mean() > 5


@pytest.mark.parametrize("level", ["easy", "hard"])
def test_moving_background_keeps_body_pixels_and_moves(level):
    plain, env = _cartpole(), MovingBackground(_cartpole(), level, seed=0)
    plain.reset(seed=1)
    env.reset(seed=1)
    physics = _physics(env)
    previous = None
    for step in range(3):
        mask = env.background_mask(SIZE, SIZE, 0)
        ids, types = np.moveaxis(physics.render(SIZE, SIZE, 0, segmentation=True), -1, 0)
        floor = (ids == physics.model.name2id("floor", "geom")) & (types == 5)
        np.testing.assert_array_equal(mask, (ids == -1) | (floor if level == "hard" else False))
        frame, reference = env.render(), plain.render()
        np.testing.assert_array_equal(frame[~mask], reference[~mask])
        assert (frame[mask] != reference[mask]).any()
        if previous is not None:
            assert np.abs(frame[mask].astype(int) - previous[mask]).mean() > 1
        previous = frame
        action = np.full(1, 0.5 - step, np.float32)
        env.step(action)
        plain.step(action)
    assert mask.any() and (~mask).any()


@pytest.mark.parametrize("name", ["color_hard", "video_easy"])
def test_same_seed_same_frames(name):
    first = _rollout(DISTRACTORS[name](_cartpole()), seed=5)[3]
    again = _rollout(DISTRACTORS[name](_cartpole()), seed=5)[3]
    other = _rollout(DISTRACTORS[name](_cartpole()), seed=6)[3]
    for a, b in zip(first, again, strict=True):
        np.testing.assert_array_equal(a, b)
    assert not np.array_equal(first[0], other[0])


def test_color_shift_writes_the_new_colours_into_the_model():
    distances = {}
    for level in ("easy", "hard"):
        env = ColorShift(_cartpole(), level, seed=0)
        env.reset(seed=2)
        model = _physics(env).model.ptr
        grid = model.texture("grid")
        start, size = int(grid.adr[0]), int(grid.height[0] * grid.width[0] * 3)
        texels = np.unique(model.tex_data[start : start + size].reshape(-1, 3), axis=0)
        expected = np.stack(
            [env.colors[f"grid/{key}"] * 255 for key in ("rgb1", "rgb2", "markrgb")]
        )
        # MuJoCo truncates colour * 255 to uint8: every texel is one of the three within 1.
        gaps = np.abs(texels[:, None].astype(float) - expected[None]).max(-1)
        assert (gaps.min(1) <= 1).all() and (gaps.min(0) <= 1).all()
        np.testing.assert_allclose(
            model.mat_rgba[model.material("self").id, :3], env.colors["self/rgb"]
        )
        distances[level] = np.concatenate(
            [np.abs(env.colors[key] - env.defaults[key]) for key in env.colors]
        )
    low, high = SHIFT_RANGES["easy"]
    assert ((distances["easy"] >= low - 1e-9) & (distances["easy"] <= high + 1e-9)).all()
    assert distances["hard"].min() >= SHIFT_RANGES["hard"][0] - 1e-9


def _with_distractor(distractor):
    return lambda: SimounObservation(
        MultiCamera(ActionRepeat(distractor(_cartpole()), 2), [0, 1], size=24), size=None
    )


STACKS = {
    "color": _with_distractor(lambda env: ColorShift(env, "hard", seed=1)),
    "video": _with_distractor(lambda env: MovingBackground(env, "hard", seed=1)),
}


@pytest.mark.parametrize("name", list(STACKS))
def test_stack_passes_check_env_and_rebuilds_from_spec(name):
    env = STACKS[name]()
    check_env(env)
    rebuilt = gym.make(env.spec)
    assert [w.name for w in rebuilt.spec.additional_wrappers] == [
        w.name for w in env.spec.additional_wrappers
    ]
    plain = SimounObservation(MultiCamera(ActionRepeat(_cartpole(), 2), [0, 1], size=24), size=None)
    pairs = [(env.reset(seed=4)[0], rebuilt.reset(seed=4)[0])]
    pairs += [(env.step(np.ones(1))[0], rebuilt.step(np.ones(1))[0]) for _ in range(2)]
    for a, b in pairs:
        np.testing.assert_array_equal(a["frames"], b["frames"])
    # The distractor reaches MultiCamera's views, not only render().
    assert not np.array_equal(plain.reset(seed=4)[0]["frames"], pairs[0][0]["frames"])


def test_bare_wrappers_pass_check_env():
    # The bare shimmy env's own render check fails in its multi_camera mode, so skip it here;
    # the stacks above check rendering.
    check_env(ColorShift(_cartpole(), seed=0), skip_render_check=True)
    check_env(MovingBackground(_cartpole(), seed=0))


@pytest.mark.parametrize("layout", ["mp4", "image_folder"])
def test_videos_are_played_behind_the_task(tmp_path, layout):
    colors = [(250, 0, 0), (0, 250, 0), (0, 0, 250), (250, 250, 0)]
    frames = [np.full((32, 32, 3), color, np.uint8) for color in colors]
    if layout == "mp4":
        imageio.mimsave(tmp_path / "clip.mp4", frames, fps=10, macro_block_size=1)
    else:  # DAVIS: JPEGImages/480p/<sequence>/00000.jpg, ...
        (tmp_path / "sequence").mkdir()
        for index, frame in enumerate(frames):
            imageio.imwrite(tmp_path / "sequence" / f"{index:05d}.jpg", frame)
    (tmp_path / "notes.txt").write_text("not a video")
    env = MovingBackground(_cartpole(), "easy", videos=tmp_path, seed=0)
    env.reset(seed=0)
    seen = []
    for _ in range(len(colors)):
        frame, mask = env.render(), env.background_mask(SIZE, SIZE, 0)
        seen.append(np.median(frame[mask], axis=0))
        env.step(np.zeros(1))
    nearest = [int(np.argmin([np.abs(s - c).sum() for c in colors])) for s in seen]
    assert all(np.abs(s - colors[n]).max() < 30 for s, n in zip(seen, nearest, strict=True))
    first = nearest[0]
    assert nearest == [(first + k) % len(colors) for k in range(len(colors))]


def test_bad_input_errors(tmp_path):
    with pytest.raises(TypeError, match=r"dm_control.*RandomConvolution"):
        ColorShift(gym.make("CartPole-v1", render_mode="rgb_array"))
    with pytest.raises(TypeError, match=r"dm_control.*RandomConvolution"):
        MovingBackground(gym.make("CartPole-v1", render_mode="rgb_array"))
    with pytest.raises(ValueError, match=r"level must be one of \('easy', 'hard'\)"):
        ColorShift(_cartpole(), level="medium")
    with pytest.raises(ValueError, match="level must be one of"):
        MovingBackground(_cartpole(), level="extreme")
    (tmp_path / "broken.mp4").write_bytes(b"not a video")
    with pytest.raises(ValueError, match=r"no readable video in .*broken\.mp4"):
        MovingBackground(_cartpole(), videos=tmp_path)
    with pytest.raises(ValueError, match="is not a folder"):
        MovingBackground(_cartpole(), videos=tmp_path / "missing")
    with pytest.raises(TypeError, match="goes under the pixel wrappers"):
        MovingBackground(SimounObservation(_cartpole(), size=SIZE))
    with pytest.raises(ValueError, match="render_mode='rgb_array'"):
        MovingBackground(gym.make("dm_control/cartpole-swingup-v0"))
