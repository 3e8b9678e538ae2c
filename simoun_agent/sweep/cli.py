"""``simoun-sweep``: a grid of training runs on Ray Tune, on this machine or a Ray cluster.

    simoun-sweep --preset cpu --grid agent.recipe=simoun,drq,curl --seeds 0-4 --sweep-dir sw
    simoun-sweep --resume --sweep-dir sw              # after Ctrl-C: finish what is unfinished
    simoun-sweep --address auto --preset cheetah-run --grid agent.recipe=simoun,drq --seeds 0-4

The base config is given exactly as to ``simoun-train`` (``--preset``, every config flag,
``--set KEY=VALUE``). Each trial is an ordinary run directory ``SWEEP_DIR/<variant>/<env>/s<seed>``;
the report (:mod:`simoun_agent.sweep.report`) is written when the sweep ends.
"""

from __future__ import annotations

import argparse
import signal
import socket
import sys
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from datetime import datetime, timezone
from pathlib import Path
from types import ModuleType
from typing import Any

from simoun_agent.config import RECIPES, SetupError, resolve
from simoun_agent.run import train
from simoun_agent.run.checkpoint import atomic_write
from simoun_agent.sweep import report
from simoun_agent.sweep.grid import SWEEP_FILE, SweepSpec, Trial
from simoun_agent.sweep.trainable import ERROR_FILE, STOP_FILE, run_trial, trial_table

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
            "pip install 'simoun[sweep]'"
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


def sweep_spec(args: argparse.Namespace, sweep_dir: Path) -> SweepSpec:
    """The sweep to run: from the flags, or the saved one on ``--resume`` (which the flags, when
    given, must match)."""
    base = train.overrides_from(args)
    given = bool(args.grid or args.seeds or args.envs or base or args.preset)
    if not args.resume:
        if (sweep_dir / SWEEP_FILE).exists():
            raise SetupError(
                f"{sweep_dir} already holds a sweep; continue it with --resume, or pass another "
                "--sweep-dir"
            )
        if sweep_dir.exists() and any(sweep_dir.iterdir()):
            raise SetupError(f"{sweep_dir} is not empty; pass a new --sweep-dir")
        cpus = 1 if args.cpus_per_trial is None else args.cpus_per_trial
        return SweepSpec.create(args.preset, base, args.grid, args.seeds, args.envs, cpus)
    saved = SweepSpec.load(sweep_dir)
    if not given and args.cpus_per_trial in (None, saved.cpus_per_trial):
        return saved
    spec = SweepSpec.create(
        args.preset,
        base,
        args.grid,
        args.seeds,
        args.envs,
        saved.cpus_per_trial if args.cpus_per_trial is None else args.cpus_per_trial,
    )
    differences = spec.describe_differences(saved)
    if differences:
        raise SetupError(
            f"the sweep in {sweep_dir} was started with another grid, so --resume cannot continue "
            f"it ({'; '.join(differences)}); give the flags it was started with (or only "
            f"--resume --sweep-dir {sweep_dir}), or start a new sweep in another --sweep-dir"
        )
    return saved


def finished(trial: Trial) -> bool:
    return (Path(trial.run_dir) / train.SUMMARY_NAME).is_file()


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


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="simoun-sweep",
        usage="simoun-sweep --sweep-dir DIR [--grid KEY=V1,V2 ...] [--seeds 0-4] [--envs A,B] "
        "[--preset NAME] [--KEY VALUE ...] [--resume] [--address auto|HOST:PORT]",
        description="Run a grid of simoun-train runs (variants x envs x seeds) on Ray Tune, on "
        "this machine or a Ray cluster, then write the report (simoun-report).",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        allow_abbrev=False,
        epilog="examples:\n"
        "  simoun-sweep --preset cpu --grid agent.recipe=simoun,drq,curl,sac --seeds 0-4 "
        "--sweep-dir sweeps/baselines\n"
        "  simoun-sweep --resume --sweep-dir sweeps/baselines\n"
        "  simoun-sweep --address auto --preset walker-walk --grid agent.recipe=simoun,drq "
        "--seeds 0-4 --sweep-dir /shared/sweeps/walker\n\n"
        f"agent recipes (--grid agent.recipe=A,B): {', '.join(RECIPES)}\n"
        "Each trial runs in SWEEP_DIR/<variant>/<env>/s<seed>, an ordinary run directory.",
    )
    sweep = parser.add_argument_group("sweep")
    sweep.add_argument(
        "--sweep-dir",
        metavar="DIR",
        help="where the runs and the report go (default: sweeps/<UTC time>; required with "
        "--resume); on a cluster, a directory every machine sees",
    )
    sweep.add_argument(
        "--grid",
        action="append",
        default=[],
        metavar="KEY=V1,V2",
        help="a config key and the values to try (repeatable: the variants are the product), "
        "e.g. --grid agent.recipe=simoun,drq",
    )
    sweep.add_argument(
        "--seeds",
        metavar="SEEDS",
        help="seeds of each variant, e.g. 0-4 or 0,2,5 (default: --seed)",
    )
    sweep.add_argument(
        "--envs", metavar="ID,ID", help="Gymnasium ids to run every variant on (default: --env)"
    )
    sweep.add_argument(
        "--cpus-per-trial",
        type=int,
        metavar="N",
        help="CPUs per trial; the trial uses as many torch threads (default: 1)",
    )
    sweep.add_argument(
        "--gpus-per-trial",
        default="auto",
        metavar="N|auto",
        help="GPUs per trial, fractions allowed; auto: 1 when the cluster has GPUs and --device "
        "is not cpu, else 0",
    )
    sweep.add_argument(
        "--address",
        metavar="auto|HOST:PORT|ray://HOST:PORT",
        help="run on a Ray cluster (auto: the one `ray start` made on this machine); default: a "
        "local Ray instance",
    )
    sweep.add_argument(
        "--num-cpus",
        type=int,
        metavar="N",
        help="CPUs of the local Ray instance (default: this machine's)",
    )
    sweep.add_argument(
        "--resume",
        action="store_true",
        help="continue the sweep in --sweep-dir: finished trials are skipped, the others go on "
        "from their checkpoints",
    )
    sweep.add_argument(
        "--verbose", type=int, default=1, choices=(0, 1, 2), help="Tune's output (default: 1)"
    )
    train.add_config_arguments(parser)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Entry point of ``simoun-sweep``."""
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.resume and not args.sweep_dir:
        parser.exit(2, "simoun-sweep: error: --resume needs the --sweep-dir of the sweep\n")
    stamp = datetime.now(timezone.utc).strftime("%Y%m%d-%H%M%S")
    # absolute: Tune runs each trial in a working directory of its own
    sweep_dir = Path(args.sweep_dir or Path("sweeps") / stamp).absolute()
    try:
        ray = load_ray()
        spec = sweep_spec(args, sweep_dir)
    except SetupError as err:
        parser.exit(2, f"simoun-sweep: error: {err}\n")
    todo = [trial for trial in spec.trials(sweep_dir) if not finished(trial)]
    done = len(spec.trials(sweep_dir)) - len(todo)
    print(f"sweep {sweep_dir}: {len(todo)} trials to run, {done} already finished", flush=True)
    terminated: list[bool] = []
    if todo:
        started = False
        try:
            started = connect(ray, args.address, args.num_cpus)
            device = spec.base.get("device", resolve(spec.preset, {}).device)
            gpus = gpus_per_trial(ray, args.gpus_per_trial, device)
            check_fits(ray, spec.cpus_per_trial, gpus)
            sweep_dir.mkdir(parents=True, exist_ok=True)
            if not (sweep_dir / SWEEP_FILE).exists():
                spec.save(sweep_dir)
            (sweep_dir / STOP_FILE).unlink(missing_ok=True)
            with stop_trials_on_sigterm(sweep_dir) as came:
                terminated = came
                outcome = run_sweep(ray, spec, sweep_dir, gpus, args.verbose)
        except SetupError as err:
            parser.exit(2, f"simoun-sweep: error: {err}\n")
        except KeyboardInterrupt:
            outcome = {"stopped": todo}
        finally:
            if started:
                ray.shutdown()
    else:
        outcome = {}
    try:
        written = report.write_report(sweep_dir)
    except SetupError:  # no trial got as far as writing its config.json
        written = []
    return summarize(outcome, sweep_dir, written, bool(terminated))


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


if __name__ == "__main__":
    sys.exit(main())
