"""SimounParallelObservation: SimounObservation's per-agent transformation for PettingZoo."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np
from gymnasium import spaces
from gymnasium.error import ResetNeeded
from pettingzoo.utils.env import AECEnv, ParallelEnv
from pettingzoo.utils.wrappers import BaseParallelWrapper

from simoun_wrappers._checks import check_action, check_reset_seed, refuse_after_close
from simoun_wrappers.observation import check_stack_options, image_layout, parse_size
from simoun_wrappers.stack import FrameStack


class SimounParallelObservation(BaseParallelWrapper):
    """Give every agent of a PettingZoo ParallelEnv Simoun's frame triplet and motion channels.

    The per-agent transformation is ``SimounObservation``'s: each agent has its own
    ``FrameStack`` (``simoun_wrappers.stack``), which resizes the agent's image (OpenCV area
    interpolation), optionally makes it grayscale (gymnasium's weights), makes it channel-first,
    stacks it with reset padding, then adds motion or folds the stack. Agents that appear
    mid-episode start with a reset-padded stack, and an agent's stack starts anew after it
    terminates or truncates.
    With ``source="render"`` (or ``"auto"`` when observations are not uint8 images and the env
    renders ``rgb_array``, as ``SimounObservation`` decides: a float ``(H, W)`` table such as
    knights_archers_zombies' vector observation is no image) every agent
    sees the env's global ``render()`` frame (then, with ``size=None``, ``observation_space``
    needs a render, so call ``reset()`` first). ``observation_space(agent)`` returns the same
    cached object on every call, as ``parallel_api_test`` requires, and ``observation_spaces``
    holds those objects.

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
        self._options = {
            "grayscale": grayscale,
            "num_frames": num_frames,
            "motion": motion,
            "fold_frames": fold_frames,
        }
        self._from_render = self._pick_source(source)
        # One stack per agent, kept across episodes so that observation_space(agent) returns the
        # same object; _live names the agents whose stack holds frames of this episode.
        self._stacks: dict[Any, FrameStack] = {}
        self._live: set[Any] = set()
        self._has_reset = False
        self._closed = False

    def _pick_source(self, source: str) -> bool:
        agent = self.env.possible_agents[0]
        space = self.env.observation_space(agent)
        layout = image_layout(space)
        is_uint8 = layout is not None and space.dtype == np.uint8
        renders = getattr(self.env, "render_mode", None) == "rgb_array"
        use_observation = source == "observation" or (
            source == "auto" and layout is not None and (is_uint8 or not renders)
        )
        if use_observation:
            if not is_uint8:
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

    def _check_open(self, call: str) -> None:
        refuse_after_close(self._closed, "SimounParallelObservation", call)

    def close(self) -> None:
        """Close the env; a later reset or step is refused (PettingZoo's envs then fail inside
        pygame)."""
        self._closed = True
        super().close()

    def _check_agent(self, agent: Any, call: str) -> None:
        """A ValueError naming the env's agents for an ``agent`` that is none of them."""
        if agent not in self.env.possible_agents:
            raise ValueError(
                f"SimounParallelObservation.{call}({agent!r}): no such agent; this env's agents "
                f"are {list(self.env.possible_agents)} (env.possible_agents)."
            )

    def _stack_of(self, agent: Any, image: np.ndarray | None = None) -> FrameStack:
        if agent not in self._stacks:
            if self._from_render and self._size is None and image is None and not self._has_reset:
                # the frame size is the first render's, and PettingZoo envs render after reset()
                raise ResetNeeded(
                    "SimounParallelObservation(size=None) takes its frame size from the env's "
                    "first render, which PettingZoo allows only after reset(); call "
                    "env.reset(seed=...) before observation_space(agent), or pass size=(H, W)."
                )
            if self._from_render and self._size is not None:
                # rgb_array renders are (H, W, 3) and get resized: no render needed, which lets
                # observation_space() answer before reset() (PettingZoo envs cannot render yet).
                layout = (*self._size, 3)
            elif self._from_render:
                image = self.env.render() if image is None else image
                layout = (*image.shape[:2], image.shape[2] if image.ndim == 3 else 1)
            else:
                layout = image_layout(self.env.observation_space(agent))
            self._stacks[agent] = FrameStack(layout, self._size, **self._options)
        return self._stacks[agent]

    def observation_space(self, agent: Any) -> spaces.Space:
        self._check_agent(agent, "observation_space")
        return self._stack_of(agent).observation_space

    @property
    def observation_spaces(self) -> dict[Any, spaces.Space]:
        """Every possible agent's space, the same objects :meth:`observation_space` returns:
        the wrapped observations' Dict of frames (and motion), not the env's own images, which
        ``observation_spaces`` would otherwise reach through the wrapper."""
        return {agent: self.observation_space(agent) for agent in self.env.possible_agents}

    def action_space(self, agent: Any) -> spaces.Space:
        self._check_agent(agent, "action_space")
        return self.env.action_space(agent)

    def _images(self, obs: dict[Any, Any]) -> dict[Any, np.ndarray]:
        if not self._from_render:
            return obs
        frame = self.env.render()
        return dict.fromkeys(obs, frame)

    def reset(
        self, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[Any, Any], dict[Any, dict[str, Any]]]:
        self._check_open("reset")
        seed = check_reset_seed(seed, "SimounParallelObservation")
        obs, infos = self.env.reset(seed=seed, options=options)
        self._has_reset = True
        self._live = set()
        return self._stack(self._images(obs)), infos

    def _check_actions(self, actions: Any) -> None:
        """A clear error for ``actions`` that is no dict, names an agent that is none of the
        env's, lacks the action of an agent that acts (one live since its last reset or
        appearance), or holds an action outside that agent's action space."""
        owner = "SimounParallelObservation"
        if not isinstance(actions, Mapping):
            raise TypeError(
                f"{owner}.step takes a dict of one action per agent, got "
                f"{type(actions).__name__}; e.g. {{agent: env.action_space(agent).sample() for "
                f"agent in env.agents}}."
            )
        unknown = [agent for agent in actions if agent not in self.env.possible_agents]
        if unknown:
            raise ValueError(
                f"{owner}.step got actions for {unknown}, which are no agents of this env; its "
                f"agents are {list(self.env.possible_agents)} (env.possible_agents)."
            )
        missing = [a for a in self.env.agents if a in self._live and a not in actions]
        if missing:
            raise ValueError(
                f"{owner}.step got no action for {missing}: every live agent acts at each step "
                f"(env.agents: {list(self.env.agents)}); e.g. {{agent: "
                f"env.action_space(agent).sample() for agent in env.agents}}."
            )
        for agent, action in actions.items():
            check_action(action, self.env.action_space(agent), f"{owner}[{agent!r}]")

    def step(self, actions: dict[Any, Any]) -> tuple[dict[Any, Any], ...]:
        self._check_open("step")
        if self._has_reset and not self.env.agents:
            # PettingZoo's own order-enforcing wrapper checks this too, but only warns, and
            # the parallel env then answers with empty dicts: a loop stepping a fixed count
            # would collect nothing without a word
            raise ResetNeeded(
                "Cannot call SimounParallelObservation.step() after the episode ended: every "
                "agent terminated or was truncated (env.agents is empty); call env.reset() "
                "first, e.g. loop while env.agents."
            )
        self._check_actions(actions)
        obs, rewards, terminations, truncations, infos = self.env.step(actions)
        stacked = self._stack(self._images(obs))
        for agent in set(terminations) | set(truncations):
            if terminations.get(agent, False) or truncations.get(agent, False):
                self._live.discard(agent)
        return stacked, rewards, terminations, truncations, infos

    def _stack(self, images: dict[Any, np.ndarray]) -> dict[Any, Any]:
        out = {}
        for agent, image in images.items():
            stack = self._stack_of(agent, image)
            if agent in self._live:
                out[agent] = stack.push(image)
            else:
                self._live.add(agent)
                out[agent] = stack.reset(image)
        return out
