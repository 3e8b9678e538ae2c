"""Action repeat: one agent step is ``repeat`` env steps with the same action."""

from __future__ import annotations

import math
import sys
from typing import Any, SupportsFloat

import gymnasium as gym

from simoun_wrappers._checks import (
    check_action,
    check_positive_int,
    check_reset_seed,
    keyword_reset,
    plain,
)
from simoun_wrappers.frames import check_single_env, refuse_over_frame_stack


class ActionRepeat(gym.Wrapper, gym.utils.RecordConstructorArgs):
    """Apply each action ``repeat`` times, summing the rewards; stop early when an episode ends.

    Returns the observation and info of the last inner step taken. It goes under the pixel
    wrappers (``SimounObservation(ActionRepeat(env, 8))``) so that the frame triplet holds
    agent steps, as in DrQ: cartpole-swingup uses 8, walker-walk 2. Over an env that already
    stacks frames (``SimounObservation``, ``FrameTriplet``, ``FrameStackObservation``) it
    raises: the stack would hold consecutive env steps instead of decisions.

    Example:
        >>> import gymnasium as gym
        >>> from simoun_wrappers import ActionRepeat
        >>> env = ActionRepeat(gym.make("CartPole-v1"), repeat=4)
        >>> _ = env.reset(seed=0)
        >>> env.step(0)[1]  # CartPole pays 1 per inner step
        4.0
    """

    def __init__(self, env: gym.Env, repeat: int) -> None:
        """Wrap ``env``.

        Args:
            env: the environment to wrap.
            repeat: inner steps per agent step, a positive int (1 changes nothing).
        """
        check_single_env(env, "ActionRepeat")
        gym.utils.RecordConstructorArgs.__init__(self, repeat=plain(repeat))
        gym.Wrapper.__init__(self, env)
        check_positive_int(
            repeat,
            "repeat",
            "e.g. ActionRepeat(env, 8) for cartpole-swingup, or leave the wrapper out for no "
            "repeat.",
        )
        refuse_over_frame_stack(
            env,
            "ActionRepeat",
            "its frames would be consecutive env steps instead of the agent's decisions",
            f"SimounObservation(ActionRepeat(env, {repeat}), ...) stacks one frame per decision",
        )
        self.repeat = int(repeat)

    @keyword_reset
    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[Any, dict[str, Any]]:
        seed = check_reset_seed(seed, "ActionRepeat")
        return self.env.reset(seed=seed, options=options)

    def step(self, action: Any) -> tuple[Any, SupportsFloat, bool, bool, dict[str, Any]]:
        check_action(action, self.action_space, "ActionRepeat")
        total, finite = 0.0, True
        for _ in range(self.repeat):
            obs, reward, terminated, truncated, info = self.env.step(action)
            total += float(reward)
            finite = finite and math.isfinite(float(reward))
            if terminated or truncated:
                break
        if finite and not math.isfinite(total):
            # finite rewards whose sum overflows: the largest float, not an inf that a learner
            # would take for a broken env
            total = math.copysign(sys.float_info.max, total)
        return obs, total, terminated, truncated, info
