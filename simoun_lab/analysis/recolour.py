"""Re-render a MuJoCo (dm_control) episode under other colours: the same physics, new pixels.

The dynamic pairs of the information-bias analysis can come from here instead of a random
convolution (``simoun-analyze bias --recolour model``): a twin of the run's environment replays
the episode's seed and actions, so its physics and rewards are the original ones step for step,
while the colours of the skybox, of every material (the floor among them) and of every geom are
drawn anew, in blocks of three decisions so that each block's last triplet shows one colour set.
"""

from __future__ import annotations

import gymnasium as gym
import numpy as np

from simoun_agent.config import SetupError, TrainConfig
from simoun_agent.run.arguments import check_config_arg
from simoun_agent.run.make_env import make_env
from simoun_wrappers._checks import is_int

BLOCK = 3
"""Decisions per colour set: the triplets at t = 2, 5, 8, ... see one colour set each."""

SKY_GAIN = (0.3, 1.7)
"""Range of the per-channel factor applied to the skybox texture."""


def dm_control_physics(env: gym.Env, env_id: str):
    """The dm_control ``Physics`` under ``env``; SetupError naming what still works if none."""
    physics = getattr(getattr(env.unwrapped, "_env", None), "physics", None)
    if physics is None or not hasattr(physics, "model"):
        raise SetupError(
            f"--recolour model re-renders MuJoCo scenes under new colours, and {env_id} is not a "
            "dm_control task; use --recolour conv (a random convolution of the frames, any env). "
            "The rest still works on this run: the static pairs, every layer of the bias "
            "analysis, and simoun-analyze masks."
        )
    return physics


class ModelColours:
    """Random colours for the skybox, the materials and the geoms of a dm_control model."""

    def __init__(self, env: gym.Env, env_id: str) -> None:
        import mujoco

        self._mujoco = mujoco
        self.physics = dm_control_physics(env, env_id)
        model = self.physics.model
        self.geom_rgba = model.geom_rgba.copy()
        self.mat_rgba = model.mat_rgba.copy()
        self.skyboxes = [
            i for i in range(model.ntex) if model.tex_type[i] == mujoco.mjtTexture.mjTEXTURE_SKYBOX
        ]
        self.sky_data = {i: self._texture(i).copy() for i in self.skyboxes}

    def _texture(self, index: int) -> np.ndarray:
        model = self.physics.model
        size = model.tex_width[index] * model.tex_height[index] * model.tex_nchannel[index]
        start = model.tex_adr[index]
        return model.tex_data[start : start + size].reshape(-1, model.tex_nchannel[index])

    def draw(self, rng: np.random.Generator) -> None:
        """New uniform RGB colours for every geom and material, and a per-channel gain on the
        skybox (alpha kept)."""
        model = self.physics.model
        model.geom_rgba[:, :3] = rng.uniform(size=(model.ngeom, 3))
        model.mat_rgba[:, :3] = rng.uniform(size=(model.nmat, 3))
        context = self.physics.contexts.mujoco
        for index in self.skyboxes:
            original = self.sky_data[index]
            gain = np.ones(original.shape[1])
            gain[:3] = rng.uniform(*SKY_GAIN, size=3)
            self._texture(index)[:] = np.clip(original * gain, 0, 255).astype(np.uint8)
            # textures live on the GPU: a changed texture must be uploaded to be seen
            self._mujoco.mjr_uploadTexture(model.ptr, context.ptr, index)


def replay_recoloured(
    config: TrainConfig, seed: int, actions: np.ndarray, rng: np.random.Generator
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Replay an episode (reset ``seed``, then ``actions``) in a fresh twin of the run's env
    under colours drawn from ``rng`` every :data:`BLOCK` decisions.

    Returns the observations ``(T + 1, k, C, H, W)``, the rewards ``(T,)`` and the final
    physics state (to check against the original).
    """
    check_config_arg(config, "replay_recoloured")
    if not (is_int(seed) and seed >= 0):
        raise TypeError(
            f"replay_recoloured(seed=...) must be an int >= 0 (the episode's reset seed), got "
            f"{type(seed).__name__} {seed!r:.60}; e.g. replay_recoloured(run.config, "
            "episode.seed, episode.actions, np.random.default_rng(0))"
        )
    if not isinstance(rng, np.random.Generator):
        raise TypeError(
            f"replay_recoloured(rng=...) must be a numpy Generator, got {type(rng).__name__}; "
            "e.g. np.random.default_rng(0)"
        )
    twin = make_env(config)
    try:
        colours = ModelColours(twin, config.env)
        colours.draw(rng)
        obs, _ = twin.reset(seed=seed)
        observations, rewards = [obs["frames"]], []
        for step, action in enumerate(actions, start=1):
            if step % BLOCK == 0:
                colours.draw(rng)
            obs, reward, _, _, _ = twin.step(action)
            observations.append(obs["frames"])
            rewards.append(reward)
        state = colours.physics.get_state().copy()
    finally:
        twin.close()
    return np.stack(observations), np.asarray(rewards, np.float64), state
