"""Running a grid of training runs on Ray Tune (the library under ``simoun-sweep``,
:mod:`simoun_lab.cli.sweep`, and ``simoun-study``): the resources of a trial, the trials through
the engine (:mod:`simoun_lab.engine.launcher`), the STOP file on SIGTERM and the summary of what
happened.

Each trial is an ordinary run directory ``SWEEP_DIR/<variant>/<env>/s<seed>``; the report
(:mod:`simoun_lab.sweep.report`) is written when the sweep ends.
"""

from __future__ import annotations

import signal
import sys
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from types import ModuleType
from typing import Any

from simoun_agent.config import SetupError
from simoun_agent.config.device import device_key
from simoun_agent.run.atomic import atomic_write
from simoun_agent.run.kept import present
from simoun_lab.engine.launcher import run_trials
from simoun_lab.engine.trial import Trial as EngineTrial
from simoun_lab.sweep.grid import SweepSpec, Trial, gpus_wanted
from simoun_lab.sweep.report import error_line
from simoun_lab.sweep.trainable import ERROR_FILE, STOP_FILE, SacTrial, finished


def gpus_per_trial(ray: ModuleType, wanted: str, device: str | None) -> float:
    """``auto``: one GPU per trial when the cluster has GPUs and the config's ``device`` is not
    ``cpu``, else none; or the number given."""
    gpus = gpus_wanted(wanted)
    if gpus is None:
        has_gpus = ray.cluster_resources().get("GPU", 0) > 0
        if not has_gpus and device is not None and device.startswith("cuda"):
            raise SetupError(
                f"the trials train on device {device} (--device, or a study's [base] device), "
                "but the Ray cluster has no GPU (so gpus_per_trial auto gives them none); train "
                "on device cpu, or run on a cluster with GPUs"
            )
        return 1.0 if has_gpus and device_key(device) not in ("cpu", "mps") else 0.0
    return gpus


def check_fits(ray: ModuleType, cpus: int, gpus: float) -> None:
    """A trial that no machine can hold would wait forever: refuse it now."""
    have = ray.cluster_resources()
    for name, need, flag in (("CPU", cpus, "--cpus-per-trial"), ("GPU", gpus, "--gpus-per-trial")):
        if need > have.get(name, 0):
            raise SetupError(
                f"each trial asks for {need:g} {name}{'s' * (need != 1)} ({flag}) but the Ray "
                f"cluster has {have.get(name, 0):g}; lower {flag} or add machines"
            )


def sac_trials(trials: list[Trial], stop_file: Path) -> list[SacTrial]:
    """The sweep's trials as the engine runs them, each stopping once ``stop_file`` appears."""
    return [SacTrial(trial, trial.name, str(stop_file)) for trial in trials]


def run_sweep(
    ray: ModuleType, spec: SweepSpec, sweep_dir: Path, gpus: float, verbose: int
) -> dict[str, list[SacTrial]]:
    """Run the unfinished trials on Tune; returns them grouped as finished / failed / stopped."""
    trials = [trial for trial in spec.trials(sweep_dir) if not finished(trial)]
    resources = {"cpu": spec.cpus_per_trial, "gpu": gpus}
    todo = sac_trials(trials, sweep_dir / STOP_FILE)
    return run_trials(todo, sweep_dir / "tune", resources, verbose)


@contextmanager
def stop_trials_on_sigterm(sweep_dir: Path) -> Iterator[list[bool]]:
    """On the first SIGTERM, write the sweep's STOP file: every trial checkpoints at its next
    step and ends unfinished, and Tune returns; a second SIGTERM stops at once. The yielded list
    gets an entry once SIGTERM came."""
    came: list[bool] = []

    def handler(signum: int, frame: Any) -> None:
        if came:
            raise KeyboardInterrupt
        came.append(True)
        atomic_write(sweep_dir / STOP_FILE, lambda tmp: tmp.write_text("SIGTERM\n"))

    previous = signal.signal(signal.SIGTERM, handler)
    try:
        yield came
    finally:
        signal.signal(signal.SIGTERM, previous)
        (sweep_dir / STOP_FILE).unlink(missing_ok=True)


def summarize(
    outcome: dict[str, Sequence[Trial | EngineTrial]],
    sweep_dir: Path,
    written: list[Path],
    terminated: bool = False,
    resume: str | None = None,
    unwritten: str | None = None,
) -> int:
    """Say what happened to each trial and how to go on (``resume``: the command that continues,
    by default simoun-sweep's); the exit status. ``unwritten``: why the closing report could not
    be written (a damaged file it names, with the fix, and the command that writes the report
    once it is fixed), said as an error: status 1 when nothing
    else failed, since the report is the sweep's result."""
    resume = resume or f"simoun-sweep --resume --sweep-dir {sweep_dir}"
    for trial in outcome.get("failed", []):
        error = Path(trial.run_dir) / ERROR_FILE
        last = error_line(error) if present(error) else "see Tune's log"
        print(f"FAILED {trial.name}: {last} (traceback: {error})", file=sys.stderr)
    if written:
        print(f"report: {', '.join(map(str, written))}")
    if unwritten:
        print(f"report not written: {unwritten}", file=sys.stderr)
    if outcome.get("stopped"):
        print(
            f"stopped with {len(outcome['stopped'])} trials unfinished; continue with: {resume}",
            file=sys.stderr,
        )
        return 143 if terminated else 130
    if outcome.get("failed"):
        print(
            f"{len(outcome['failed'])} trials failed, the others finished; fix the cause and "
            f"rerun them with: {resume}",
            file=sys.stderr,
        )
        return 1
    return 1 if unwritten else 0
