"""The study on Ray Tune: every unfinished run as a trial, two at a time, one torch thread each,
each finished run's files copied into the archive as its trial reports them.

Resuming: a run whose ``summary.json`` is in the archive is finished and skipped. A run in
progress reports each checkpoint it writes to Tune (kept in Tune's storage, the latest only),
and the study copies it into the archive as ``<run>/checkpoint.pt``, where it stays until the
run finishes: committed with the archive, it outlives the machine. A run ended mid-way goes on
from the checkpoint in its run directory, ``<work_dir>/runs/<task>/<arm>/s<seed>``, when that
is still there, else from the archive's, else from scratch. The files travel in the trial's
result and the archived checkpoints in Ray's object store (not through a shared disk), so
trials on the machines of a Ray cluster (``--address``) archive on the machine that runs the
study; Tune's own checkpoint storage there needs the cluster's shared ``storage_path``, as Ray
documents.
"""

from __future__ import annotations

import json
import os
import shutil
import tempfile
from datetime import datetime, timezone
from pathlib import Path
from typing import Any

from simoun_agent.config import SetupError
from simoun_agent.run.atomic import atomic_write
from simoun_lab.minigrid_study.checkpoint import CHECKPOINT
from simoun_lab.minigrid_study.run import RUN_FILES, SUMMARY, train_run
from simoun_lab.minigrid_study.spec import StudySpec, spec_from_dict
from simoun_lab.minigrid_study.training import write_json
from simoun_lab.study.provenance import code_version
from simoun_lab.sweep.launch import connect, load_ray

__all__ = ["SPEC_FILE", "finished_runs", "run_study"]

SPEC_FILE = "spec.json"
"""the spec the archive's runs were trained with"""

RUNS_DIR = "runs"
"""the run directories under the work directory, kept across invocations for resuming"""


def finished_runs(spec: StudySpec, archive: Path) -> list[str]:
    """The names of the spec's runs whose summary is in the archive."""
    return [run.name for run in spec.runs() if (archive / run.name / SUMMARY).is_file()]


def record_spec(spec: StudySpec, archive: Path) -> None:
    """Write the spec into the archive, or refuse a spec that differs from the one there (the
    finished runs would be compared with runs of another design)."""
    path = archive / SPEC_FILE
    wanted = spec.to_json()
    if path.is_file():
        recorded = json.loads(path.read_text())
        if recorded != wanted:
            changed = sorted(k for k in wanted if recorded.get(k) != wanted[k])
            raise SetupError(
                f"--archive {archive} holds runs of another spec (keys {changed} differ from "
                f"{path}); pass the spec it was run with, or a new --archive"
            )
        return
    archive.mkdir(parents=True, exist_ok=True)
    write_json(path, wanted)


def archived_checkpoints(archive: Path, names: list[str]) -> dict[str, bytes]:
    """The archived checkpoints of the runs ``names`` that have one, by run name."""
    paths = {name: archive / name / CHECKPOINT for name in names}
    return {name: path.read_bytes() for name, path in paths.items() if path.is_file()}


def report_checkpoint(path: Path) -> None:
    """Hand the run's checkpoint file ``path`` to Tune, which persists it in its storage."""
    from ray import tune

    # a hard link (so on path's file system): Tune copies the file, and we need not
    with tempfile.TemporaryDirectory(dir=path.parent) as folder:
        os.link(path, Path(folder) / CHECKPOINT)
        tune.report({"finished": 0}, checkpoint=tune.Checkpoint.from_directory(folder))


def trainable(
    config: dict[str, Any],
    spec: dict[str, Any],
    commit: str | None,
    work_dir: str,
    resume: dict[str, bytes],
) -> None:
    """One Tune trial: train the run ``config["run"]`` in its run directory under ``work_dir``
    (from the checkpoint an earlier trial left there, else from its archived one in ``resume``;
    not again if it finished there), reporting each checkpoint, then report its files."""
    from ray import tune

    study = spec_from_dict(spec, "the study's spec")
    run = {r.name: r for r in study.runs()}[config["run"]]
    run_dir = Path(work_dir) / RUNS_DIR / run.name
    if not (run_dir / SUMMARY).is_file():
        if not (run_dir / CHECKPOINT).is_file() and run.name in resume:
            run_dir.mkdir(parents=True, exist_ok=True)
            saved = resume[run.name]
            atomic_write(run_dir / CHECKPOINT, lambda tmp: tmp.write_bytes(saved))
        train_run(study, run, run_dir, commit=commit, on_checkpoint=report_checkpoint)
    files = {name: (run_dir / name).read_text() for name in RUN_FILES}
    tune.report({"finished": 1, "files_json": json.dumps(files)})


def archive_files(archive: Path, name: str, files: dict[str, str]) -> None:
    """Write a finished run's files under ``archive/name``, each atomically, the summary last,
    then remove the run's archived checkpoint."""
    run_dir = archive / name
    run_dir.mkdir(parents=True, exist_ok=True)
    for file in sorted(files, key=lambda f: f == SUMMARY):
        text = files[file]
        atomic_write(run_dir / file, lambda tmp, text=text: tmp.write_text(text))
    (run_dir / CHECKPOINT).unlink(missing_ok=True)


def archive_checkpoint(archive: Path, name: str, folder: str) -> None:
    """Copy the checkpoint in a Tune checkpoint's ``folder`` to ``archive/name``, atomically
    (an interrupted copy keeps the previous one)."""
    target = archive / name / CHECKPOINT
    target.parent.mkdir(parents=True, exist_ok=True)
    atomic_write(target, lambda tmp: shutil.copyfile(Path(folder) / CHECKPOINT, tmp))


def archive_callback(archive: Path) -> Any:
    """A Tune callback that archives each run's checkpoints as its trial saves them, and its
    files as it reports them."""
    from ray import tune

    class ArchiveOnResult(tune.Callback):
        def on_trial_result(self, iteration: int, trials: list, trial: Any, result: dict, **info):
            if "files_json" in result:
                archive_files(archive, trial.config["run"], json.loads(result["files_json"]))

        def on_checkpoint(self, iteration: int, trials: list, trial: Any, checkpoint, **info):
            with checkpoint.as_directory() as folder:
                archive_checkpoint(archive, trial.config["run"], folder)

    return ArchiveOnResult()


def run_study(
    spec: StudySpec,
    archive: Path,
    work_dir: Path,
    address: str | None = None,
    concurrent: int = 2,
    verbose: int = 1,
) -> dict[str, list[str]]:
    """Run every unfinished run of ``spec`` (Ray Tune's records under ``work_dir``), archiving
    each as it finishes; returns the run names grouped as skipped (finished before), finished
    and failed."""
    if concurrent < 1:
        raise SetupError(f"--concurrent must be >= 1, got {concurrent}")
    record_spec(spec, archive)
    done = set(finished_runs(spec, archive))
    todo = [run.name for run in spec.runs() if run.name not in done]
    print(f"{len(done)} of {len(spec.runs())} runs finished in {archive}; {len(todo)} to run")
    resume = archived_checkpoints(archive, todo)
    if resume:
        print(f"from the archive's checkpoints: {', '.join(sorted(resume))}")
    outcome = {"skipped": sorted(done), "finished": [], "failed": []}
    if not todo:
        return outcome
    ray = load_ray()
    from ray import tune

    started = connect(ray, address, None)
    try:
        tuner = tune.Tuner(
            tune.with_resources(
                tune.with_parameters(
                    trainable,
                    spec=spec.to_json(),
                    commit=code_version()["commit"],
                    work_dir=str(work_dir.resolve()),
                    resume=resume,
                ),
                {"cpu": 1},
            ),
            param_space={"run": tune.grid_search(todo)},
            tune_config=tune.TuneConfig(
                trial_name_creator=lambda t: t.config["run"].replace("/", "_"),
                trial_dirname_creator=lambda t: t.config["run"].replace("/", "_"),
                max_concurrent_trials=concurrent,
            ),
            run_config=tune.RunConfig(
                name="minigrid_study-" + datetime.now(timezone.utc).strftime("%Y%m%d-%H%M%S"),
                storage_path=str(work_dir.resolve()),
                failure_config=tune.FailureConfig(max_failures=0, fail_fast=False),
                verbose=verbose,
                checkpoint_config=tune.CheckpointConfig(num_to_keep=1),
                callbacks=[archive_callback(archive)],
            ),
        )
        tuner.fit()
    finally:
        if started:
            ray.shutdown()
    now_done = set(finished_runs(spec, archive))
    outcome["finished"] = [name for name in todo if name in now_done]
    outcome["failed"] = [name for name in todo if name not in now_done]
    return outcome
