"""What ``simoun-train`` shows while it runs: a progress bar on a terminal, plain lines otherwise.

On a terminal the bar counts env steps and shows the last episode's and evaluation's returns;
during an evaluation it shows the episodes done (the first one of a run takes a while: 10
episodes of an untrained agent before any training step). Without a terminal (nohup, cluster
jobs, CI), or with the bar switched off (``--no-progress``), there is one line when the first
evaluation starts and one per evaluation after it, so logs do not fill with bar redraws and a
run of hours still says how far it is.
"""

from __future__ import annotations

import sys
import time

from tqdm import tqdm


class Progress:
    """The bar or the lines of one training process.

    Args:
        total: env steps of the run.
        done: env steps done before this process (a resumed run).
        label: the bar's label (the env id).
        enabled: the run's ``progress`` setting: the bar on a terminal (off: lines only).
    """

    def __init__(self, total: int, done: int, label: str, enabled: bool) -> None:
        self.total, self.start_step = total, done
        self.start = time.perf_counter()
        show_bar = enabled and sys.stderr.isatty()
        self.lines = not show_bar
        self.bar = tqdm(
            total=total,
            initial=done,
            unit="step",
            desc=label,
            dynamic_ncols=True,
            disable=not show_bar,
        )
        self.postfix: dict[str, str] = {}
        self.evaluations = 0
        self.episodes = 0

    def advance(self, env_steps: int) -> None:
        """``env_steps`` more steps taken."""
        self.bar.update(env_steps)

    def episode_end(self, episode_return: float) -> None:
        """A training episode ended with ``episode_return``."""
        self.postfix["episode_return"] = f"{episode_return:.1f}"
        self.bar.set_postfix(self.postfix)

    def evaluation_start(self, env_step: int, episodes: int) -> None:
        """An evaluation of ``episodes`` episodes begins at ``env_step``."""
        self.episodes = episodes
        self.bar.set_postfix_str(f"evaluating: 0/{episodes} episodes")
        if self.lines and self.evaluations == 0:
            plural = "s" if episodes != 1 else ""
            self.write(f"evaluating at env step {env_step} ({episodes} episode{plural})")

    def evaluation_episode(self, index: int, episode_return: float) -> None:
        """Episode ``index`` of the evaluation ended (:func:`~simoun_agent.run.evaluate.evaluate`'s
        ``on_episode``)."""
        self.bar.set_postfix_str(f"evaluating: {index + 1}/{self.episodes} episodes")

    def evaluated(self, env_step: int, metrics: dict[str, float]) -> None:
        """An evaluation was logged: the bar shows its return, or a line says it with the speed
        and the time left."""
        self.evaluations += 1
        self.postfix["eval_return"] = f"{metrics['return_mean']:.1f}"
        self.bar.set_postfix(self.postfix)
        if not self.lines:
            return
        elapsed = time.perf_counter() - self.start
        rate = (env_step - self.start_step) / elapsed if elapsed > 0 else 0.0
        left = self.total - env_step
        eta = f", ETA {duration(left / rate)}" if rate > 0 and left > 0 else ""
        self.write(
            f"env step {env_step}/{self.total}: eval return {metrics['return_mean']:.1f} +- "
            f"{metrics['return_std']:.1f}, {rate:.1f} env steps/s, {duration(elapsed)} "
            f"elapsed{eta}"
        )

    def write(self, text: str) -> None:
        """A line on stderr, above the bar when there is one."""
        tqdm.write(text, file=sys.stderr)

    def close(self) -> None:
        self.bar.close()


def duration(seconds: float) -> str:
    """``h:mm:ss``."""
    minutes, secs = divmod(int(seconds), 60)
    return f"{minutes // 60}:{minutes % 60:02d}:{secs:02d}"
