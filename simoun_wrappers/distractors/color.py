"""ColorShift: new skybox, floor and body colours for a dm_control task at every reset."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any, SupportsFloat

import gymnasium as gym
import numpy as np

from simoun_wrappers._checks import check_action, check_reset_seed, keyword_reset, plain
from simoun_wrappers.distractors._dm_control import (
    check_level,
    check_open,
    check_seed,
    dm_control_physics,
    episode_rng,
)
from simoun_wrappers.frames import check_single_env

if TYPE_CHECKING:
    import mujoco

SHIFT_RANGES = {"easy": (0.05, 0.2), "hard": (0.3, 0.6)}
"""Per-channel distance of a new colour from the task's default (RGB in [0, 1]) at each level:
every channel moves by a uniform amount in this range, up or down at random (towards the side
with room when one would leave [0, 1]; ``hard`` is then clipped there, which still leaves it at
least 0.3 away, since each channel has 0.5 of room on one side). DMC-GB's colour modes likewise
draw colours near the defaults (easy) and anywhere (hard)."""

TEXTURE_COLORS = {"skybox": ("rgb1", "rgb2", "markrgb"), "grid": ("rgb1", "rgb2", "markrgb")}
"""The texture colours DMC-GB randomises, per texture of dm_control's ``suite/common`` assets."""

BODY_MATERIALS = ("self", "self_default")
"""The body's material and the copy tasks restore it from (DMC-GB's ``self_rgb``)."""

_COMMON_FILES = ("skybox.xml", "materials.xml")


def common_assets_spec() -> mujoco.MjSpec:
    """An MjSpec of dm_control's ``suite/common`` skybox and materials (textures included)."""
    import mujoco
    from dm_control.suite import common

    folder = Path(common.__file__).parent
    includes = "".join(f'<include file="{folder / name}"/>' for name in _COMMON_FILES)
    return mujoco.MjSpec.from_string(f"<mujoco>{includes}</mujoco>")


def shift_color(
    default: np.ndarray, rng: np.random.Generator, distance: tuple[float, float]
) -> np.ndarray:
    """``default`` (RGB in [0, 1]) with every channel moved by ``distance`` (see SHIFT_RANGES)."""
    magnitude = rng.uniform(*distance, size=default.shape)
    sign = rng.choice([-1.0, 1.0], size=default.shape)
    outside = (default + sign * magnitude < 0) | (default + sign * magnitude > 1)
    sign = np.where(outside, -sign, sign)
    return np.clip(default + sign * magnitude, 0.0, 1.0)


class ColorShift(gym.Wrapper, gym.utils.RecordConstructorArgs):
    """Give a dm_control task new skybox, floor-grid and body colours at every reset.

    The colours DMC-GB randomises (skybox ``rgb1``/``rgb2``/``markrgb``, grid
    ``rgb1``/``rgb2``/``markrgb``, the body's ``self`` material) get new values at each
    ``reset()``, ``easy`` near the defaults and ``hard`` far from them (``SHIFT_RANGES``). The
    change is made in the loaded MuJoCo model: MuJoCo rebuilds the two textures from the new
    colours (its own builtin gradient and checker, from dm_control's ``suite/common`` assets)
    and they are uploaded to the renderer, so ``render()``, ``MultiCamera`` views and anything
    else that renders the physics see them. Only appearance changes: observations, rewards and
    dynamics are those of the wrapped env. It can go anywhere under the pixel wrappers, e.g.
    ``SimounObservation(ActionRepeat(ColorShift(env), 8))``.

    Colours come from the wrapper's own RNG: ``reset(seed=s)`` makes them a function of
    ``(seed, s)``; unseeded resets continue the stream started by ``seed``. ``colors`` holds the
    current ones.

    Example:
        >>> import gymnasium as gym
        >>> import shimmy
        >>> from simoun_wrappers import ColorShift
        >>> gym.register_envs(shimmy)
        >>> env = ColorShift(gym.make("dm_control/cartpole-swingup-v0"), level="hard", seed=0)
        >>> _ = env.reset(seed=1)
        >>> sorted(env.colors)[:3]
        ['grid/markrgb', 'grid/rgb1', 'grid/rgb2']
    """

    def __init__(self, env: gym.Env, level: str = "easy", seed: int | None = None) -> None:
        """Wrap ``env``.

        Args:
            env: a dm_control task made through shimmy, e.g.
                ``gym.make("dm_control/cartpole-swingup-v0", render_mode="rgb_array")``.
            level: ``"easy"`` (colours near the defaults) or ``"hard"`` (far from them).
            seed: seed of the colour stream; None draws fresh entropy.
        """
        check_single_env(env, "ColorShift")
        gym.utils.RecordConstructorArgs.__init__(self, level=level, seed=plain(seed))
        gym.Wrapper.__init__(self, env)
        physics = dm_control_physics(env, "ColorShift")
        check_level(level, "ColorShift")
        check_seed(seed, "ColorShift")
        import mujoco

        self.level, self.seed = level, seed
        self._spec = common_assets_spec()
        model = physics.model.ptr
        self._textures = self._matching_textures(model)
        ids = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_MATERIAL, n) for n in BODY_MATERIALS]
        self._materials = [index for index in ids if index >= 0]
        if not self._textures and not self._materials:
            raise ValueError(
                f"{env.unwrapped} has none of dm_control's common skybox/grid textures or "
                f"'self' material, so ColorShift has nothing to recolour; use "
                f"RandomConvolution(env) to randomise its appearance instead."
            )
        self.defaults = {
            f"{name}/{key}": np.array(getattr(self._spec.texture(name), key), dtype=float)
            for name in self._textures
            for key in TEXTURE_COLORS[name]
        }
        if self._materials:
            self.defaults["self/rgb"] = model.mat_rgba[self._materials[0], :3].astype(float)
        self.colors = {key: value.copy() for key, value in self.defaults.items()}
        self._rng = np.random.default_rng(seed)

    def __getstate__(self) -> dict[str, Any]:
        # MuJoCo's MjSpec does not pickle; it holds only dm_control's common assets, and
        # _apply sets every colour it compiles, so a copy builds its own
        return {key: value for key, value in self.__dict__.items() if key != "_spec"}

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.__dict__.update(state)
        self._spec = common_assets_spec()

    def _matching_textures(self, model: Any) -> list[str]:
        """The common textures this model has, checked to be the common assets' sizes."""
        import mujoco

        compiled = self._spec.compile()
        found = []
        for name in TEXTURE_COLORS:
            if mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_TEXTURE, name) < 0:
                continue
            ours, theirs = model.texture(name), compiled.texture(name)
            if (ours.height, ours.width, ours.nchannel) != (
                theirs.height,
                theirs.width,
                theirs.nchannel,
            ):
                raise ValueError(
                    f"the {name!r} texture of this task ({ours.height[0]}x{ours.width[0]}) is "
                    f"not dm_control's common one ({theirs.height[0]}x{theirs.width[0]}); "
                    f"ColorShift only recolours tasks built on dm_control's suite/common assets."
                )
            found.append(name)
        return found

    @keyword_reset
    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[Any, dict[str, Any]]:
        seed = check_reset_seed(seed, "ColorShift")
        self._rng = episode_rng(self.seed, seed, self._rng, "ColorShift")
        distance = SHIFT_RANGES[self.level]
        self.colors = {
            key: shift_color(default, self._rng, distance) for key, default in self.defaults.items()
        }
        self._apply(dm_control_physics(self.env, "ColorShift"))
        return self.env.reset(seed=seed, options=options)

    def step(self, action: Any) -> tuple[Any, SupportsFloat, bool, bool, dict[str, Any]]:
        check_action(action, self.action_space, "ColorShift")
        check_open(self.env, "ColorShift")
        return self.env.step(action)

    def render(self) -> Any:
        check_open(self.env, "ColorShift")
        return self.env.render()

    def _apply(self, physics: Any) -> None:
        import mujoco

        model = physics.model.ptr
        for material in self._materials:
            model.mat_rgba[material, :3] = self.colors["self/rgb"]
        if not self._textures:
            return
        for name in self._textures:
            texture = self._spec.texture(name)
            for key in TEXTURE_COLORS[name]:
                setattr(texture, key, self.colors[f"{name}/{key}"])
        # MuJoCo builds the textures from the new colours exactly as when it loads a task.
        built = self._spec.compile()
        contexts = physics.contexts
        for name in self._textures:
            ours, new = model.texture(name), built.texture(name)
            size = int(new.height[0] * new.width[0] * new.nchannel[0])
            start, source = int(ours.adr[0]), int(new.adr[0])
            model.tex_data[start : start + size] = built.tex_data[source : source + size]
            with contexts.gl.make_current() as ctx:
                ctx.call(mujoco.mjr_uploadTexture, model, contexts.mujoco.ptr, ours.id)
