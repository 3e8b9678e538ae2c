"""MovingBackground: a moving background behind a dm_control task, found by segmentation."""

from __future__ import annotations

from pathlib import Path
from typing import Any, SupportsFloat

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
from simoun_wrappers.distractors.backgrounds import ProceduralBackground, VideoBackground
from simoun_wrappers.frames import check_single_env


class MovingBackground(gym.Wrapper, gym.utils.RecordConstructorArgs):
    """Replace the background of a dm_control task's frames with a moving one.

    Each frame is rendered twice by the physics, once in colour and once with dm_control's
    segmentation (object id and type per pixel, -1 for the skybox); the background pixels, the
    sky (``level="easy"``) or the sky and the floor planes (``level="hard"``, as DMC-GB's
    ``video_hard``), are replaced, so the agent's body is never covered, whatever its colour.
    The background is procedural by default (a drifting texture with moving discs, new each
    episode, seeded) or, with ``videos``, a folder of video files played in a loop (DMC-GB's
    videos or DAVIS clips). It moves at every ``step()``.

    ``render()`` returns the composited frame, and ``render_camera(height, width, camera_id)``
    composites any camera: ``MultiCamera`` above uses it for its dm_control views. Put the
    wrapper under the pixel wrappers, e.g.
    ``SimounObservation(MultiCamera(ActionRepeat(MovingBackground(env), 4), [0, 1]))``; under
    ``ActionRepeat`` the background moves at every inner step. Observations, rewards and
    dynamics are those of the wrapped env.

    Example:
        >>> import gymnasium as gym
        >>> import shimmy
        >>> gym.register_envs(shimmy)  # the dm_control/... ids
        >>> from simoun_wrappers import MovingBackground
        >>> env = gym.make(
        ...     "dm_control/cartpole-swingup-v0",
        ...     render_mode="rgb_array",
        ...     render_kwargs={"height": 32, "width": 32, "camera_id": 0},
        ... )
        >>> env = MovingBackground(env, level="hard", seed=0)
        >>> _ = env.reset(seed=1)
        >>> first = env.render()
        >>> _ = env.step(env.action_space.sample())
        >>> first.shape, bool((env.render() != first).any())
        ((32, 32, 3), True)
    """

    def __init__(
        self,
        env: gym.Env,
        level: str = "easy",
        videos: str | Path | None = None,
        seed: int | None = None,
    ) -> None:
        """Wrap ``env``.

        Args:
            env: a dm_control task made through shimmy with ``render_mode="rgb_array"``.
            level: ``"easy"`` replaces the sky, ``"hard"`` the sky and the floor.
            videos: a folder of video files, or of sub-folders of frames (DAVIS's layout), to
                play; None for the procedural background.
            seed: seed of the background stream; None draws fresh entropy.
        """
        check_single_env(env, "MovingBackground")
        gym.utils.RecordConstructorArgs.__init__(
            self, level=level, videos=None if videos is None else str(videos), seed=plain(seed)
        )
        gym.Wrapper.__init__(self, env)
        physics = dm_control_physics(env, "MovingBackground")
        check_level(level, "MovingBackground")
        check_seed(seed, "MovingBackground")
        if env.render_mode != "rgb_array":
            raise ValueError(
                f"MovingBackground changes rendered frames, but the env's render_mode is "
                f"{env.render_mode!r}; make it with gym.make(env_id, render_mode='rgb_array')."
            )
        import mujoco

        _check_under_pixel_wrappers(env)
        self.metadata = {**env.metadata, "render_modes": ["rgb_array"]}
        self.level, self.seed = level, seed
        self._geom_type = int(mujoco.mjtObj.mjOBJ_GEOM)
        self._source = ProceduralBackground() if videos is None else VideoBackground(videos)
        model = physics.model.ptr
        floors = np.flatnonzero(model.geom_type == mujoco.mjtGeom.mjGEOM_PLANE)
        self._replaced_geoms = floors if level == "hard" else np.array([], dtype=int)
        self._rng = np.random.default_rng(seed)
        self._source.start(self._rng)
        self._t = 0

    @keyword_reset
    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[Any, dict[str, Any]]:
        seed = check_reset_seed(seed, "MovingBackground")
        check_open(self.env, "MovingBackground")
        self._rng = episode_rng(self.seed, seed, self._rng, "MovingBackground")
        self._source.start(self._rng)
        self._t = 0
        return self.env.reset(seed=seed, options=options)

    def step(self, action: Any) -> tuple[Any, SupportsFloat, bool, bool, dict[str, Any]]:
        check_action(action, self.action_space, "MovingBackground")
        check_open(self.env, "MovingBackground")
        result = self.env.step(action)
        self._t += 1
        return result

    def render(self) -> np.ndarray:
        """The wrapped env's frame (its ``render_kwargs``) with the moving background."""
        return self.render_camera(**self.env.unwrapped.render_kwargs)

    def render_camera(
        self, height: int = 240, width: int = 320, camera_id: int | str = -1, **kwargs: Any
    ) -> np.ndarray:
        """``physics.render(height, width, camera_id, **kwargs)`` with the moving background."""
        physics = dm_control_physics(self.env, "MovingBackground")
        image = physics.render(height, width, camera_id, **kwargs)
        mask = self.background_mask(height, width, camera_id)
        background = self._source.frame(self._t, height, width)
        return np.where(mask[..., None], background, image)

    def background_mask(
        self, height: int = 240, width: int = 320, camera_id: int | str = -1
    ) -> np.ndarray:
        """``(height, width)`` bool: the pixels this wrapper replaces, from the segmentation."""
        physics = dm_control_physics(self.env, "MovingBackground")
        segmentation = physics.render(height, width, camera_id, segmentation=True)
        ids, types = segmentation[..., 0], segmentation[..., 1]
        floor = (types == self._geom_type) & np.isin(ids, self._replaced_geoms)
        return (ids == -1) | floor


def _check_under_pixel_wrappers(env: gym.Env) -> None:
    """Refuse to sit over wrappers that already turned renders into observations.

    Their observations were rendered below this wrapper, so the agent would never see the
    background; only ``render()`` would change.
    """
    from gymnasium.wrappers import AddRenderObservation

    from simoun_wrappers.cameras import MultiCamera

    inner = env
    while isinstance(inner, gym.Wrapper):
        if isinstance(inner, (AddRenderObservation, MultiCamera)):
            raise TypeError(
                f"MovingBackground goes under the pixel wrappers, but {env} already renders its "
                f"observations ({type(inner).__name__}), which would keep the plain background. "
                f"Swap the order, e.g. SimounObservation(MultiCamera(MovingBackground(env), ...))."
            )
        inner = inner.env
