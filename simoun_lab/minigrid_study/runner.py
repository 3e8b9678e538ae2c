"""The MiniGrid study on the engine (:mod:`simoun_lab.engine.launcher`): every unfinished run
as a :class:`~simoun_lab.minigrid_study.trial.MiniGridTrial`, two at a time, one torch thread
each, each finished run's files and each in-progress checkpoint copied into the archive.

Resuming: a run whose ``summary.json`` is in the archive is finished and skipped. A run ended
mid-way goes on from the checkpoint in its run directory, ``<work_dir>/runs/<task>/<arm>/s<seed>``,
when that is still there, else from the archive's ``<run>/checkpoint.pt``, else from scratch.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from simoun_agent.config import SetupError
from simoun_agent.run.kept import Damaged, checkpoint_problem, present, read_json_object
from simoun_lab.engine.launcher import changed_keys, run_trials
from simoun_lab.engine.ray_start import connect, load_ray
from simoun_lab.engine.trial import check_no_live_runs, summary_written
from simoun_lab.minigrid_study.checkpoint import CHECKPOINT
from simoun_lab.minigrid_study.report import finished as checked_finished
from simoun_lab.minigrid_study.run import SUMMARY
from simoun_lab.minigrid_study.spec import StudySpec, spec_from_dict
from simoun_lab.minigrid_study.training import write_json
from simoun_lab.minigrid_study.trial import RUNS_DIR, MiniGridTrial
from simoun_lab.study.provenance import code_version

__all__ = ["SPEC_FILE", "finished_runs", "load_saved_spec", "run_study"]

SPEC_FILE = "spec.json"
"""the spec the archive's runs were trained with"""


def finished_runs(spec: StudySpec, archive: Path) -> list[str]:
    """The names of the spec's runs whose summary is in the archive."""
    return [run.name for run in spec.runs() if summary_written(archive / run.name)]


def refuse_foreign_runs(spec: StudySpec, archive: Path, source: str) -> None:
    """When none of the spec's runs finished in the archive but it holds finished runs of
    others (a ``spec.json`` of another study copied in), SetupError naming ``source`` (where
    the spec came from): advice to train the spec's runs would mix two studies."""
    names = {run.name for run in spec.runs()}
    others = sorted(
        str(path.parent.relative_to(archive))
        for path in archive.glob(f"*/*/*/{SUMMARY}")
        if str(path.parent.relative_to(archive)) not in names
    )
    if others:
        raise SetupError(
            f"{archive} holds no finished run of the spec in {source}, but {len(others)} "
            f"finished runs of another spec (e.g. {others[0]}): {source} is another study's. "
            f"Restore the archive's own {SPEC_FILE} from a copy (git checkout -- "
            f"{archive / SPEC_FILE}, for a committed archive), or pass the archive of the study "
            "that spec ran"
        )


def read_saved_spec(path: Path) -> dict[str, Any]:
    """The archive's ``spec.json`` as saved; SetupError naming the file when it is damaged: the
    finished runs cannot be checked against the spec given without it."""
    try:
        return read_json_object(path)
    except Damaged as err:
        problem = str(err)
    raise SetupError(
        f"{path} is damaged: {problem}. Restore it from a copy (git checkout -- {path}, for a "
        "committed archive): it records the spec the archive's runs were trained with"
    )


def load_saved_spec(path: Path) -> StudySpec:
    """The spec in the archive's ``spec.json``; SetupError naming the file when it is damaged."""
    return spec_from_dict(read_saved_spec(path), str(path))


def record_spec(spec: StudySpec, archive: Path) -> None:
    """Write the spec into the archive, or refuse a spec that differs from the one there (the
    finished runs would be compared with runs of another design)."""
    path = archive / SPEC_FILE
    wanted = spec.to_json()
    if present(path):
        changed = sorted(changed_keys(read_saved_spec(path), wanted))
        if changed:
            raise SetupError(
                f"--archive {archive} holds runs of another spec (keys {changed} differ from "
                f"{path}); pass the spec it was run with, or a new --archive"
            )
        return
    archive.mkdir(parents=True, exist_ok=True)
    write_json(path, wanted)


def check_checkpoints(todo: list[MiniGridTrial], archive: Path) -> None:
    """Refuse, before Ray starts, a damaged checkpoint an unfinished run would go on from (in
    its run directory or in the archive): its trial would fail only once it is running."""
    for trial in todo:
        for path in (Path(trial.run_dir, CHECKPOINT), archive / trial.name / CHECKPOINT):
            problem = checkpoint_problem(path) if present(path) else None
            if problem:
                raise SetupError(
                    f"{path} is damaged: {problem}. Restore it from a copy (git checkout -- "
                    f"{path}, for a committed archive), or move it aside (mv {path} "
                    f"{path}.damaged) to train run {trial.name} from the other checkpoint or "
                    "from the start"
                )


def run_study(
    spec: StudySpec,
    archive: Path,
    work_dir: Path,
    address: str | None = None,
    concurrent: int = 2,
    verbose: int = 1,
) -> dict[str, list[str]]:
    """Run every unfinished run of ``spec`` (Ray Tune's records and the run directories under
    ``work_dir``), archiving each as it finishes; returns the run names grouped as skipped
    (finished before), finished and failed."""
    if concurrent < 1:
        raise SetupError(f"--concurrent must be >= 1, got {concurrent}")
    check_no_live_runs(work_dir / RUNS_DIR, "the study")
    record_spec(spec, archive)
    checked_finished(spec, archive)  # before Ray: a damaged finished run fails nothing there
    done = set(finished_runs(spec, archive))
    commit, work = code_version()["commit"], str(work_dir.resolve())
    todo = [MiniGridTrial(spec, run, work, commit) for run in spec.runs() if run.name not in done]
    check_checkpoints(todo, archive)
    print(f"{len(done)} of {len(spec.runs())} runs finished in {archive}; {len(todo)} to run")
    outcome = {"skipped": sorted(done), "finished": [], "failed": []}
    if not todo:
        return outcome
    ray = load_ray()
    started = connect(ray, address, None)
    try:
        ran = run_trials(
            todo, work_dir, {"cpu": 1}, verbose, archive, concurrent, name="minigrid_study-"
        )
    finally:
        if started:
            ray.shutdown()
    outcome["finished"] = [trial.name for trial in ran["finished"]]
    outcome["failed"] = [trial.name for trial in ran["failed"] + ran["stopped"]]
    return outcome
