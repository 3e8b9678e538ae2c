"""Running a grid of training runs on Ray Tune (the library under ``simoun-sweep``,
:mod:`simoun_lab.cli.sweep`, and ``simoun-study``): Ray's start, the trials as one Tune
experiment, the STOP file on SIGTERM and the summary of what happened.

Each trial is an ordinary run directory ``SWEEP_DIR/<variant>/<env>/s<seed>``; the report
(:mod:`simoun_lab.sweep.report`) is written when the sweep ends.
"""

from __future__ import annotations

import json
import signal
import socket
import sys
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from datetime import datetime, timezone
from pathlib import Path
from types import ModuleType
from typing import Any

from simoun_agent.config import SetupError
from simoun_agent.run.atomic import atomic_write
from simoun_agent.run.layout import SUMMARY_NAME
from simoun_lab.sweep.grid import SweepSpec, Trial
from simoun_lab.sweep.trainable import (
    ERROR_FILE,
    STOP_FILE,
    run_trial,
    trial_budget,
    trial_table,
)

CONNECT_TIMEOUT_S = 5.0
"""How long ``--address HOST:PORT`` may take to answer before the sweep gives up."""


def load_ray() -> ModuleType:
    """Ray, or a SetupError saying how to install it."""
    try:
        import ray
        from ray import tune  # noqa: F401  (fails too when ray is there without the tune extra)
    except ImportError:
        raise SetupError(
            "simoun-sweep runs on Ray Tune, which is not installed; install it with: "
            "pip install 'simoun[lab]'"
        ) from None
    return ray


def connect(ray: ModuleType, address: str | None, num_cpus: int | None) -> bool:
    """Start a local Ray instance (``address`` None) or join a cluster (``auto``, ``HOST:PORT``,
    ``ray://HOST:PORT``); an address where no Ray cluster answers fails within seconds.

    Returns whether Ray was started here (False when this process had already initialized it,
    e.g. a notebook that called ``ray.init`` itself): only then does the sweep shut it down.
    """
    if ray.is_initialized():
        return False
    if address is None:
        ray.init(address="local", num_cpus=num_cpus, include_dashboard=False)
        return True
    fix = (
        "start a cluster with `ray start --head` (and `ray start --address HEAD:6379` on the "
        "other machines), or drop --address to run on a local Ray instance"
    )
    if address != "auto":
        host, _, port = address.removeprefix("ray://").rpartition(":")
        if not host or not port.isdigit():
            raise SetupError(f"--address {address!r} is not HOST:PORT, ray://HOST:PORT or auto")
        problem = probe_tcp(host, int(port)) if address.startswith("ray://") else probe_gcs(address)
        if problem:
            raise SetupError(f"--address {address}: no Ray cluster answers ({problem}); {fix}")
    try:
        ray.init(address=address)
    except (ConnectionError, RuntimeError, ValueError) as err:
        raise SetupError(f"--address {address}: cannot join a Ray cluster ({err}); {fix}") from None
    return True


def probe_tcp(host: str, port: int) -> str | None:
    """Why nothing listens at ``host:port``, or None when something does."""
    try:
        socket.create_connection((host, port), timeout=CONNECT_TIMEOUT_S).close()
    except OSError as err:
        return err.strerror or str(err)
    return None


def probe_gcs(address: str) -> str | None:
    """Why no Ray head (GCS) answers at ``address``, or None when one does.

    ``ray.init`` retries a silent or foreign server for about 20 s; one gRPC call with a
    deadline answers at once. A head that wants an auth token still proves it is there.
    """
    import grpc
    from ray.core.generated import gcs_service_pb2, gcs_service_pb2_grpc

    with grpc.insecure_channel(address) as channel:
        stub = gcs_service_pb2_grpc.NodeInfoGcsServiceStub(channel)
        try:
            stub.GetClusterId(gcs_service_pb2.GetClusterIdRequest(), timeout=CONNECT_TIMEOUT_S)
        except grpc.RpcError as err:
            if err.code() != grpc.StatusCode.UNAUTHENTICATED:
                return f"{err.code().name}: {err.details()}"
    return None


def gpus_per_trial(ray: ModuleType, wanted: str, device: str | None) -> float:
    """``auto``: one GPU per trial when the cluster has GPUs and the config's ``device`` is not
    ``cpu``, else none; or the number given."""
    if wanted == "auto":
        has_gpus = ray.cluster_resources().get("GPU", 0) > 0
        return 1.0 if has_gpus and device != "cpu" else 0.0
    try:
        gpus = float(wanted)
    except ValueError:
        raise SetupError(f"--gpus-per-trial takes a number or auto, got {wanted!r}") from None
    if gpus < 0:
        raise SetupError(f"--gpus-per-trial must be 0 or more, got {wanted}")
    return gpus


def check_fits(ray: ModuleType, cpus: int, gpus: float) -> None:
    """A trial that no machine can hold would wait forever: refuse it now."""
    have = ray.cluster_resources()
    for name, need, flag in (("CPU", cpus, "--cpus-per-trial"), ("GPU", gpus, "--gpus-per-trial")):
        if need > have.get(name, 0):
            raise SetupError(
                f"each trial asks for {need:g} {name}s ({flag}) but the Ray cluster has "
                f"{have.get(name, 0):g}; lower {flag} or add machines"
            )


def finished(trial: Trial) -> bool:
    """True once the trial's run has ended at the sweep's budget (a sweep extended with a larger
    ``--total-env-steps`` makes its finished runs unfinished again)."""
    path = Path(trial.run_dir) / SUMMARY_NAME
    if not path.is_file():
        return False
    try:
        done = json.loads(path.read_text())["env_step"]
    except (json.JSONDecodeError, KeyError, TypeError, UnicodeDecodeError):
        return True  # damaged: the report names it; training cannot tell how far the run got
    return done >= trial_budget(trial)


def run_sweep(
    ray: ModuleType, spec: SweepSpec, sweep_dir: Path, gpus: float, verbose: int
) -> dict[str, list[Trial]]:
    """Run the unfinished trials on Tune; returns them grouped as finished / failed / stopped."""
    trials = [trial for trial in spec.trials(sweep_dir) if not finished(trial)]
    return run_trials(trials, sweep_dir, spec.cpus_per_trial, gpus, verbose)


def run_trials(
    trials: list[Trial],
    sweep_dir: Path,
    cpus_per_trial: int,
    gpus: float,
    verbose: int,
    callbacks: Sequence[Any] = (),
    max_concurrent_trials: int | None = None,
    name: str = "",
) -> dict[str, list[Trial]]:
    """Run ``trials`` as one Tune experiment under ``sweep_dir/tune``, named ``name`` and the
    UTC time (``callbacks``: Tune callbacks, e.g. ``simoun-study``'s archiving;
    ``max_concurrent_trials`` None: as many as fit); returns them grouped as finished / failed /
    stopped."""
    from ray import tune

    stamp = name + datetime.now(timezone.utc).strftime("%Y%m%d-%H%M%S")
    tuner = tune.Tuner(
        tune.with_resources(
            tune.with_parameters(
                run_trial, trials=trial_table(trials), stop_file=str(sweep_dir / STOP_FILE)
            ),
            {"cpu": cpus_per_trial, "gpu": gpus},
        ),
        param_space={"trial": tune.grid_search([trial.name for trial in trials])},
        tune_config=tune.TuneConfig(
            trial_name_creator=lambda t: t.config["trial"],
            reuse_actors=True,
            max_concurrent_trials=max_concurrent_trials,
        ),
        run_config=tune.RunConfig(
            name=stamp,
            storage_path=str((sweep_dir / "tune").resolve()),
            failure_config=tune.FailureConfig(max_failures=0, fail_fast=False),
            verbose=verbose,
            callbacks=list(callbacks),
        ),
    )
    results = tuner.fit()
    errors = {result.config["trial"]: result.error for result in results if result.error}
    outcome: dict[str, list[Trial]] = {"finished": [], "failed": [], "stopped": []}
    for trial in trials:
        if finished(trial):
            outcome["finished"].append(trial)
        elif trial.name in errors or (Path(trial.run_dir) / ERROR_FILE).is_file():
            outcome["failed"].append(trial)
        else:
            outcome["stopped"].append(trial)
    return outcome


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
    outcome: dict[str, list[Trial]],
    sweep_dir: Path,
    written: list[Path],
    terminated: bool = False,
    resume: str | None = None,
) -> int:
    """Say what happened to each trial and how to go on (``resume``: the command that continues,
    by default simoun-sweep's); the exit status."""
    resume = resume or f"simoun-sweep --resume --sweep-dir {sweep_dir}"
    for trial in outcome.get("failed", []):
        error = Path(trial.run_dir) / ERROR_FILE
        last = error.read_text().strip().splitlines()[-1] if error.is_file() else "see Tune's log"
        print(f"FAILED {trial.name}: {last} (traceback: {error})", file=sys.stderr)
    if written:
        print(f"report: {', '.join(map(str, written))}")
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
    return 0
