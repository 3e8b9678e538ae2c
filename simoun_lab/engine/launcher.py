"""Running a list of :class:`~simoun_lab.engine.trial.Trial` on Ray Tune as one experiment, with
an optional archive: the one launcher and archiver of ``simoun-sweep``, ``simoun-study`` and the
MiniGrid study.

Each unfinished trial trains in its run directory. With an archive, a trial hands each
checkpoint it writes to Tune (kept in Tune's storage, the latest only), and the engine copies it
into the archive as ``<name>/<checkpoint>``, where it stays until the run finishes: committed
with the archive, it outlives the machine. A finished trial reports its ``run_files`` in its
result and the engine writes them into the archive (``summary.json`` last) and removes the
archived checkpoint. A trial ended mid-way goes on from the checkpoint in its run directory when
that is still there, else from the archive's. Files travel in the trial's result and archived
checkpoints in Ray's object store (not through a shared disk), so trials on the machines of a Ray
cluster archive on the machine that launched them; Tune's own checkpoint storage there needs the
cluster's shared storage path, as Ray documents.
"""

from __future__ import annotations

import json
import os
import shutil
import tempfile
from collections.abc import Sequence
from datetime import datetime, timezone
from pathlib import Path
from typing import Any

from simoun_agent.config import SetupError
from simoun_agent.config.device import device_keys
from simoun_agent.run.atomic import atomic_write
from simoun_agent.run.kept import Damaged, present, read_text
from simoun_lab.engine.trial import SUMMARY, Trial, summary_written

__all__ = ["archive_files", "changed_keys", "read_run_files", "run_trials"]

FILES_KEY = "files_json"
"""the key of a finished trial's result that carries its files"""


def changed_keys(saved: dict[str, Any], wanted: dict[str, Any]) -> list[str]:
    """The keys of two specs (as JSON objects) whose values differ: a study refuses to go on
    under another spec, whose runs it would compare with the finished ones."""
    saved, wanted = device_keys(saved), device_keys(wanted)  # a device however it is spelled
    return [key for key in {**saved, **wanted} if saved.get(key) != wanted.get(key)]


def read_run_files(run_dir: Path, names: Sequence[str]) -> dict[str, str]:
    """The text of each file of ``names`` that ``run_dir`` holds, in the order of ``names``;
    SetupError naming a damaged one, which the archive must not take for the run's."""
    files = {}
    for name in names:
        path = run_dir / name
        if not present(path):
            continue
        try:
            files[name] = read_text(path)
        except Damaged as err:
            raise SetupError(
                f"{path} is damaged: {err}; restore it from a copy, or move the run directory "
                f"aside (mv {run_dir} {run_dir}.damaged) and run the study again to train the run "
                "anew"
            ) from None
    return files


def archive_files(
    archive: Path, name: str, files: dict[str, str], checkpoint: str | None = None
) -> None:
    """Write a finished run's ``files`` under ``archive/name``, each atomically, the summary last
    (its presence marks a whole copy), then remove the run's archived ``checkpoint``."""
    run_dir = archive / name
    run_dir.mkdir(parents=True, exist_ok=True)
    for file in sorted(files, key=lambda f: f == SUMMARY):
        text = files[file]
        atomic_write(run_dir / file, lambda tmp, text=text: tmp.write_text(text))
    if checkpoint is not None:
        (run_dir / checkpoint).unlink(missing_ok=True)


def archived_checkpoints(archive: Path, trials: Sequence[Trial]) -> dict[str, bytes]:
    """The archived checkpoints of the unfinished ``trials`` that have one, by trial name."""
    paths = {t.name: archive / t.name / t.checkpoint for t in trials if t.checkpoint is not None}
    return {name: path.read_bytes() for name, path in paths.items() if path.is_file()}


def report_checkpoint(path: Path) -> None:
    """Hand the run's checkpoint file ``path`` to Tune, which persists it in its storage."""
    from ray import tune

    # a hard link (so on path's file system): Tune copies the file, and we need not
    with tempfile.TemporaryDirectory(dir=path.parent) as folder:
        os.link(path, Path(folder) / path.name)
        tune.report({"finished": 0}, checkpoint=tune.Checkpoint.from_directory(folder))


def train_trial(
    config: dict[str, Any], trials: dict[str, Trial], archiving: bool, resume: dict[str, bytes]
) -> None:
    """Tune's function trainable: train the trial named ``config["trial"]`` in its run directory
    (from the checkpoint an earlier trial left there, else from its archived one in ``resume``;
    not again once finished), reporting each checkpoint and, finished, its files when
    ``archiving``."""
    from ray import tune

    trial = trials[config["trial"]]
    run_dir = Path(trial.run_dir)
    if not trial.finished():
        saved = resume.get(trial.name)
        if saved is not None and not (run_dir / trial.checkpoint).is_file():
            run_dir.mkdir(parents=True, exist_ok=True)
            atomic_write(run_dir / trial.checkpoint, lambda tmp: tmp.write_bytes(saved))
        carry = archiving and trial.checkpoint is not None
        trial.train(report_checkpoint if carry else None)
    if archiving and trial.finished():
        files = read_run_files(run_dir, trial.run_files)
        tune.report({"finished": 1, FILES_KEY: json.dumps(files)})


def archive_callback(archive: Path, table: dict[str, Trial]) -> Any:
    """A Tune callback that archives each run's checkpoints as its trial saves them, and its
    files as it reports them (``table``: the trials by name)."""
    from ray import tune

    class ArchiveOnResult(tune.Callback):
        def on_trial_result(self, iteration: int, trials: list, trial: Any, result: dict, **info):
            if FILES_KEY in result:
                run = table[trial.config["trial"]]
                archive_files(archive, run.name, json.loads(result[FILES_KEY]), run.checkpoint)

        def on_checkpoint(self, iteration: int, trials: list, trial: Any, checkpoint, **info):
            run = table[trial.config["trial"]]
            target = archive / run.name / run.checkpoint
            target.parent.mkdir(parents=True, exist_ok=True)
            with checkpoint.as_directory() as folder:
                source = Path(folder) / run.checkpoint
                # atomically: an interrupted copy keeps the previous checkpoint
                atomic_write(target, lambda tmp: shutil.copyfile(source, tmp))

    return ArchiveOnResult()


def run_trials(
    trials: Sequence[Trial],
    storage: Path,
    resources: dict[str, float],
    verbose: int,
    archive: Path | None = None,
    max_concurrent_trials: int | None = None,
    name: str = "",
) -> dict[str, list[Trial]]:
    """Run ``trials`` (Ray started) as one Tune experiment under ``storage``, named ``name`` and
    the UTC time, each with ``resources`` (``{"cpu": 1}``), ``max_concurrent_trials`` at a time
    (None: as many as fit), archiving into ``archive`` when given; returns them grouped as
    finished / failed / stopped (a trial asked to stop ends unfinished without an error)."""
    from ray import tune

    table = {trial.name: trial for trial in trials}
    resume: dict[str, bytes] = {}
    callbacks = []
    if archive is not None:
        resume = archived_checkpoints(archive, trials)
        if resume:
            print(f"from the archive's checkpoints: {', '.join(sorted(resume))}", flush=True)
        callbacks.append(archive_callback(archive, table))
    stamp = name + datetime.now(timezone.utc).strftime("%Y%m%d-%H%M%S")
    tuner = tune.Tuner(
        tune.with_resources(
            tune.with_parameters(
                train_trial, trials=table, archiving=archive is not None, resume=resume
            ),
            resources,
        ),
        param_space={"trial": tune.grid_search(list(table))},
        tune_config=tune.TuneConfig(
            trial_name_creator=lambda t: t.config["trial"],
            trial_dirname_creator=lambda t: t.config["trial"].replace("/", "_"),
            reuse_actors=True,
            max_concurrent_trials=max_concurrent_trials,
        ),
        run_config=tune.RunConfig(
            name=stamp,
            storage_path=str(storage.resolve()),
            failure_config=tune.FailureConfig(max_failures=0, fail_fast=False),
            verbose=verbose,
            checkpoint_config=tune.CheckpointConfig(num_to_keep=1),
            callbacks=callbacks,
        ),
    )
    results = tuner.fit()
    errors = {result.config["trial"] for result in results if result.error}
    outcome: dict[str, list[Trial]] = {"finished": [], "failed": [], "stopped": []}
    for trial in trials:
        archived = archive is not None and summary_written(archive / trial.name)
        if trial.finished() or archived:
            outcome["finished"].append(trial)
        elif trial.name in errors:
            outcome["failed"].append(trial)
        else:
            outcome["stopped"].append(trial)
    return outcome
