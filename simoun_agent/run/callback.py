"""The interface through which the training loop calls out: :class:`TrainCallback`.

Its own module, so a callback (Ray Tune's reporter, distracted evaluation) builds on the
interface without importing the loop of :mod:`simoun_agent.run.train`.
"""

from __future__ import annotations

from simoun_agent.run.state import Run


class TrainCallback:
    """Hooks into the loop (:func:`simoun_agent.run.train.train`); subclass and override what
    you need (all do nothing here).

    Ray Tune's reporter (``simoun_lab.sweep``) and extra evaluation environments plug in here
    instead of editing the loop; whoever wants one passes it to the loop.
    """

    serves: tuple[str, ...] = ()
    """config keys this callback carries out (``eval_distraction``: distracted evaluation); the
    loop refuses a run whose config sets such a key when no callback given to it serves the key,
    so the setting is never dropped silently"""

    def on_start(self, run: Run) -> None:
        """Once, when the loop begins, before the first evaluation (build what you need)."""

    def on_evaluation(self, run: Run, metrics: dict[str, float]) -> None:
        """After each evaluation (env step ``run.counters.env_step``), before it is logged; may
        add entries to ``metrics``, which then go to eval.csv and TensorBoard too. Evaluations of
        your own should pass ``stop=run.stop.is_set`` to
        :func:`simoun_agent.run.evaluate.evaluate`."""

    def on_logged(self, run: Run, metrics: dict[str, float]) -> None:
        """After each evaluation has been logged (``metrics`` as written to eval.csv)."""

    def on_end(self, run: Run, metrics: dict[str, float] | None) -> None:
        """Once, whenever the loop ends: ``metrics`` are the final evaluation's after the
        video and summary.json, None when the run stopped early (a signal, an error). Close here
        what :meth:`on_start` opened."""

    def stop_requested(self, run: Run) -> int | None:
        """Polled between steps: a signal number stops the run as if that signal had arrived
        (checkpoint, then :class:`~simoun_agent.run.signals.Stopped`); None goes on. For
        supervisors that cannot signal the loop's thread, such as a Ray Tune trial."""
        return None
