"""SimounParallelObservation: SimounObservation's per-agent transformation for PettingZoo."""

from __future__ import annotations

from typing import Any

import numpy as np
from gymnasium import spaces
from pettingzoo.utils.env import AECEnv, ParallelEnv
from pettingzoo.utils.wrappers import BaseParallelWrapper

from simoun_wrappers.frames import FrameRing
from simoun_wrappers.motion import residual_motion
from simoun_wrappers.observation import (
    check_stack_options,
    frame_shape,
    image_layout,
    parse_size,
    to_frame,
)


class SimounParallelObservation(BaseParallelWrapper):
    """Give every agent of a PettingZoo ParallelEnv Simoun's frame triplet and motion channels.

    The per-agent transformation is ``SimounObservation``'s: each agent's image is resized
    (OpenCV area interpolation), optionally made grayscale (gymnasium's weights), made
    channel-first, and stacked in the agent's own ring with reset padding; then motion is
    added or the stack is folded. Agents that appear mid-episode start with their own
    reset-padded stack, and an agent's stack is dropped when it terminates or truncates.
    With ``source="render"`` (or ``"auto"`` when observations are not images) every agent
    sees the env's global ``render()`` frame (then, with ``size=None``, ``observation_space``
    needs a render, so call ``reset()`` first). ``observation_space(agent)`` returns the same
    cached object on every call, as ``parallel_api_test`` requires.

    Example:
        >>> import pettingzoo
        >>> from simoun_wrappers.pettingzoo import SimounParallelObservation
        >>> pistons = pettingzoo.make("parallel", "butterfly/pistonball-v6", n_pistons=3)
        >>> env = SimounParallelObservation(pistons, size=32)
        >>> obs, _ = env.reset(seed=0)
        >>> obs["piston_0"]["frames"].shape, obs["piston_0"]["motion"].shape
        ((3, 3, 32, 32), (6, 32, 32))
    """

    def __init__(
        self,
        env: ParallelEnv,
        size: int | tuple[int, int] | None = 84,
        grayscale: bool = False,
        num_frames: int = 3,
        motion: bool = True,
        fold_frames: bool = False,
        source: str = "auto",
    ) -> None:
        """Wrap ``env``, a ParallelEnv with image observations per agent or
        ``render_mode="rgb_array"``. The other arguments are ``SimounObservation``'s, applied to
        each agent (``source="observation"``: each agent's own image).
        """
        if isinstance(env, AECEnv):
            raise TypeError(
                f"SimounParallelObservation wraps a PettingZoo ParallelEnv, got the AEC env {env}; "
                f"create the parallel version (e.g. pistonball_v6.parallel_env(...) or "
                f"pettingzoo.make('parallel', ...)), or convert it with "
                f"pettingzoo.utils.conversions.aec_to_parallel(env)."
            )
        if not isinstance(env, ParallelEnv):
            raise TypeError(
                f"SimounParallelObservation wraps a PettingZoo ParallelEnv, got "
                f"{type(env).__name__} ({env!r:.60}); for one Gymnasium env use "
                f"SimounObservation(env, ...), for a vector env gym.make_vec(env_id, num_envs, "
                f"wrappers=[lambda e: SimounObservation(e, ...)])."
            )
        inner = env
        while isinstance(inner, BaseParallelWrapper):
            if isinstance(inner, SimounParallelObservation):
                raise TypeError(
                    f"SimounParallelObservation stacks frames itself, but {env} already holds "
                    f"one: over it, each agent's triplet would be replaced by render() frames. "
                    f"Apply SimounParallelObservation once, to the PettingZoo env."
                )
            inner = inner.env
        super().__init__(env)
        check_stack_options(num_frames, motion, fold_frames, source, grayscale)
        self._size = parse_size(size)
        self._grayscale = grayscale
        self._num_frames = int(num_frames)
        self._motion = motion and not fold_frames
        self._fold = fold_frames
        self._from_render = self._pick_source(source)
        self._spaces: dict[Any, spaces.Space] = {}
        self._layouts: dict[Any, tuple[int, int, int]] = {}
        self._rings: dict[Any, FrameRing] = {}

    def _pick_source(self, source: str) -> bool:
        agent = self.env.possible_agents[0]
        layout = image_layout(self.env.observation_space(agent))
        if source == "observation" or (source == "auto" and layout is not None):
            space = self.env.observation_space(agent)
            if layout is None or space.dtype != np.uint8:
                raise TypeError(
                    f"SimounParallelObservation expects each agent's observation to be an "
                    f"(H, W, C) or (H, W) uint8 image, got {space} for {agent!r}; convert it "
                    f"first, or pass source='render' with render_mode='rgb_array'."
                )
            return False
        if getattr(self.env, "render_mode", None) != "rgb_array":
            raise ValueError(
                f"SimounParallelObservation needs pixels: the env has neither image "
                f"observations ({self.env.observation_space(agent)} for {agent!r}) nor "
                f"render_mode='rgb_array'. Create it with render_mode='rgb_array', or give its "
                f"agents (H, W, 3) uint8 image observations."
            )
        return True

    def _layout(self, agent: Any, frame: np.ndarray | None = None) -> tuple[int, int, int]:
        if agent not in self._layouts:
            if self._from_render and self._size is not None:
                # rgb_array renders are (H, W, 3) and get resized: no render needed, which lets
                # observation_space() answer before reset() (PettingZoo envs cannot render yet).
                layout = (*self._size, 3)
            elif self._from_render:
                frame = self.env.render() if frame is None else frame
                layout = (*frame.shape[:2], frame.shape[2] if frame.ndim == 3 else 1)
            else:
                layout = image_layout(self.env.observation_space(agent))
            self._layouts[agent] = frame_shape(layout, self._size, self._grayscale)
        return self._layouts[agent]

    def observation_space(self, agent: Any) -> spaces.Space:
        if agent not in self._spaces:
            c, h, w = self._layout(agent)
            k = self._num_frames
            frames = spaces.Box(0, 255, (k, c, h, w), dtype=np.uint8)
            if self._fold:
                space = spaces.Box(0, 255, (k * c, h, w), dtype=np.uint8)
            elif self._motion:
                motion = spaces.Box(-255, 255, ((k - 1) * c, h, w), dtype=np.int16)
                space = spaces.Dict({"frames": frames, "motion": motion})
            else:
                space = spaces.Dict({"frames": frames})
            self._spaces[agent] = space
        return self._spaces[agent]

    def _output(self, stack: np.ndarray) -> np.ndarray | dict[str, np.ndarray]:
        if self._fold:
            return stack.reshape(-1, *stack.shape[2:])
        if self._motion:
            return {"frames": stack, "motion": residual_motion(stack)}
        return {"frames": stack}

    def _images(self, obs: dict[Any, Any]) -> dict[Any, np.ndarray]:
        if not self._from_render:
            return obs
        frame = self.env.render()
        return dict.fromkeys(obs, frame)

    def reset(
        self, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[Any, Any], dict[Any, dict[str, Any]]]:
        obs, infos = self.env.reset(seed=seed, options=options)
        self._rings = {}
        return self._stack(self._images(obs)), infos

    def step(self, actions: dict[Any, Any]) -> tuple[dict[Any, Any], ...]:
        obs, rewards, terminations, truncations, infos = self.env.step(actions)
        stacked = self._stack(self._images(obs))
        for agent in set(terminations) | set(truncations):
            if terminations.get(agent, False) or truncations.get(agent, False):
                self._rings.pop(agent, None)
        return stacked, rewards, terminations, truncations, infos

    def _stack(self, images: dict[Any, np.ndarray]) -> dict[Any, Any]:
        out = {}
        for agent, image in images.items():
            frame = to_frame(image, self._size, self._grayscale)
            ring = self._rings.get(agent)
            if ring is None:
                c, h, w = self._layout(agent, image)
                ring = self._rings[agent] = FrameRing(self._num_frames, (c, h, w), np.uint8)
                out[agent] = self._output(ring.reset(frame))
            else:
                out[agent] = self._output(ring.push(frame))
        return out
