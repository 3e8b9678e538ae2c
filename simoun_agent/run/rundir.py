"""A run directory's ownership: one trainer at a time, and starting over after a crash.

Two trainers writing one directory would overwrite each other's checkpoints and logs, so a
trainer holds an exclusive ``flock`` on ``<run dir>/.lock`` for the life of its process (the
kernel releases it when the process ends, crash or not); the file names the PID of its holder,
so the second trainer can say whom to wait for.

A run that crashed after set-up and before its first checkpoint leaves ``config.json`` and logs
but nothing to resume from; ``--overwrite`` starts it over in the same directory. A directory
with a checkpoint is never overwritten: it is resumed, or the user deletes it.
"""

from __future__ import annotations

import errno
import fcntl
import os
import shutil
import tempfile
from collections.abc import Iterable
from pathlib import Path
from typing import IO

from simoun_agent.config import SetupError
from simoun_agent.run.kept import (
    DENIED,
    Damaged,
    broken_link,
    not_a_file,
    owner_and_mode,
    read_json_object,
)
from simoun_agent.run.layout import (
    CHECKPOINT_NAME,
    CONFIG_NAME,
    CURVE_PNG,
    EVAL_CSV,
    LOCK_NAME,
    SUMMARY_NAME,
    TENSORBOARD_DIR,
    TRAIN_CSV,
    TRAINER_FILES,
    VIDEO_NAME,
)

_held: dict[Path, IO[str]] = {}
"""The run-directory locks this process holds, by lock file"""


def refuse_a_file(path: Path, flag: str | None) -> None:
    """Raise SetupError naming ``flag`` when the output directory ``path`` is a file; creates
    nothing, so a command can check before work whose failure must leave nothing behind.
    ``flag`` None: a folder the command names itself (``DIR/report/tuning``), which no flag
    moves; the fix is then to move the file aside."""
    if path.exists() and not path.is_dir():
        fix = (
            f"pass a new or existing directory to {flag}"
            if flag
            else f"move it aside (mv {path} {path}.aside) and run the command again"
        )
        raise SetupError(f"the output directory {path} is a file, not a directory; {fix}")


def writable_fix(flag: str | None) -> str:
    """The fix for an output directory that cannot be written: another one by ``flag``, or,
    for a folder the command names itself (``flag`` None), write access to it."""
    if flag:
        return f"pass a writable {flag}"
    return "make it writable (or free space there) and run the command again"


def check_output_files(paths: Iterable[Path], flag: str | None = None) -> None:
    """Raise SetupError naming the first of ``paths``, files a command is about to write, where
    something else than a file stands (a directory, a named pipe ...: an earlier output
    replaced, or made by hand); the fix names ``flag``, the output directory's, where the user
    may pass another. A command checks its files before its work, which the write at its end
    would otherwise lose. A path that is missing, a file, or a link (replaced as it stands) is
    fine."""
    for path in paths:
        problem = None if path.is_symlink() else not_a_file(path)
        if problem:
            other = f"or pass another {flag}" if flag else "and run the command again"
            raise SetupError(
                f"cannot write {path} ({problem}), which this command writes as a file; move "
                f"it aside (mv {path} {path}.aside) {other}"
            )


def output_files(directory: Path, names: Iterable[str]) -> list[Path]:
    """The paths in ``directory`` a command writes, by name or glob pattern (``ep*-step*.png``:
    those an earlier run of it left)."""
    if not directory.is_dir():
        return []
    return [path for name in names for path in sorted(directory.glob(name))]


def copy_fix(path: Path, command: str) -> str:
    """The fix for a folder that cannot be written but holds work to go on with (a run, a
    sweep, a study resumed; an archive read): copy it to a writable place (the user's home)
    and run ``command``, which ends with the folder's flag, on the copy."""
    copy = f"~/{Path(path).absolute().name}"
    return (
        f"copy {path} to a writable place and go on there: cp -r {path} {copy} && {command} {copy}"
    )


def check_output_dir(
    path: Path, flag: str | None, files: Iterable[str] = (), fix: str | None = None
) -> None:
    """Raise SetupError naming ``flag`` when the output directory ``path`` could not be made or
    written: it is a file, a folder on its way is a file or a symbolic link that loops or leads
    nowhere, a name is too long, or the nearest folder of it that exists takes no new folder
    (not writable, a read-only mount, a kernel file system such as /proc); or when one of the
    ``files`` (names or glob patterns) the command writes in it is something else than a file
    (:func:`check_output_files`). Leaves nothing behind (its probe folder is removed at once),
    so a command can check before the work whose set-up takes long (Ray) rather than fail
    after it. ``flag`` None: a folder the command names itself, which the fixes say how to
    free rather than naming a flag the command does not have. ``fix``: the fix to give instead
    (:func:`copy_fix` for a folder whose contents the command goes on with)."""
    try:
        refuse_a_file(path, flag)
        reason = unwritable(path.absolute())
    except (OSError, RuntimeError) as err:  # the path itself cannot be looked at
        reason = getattr(err, "strerror", None) or str(err)
    if reason:
        raise SetupError(
            f"cannot write to the output directory {path} ({reason}); {fix or writable_fix(flag)}"
        )
    check_output_files(output_files(path, files), flag)


def unwritable(path: Path) -> str | None:
    """Why no directory can be made at the absolute ``path``, or None when one can."""
    existing = path
    while not existing.exists() and existing != existing.parent:
        if existing.is_symlink():  # exists() is False for a link that loops or leads nowhere
            try:
                existing.stat()
            except OSError as err:
                return f"{existing} is a symbolic link to {os.readlink(existing)}: {err.strerror}"
            return f"{existing} is a symbolic link that cannot be followed"
        existing = existing.parent
    if not existing.is_dir():
        return f"{existing} is a file"
    if not os.access(existing, os.W_OK | os.X_OK):
        return f"{existing} is not writable"
    try:
        os.rmdir(tempfile.mkdtemp(prefix=".write-test-", dir=existing))
    except OSError as err:
        return f"{existing} takes no new folder: {err.strerror}"
    return None


def make_output_dir(path: Path, flag: str | None = "--out", files: Iterable[str] = ()) -> bool:
    """Create ``path`` (with its parents) and check that it can be written, and that none of
    ``files`` (names or glob patterns) the command writes in it is something else than a file
    (:func:`check_output_dir`). Returns True when it did not exist before, so a caller that
    stops later can remove what it made; raises SetupError naming ``flag`` (and leaves no empty
    directory behind) when it cannot."""
    created = not path.exists()
    check_output_dir(path, flag, files)
    try:
        path.mkdir(parents=True, exist_ok=True)
        probe = path / ".write-test"
        probe.write_text("")
        probe.unlink()
    except OSError as err:
        if created and path.is_dir() and not any(path.iterdir()):
            path.rmdir()
        raise SetupError(
            f"cannot write to the output directory {path} ({err.strerror}); {writable_fix(flag)}"
        ) from None
    return created


WRITTEN_FILES = (
    CONFIG_NAME,
    EVAL_CSV,
    TRAIN_CSV,
    CURVE_PNG,
    VIDEO_NAME,
    CHECKPOINT_NAME,
    SUMMARY_NAME,
    LOCK_NAME,
)
"""The files a trainer writes in its run directory (with the directory ``tb/``)."""

READ_BACK = (CONFIG_NAME, EVAL_CSV, TRAIN_CSV, CHECKPOINT_NAME, SUMMARY_NAME)
"""Those of :data:`WRITTEN_FILES` a resumed run reads back: lost, they come from a copy."""


def wrong_kind(run_dir: Path) -> str | None:
    """What is wrong with the first path a trainer writes in ``run_dir`` that is the wrong kind
    of thing (a directory or a named pipe where a file goes, a file where ``tb/`` goes), with
    the fix; None when each is missing or of its kind. A run that met it would fail after
    training, when it writes the path, or take it for a directory it cannot write to. A
    symbolic link to nothing (a run copied from another machine) is named here where the run
    only writes the path; the files it reads back name theirs when they are read."""
    tensorboard = run_dir / TENSORBOARD_DIR
    link = broken_link(tensorboard)
    if link:
        return (
            f"{tensorboard}, where the run writes its TensorBoard logs, is damaged: {link}. "
            f"Point the link at a directory that exists, or remove it (rm {tensorboard}) and the "
            "run writes a new tb/"
        )
    if tensorboard.exists() and not tensorboard.is_dir():
        return (
            f"{tensorboard} is a file where the run writes its TensorBoard logs (a directory); "
            f"move it aside (mv {tensorboard} {tensorboard}.aside) and run again"
        )
    for name in WRITTEN_FILES:
        path = run_dir / name
        link = None if name in READ_BACK else broken_link(path)
        if link:
            return (
                f"{path} is damaged: {link}. Remove the link (rm {path}): the run writes the "
                "file anew"
            )
        problem = not_a_file(path)
        if problem:
            fix = "restore the file from a copy" if name in READ_BACK else "the run writes it anew"
            return (
                f"{path} is not a file the run can write ({problem}); move it aside (mv {path} "
                f"{path}.aside), {fix}, and run again"
            )
    return None


def lock_run_dir(run_dir: Path) -> IO[str]:
    """Take the run directory's lock, or raise SetupError naming the PID that holds it.

    Keep the returned file open as long as the run uses the directory; closing it releases the
    lock.
    """
    problem = wrong_kind(run_dir)
    if problem:
        raise SetupError(problem)
    path = (run_dir / LOCK_NAME).resolve()
    earlier = _held.pop(path, None)
    if earlier is not None:
        # This process held it already (a run that raised, in a notebook or a Ray worker): flock
        # would refuse a second handle of our own, so the old one goes.
        earlier.close()
    handle = open_lock(run_dir, "a+")
    try:
        fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        handle.seek(0)
        holder = (handle.read().split() or ["unknown"])[-1]
        handle.close()
        raise in_use(run_dir, holder) from None
    handle.seek(0)
    handle.truncate()
    handle.write(f"{os.getpid()}\n")
    handle.flush()
    _held[path] = handle
    return handle


def not_writable(run_dir: Path, why: str) -> SetupError:
    """The refusal of a run directory the run cannot write its lock in (``why``: the OS's
    word)."""
    return SetupError(
        f"cannot write to the run directory {run_dir} ({why}): a run writes its lock, "
        "checkpoints and logs there. Make it writable (chmod -R u+w, for your own files), or "
        + copy_fix(run_dir, "simoun-train --resume")
    )


def foreign_lock(run_dir: Path) -> SetupError:
    """The refusal of a run directory whose lock file the user may not open (another user's,
    as a trainer run with sudo leaves it), with who holds it, if anyone: a lock no process
    holds is stale, and removing it is the fix (the directory being writable)."""
    path = run_dir / LOCK_NAME
    owner, mode = owner_and_mode(path)
    holders = lock_holders(path)
    seen = f"{path} is another user's (owner {owner}, mode {mode}), and cannot be opened"
    if holders:
        return SetupError(
            f"{seen}: the trainer of PID {', '.join(holders)} holds it; wait for it to end, or "
            "ask its owner to stop it"
        )
    return SetupError(
        f"{seen}; no process holds it (a trainer once run as that user, with sudo, left it): "
        f"remove it (rm {path}) and run again: the run writes its lock anew"
    )


def lock_holders(path: Path) -> list[str]:
    """The PIDs that hold a lock on the file ``path`` (Linux's /proc/locks), found without
    opening it; none where the file or /proc/locks cannot be looked at."""
    try:
        info = os.stat(path)
        lines = Path("/proc/locks").read_text().splitlines()
    except OSError:
        return []
    where = f"{os.major(info.st_dev):02x}:{os.minor(info.st_dev):02x}:{info.st_ino}"
    return [fields[4] for line in lines if len(fields := line.split()) > 5 and fields[5] == where]


def open_lock(run_dir: Path, mode: str) -> IO[str]:
    """The run directory's lock file opened in ``mode``, or SetupError: another user's lock
    file (:func:`foreign_lock`) in a directory the user may write, or a directory the run
    cannot write in (:func:`not_writable`)."""
    path = run_dir / LOCK_NAME
    try:
        return path.open(mode)
    except OSError as err:
        if err.errno in DENIED and os.access(run_dir, os.W_OK | os.X_OK):
            raise foreign_lock(run_dir) from None
        raise not_writable(run_dir, err.strerror) from None


def in_use(run_dir: Path, holder: str) -> SetupError:
    """The refusal of a run directory whose lock the trainer of PID ``holder`` holds."""
    return SetupError(
        f"{run_dir} is in use by another simoun-train (PID {holder}); two trainers in one "
        f"directory would overwrite each other's checkpoints. Wait for it to end, stop it "
        f"with `kill -TERM {holder}` (it checkpoints first), or pass another --run-dir"
    )


def refuse_live_lock(run_dir: Path) -> None:
    """SetupError when another process holds ``run_dir``'s lock, or the run could not write it,
    found without writing anything: a directory without a lock file has no live trainer."""
    path = run_dir / LOCK_NAME
    if not os.access(run_dir, os.W_OK | os.X_OK):
        read_only = os.statvfs(run_dir).f_flag & os.ST_RDONLY
        raise not_writable(run_dir, os.strerror(errno.EROFS if read_only else errno.EACCES))
    if not path.is_file():
        return
    open_lock(run_dir, "r").close()  # names another user's lock file or an unreadable one
    try:
        holder = lock_holder(run_dir)
    except OSError as err:
        raise not_writable(run_dir, err.strerror) from None
    if holder is not None:
        raise in_use(run_dir, holder)


def lock_holder(run_dir: Path) -> str | None:
    """The PID (as the lock file names it, its last word: the holder writes its own after any
    left there; or ``unknown``) of the process that holds ``run_dir``'s lock, None when none
    does; found without writing anything, so a command can ask before it starts a run there.
    OSError when the lock file cannot be opened."""
    path = run_dir / LOCK_NAME
    if not path.is_file():
        return None
    with path.open() as handle:
        try:
            fcntl.flock(handle, fcntl.LOCK_SH | fcntl.LOCK_NB)
        except BlockingIOError:
            return (handle.read().split() or ["unknown"])[-1]
        fcntl.flock(handle, fcntl.LOCK_UN)
    return None


def check_run_dir(run_dir: Path, *, resume: bool = False, overwrite: bool = False) -> None:
    """Every refusal of :func:`take_run_dir` for ``run_dir``, without writing anything there
    (no lock file, no file of an earlier attempt removed): trainers call it before they build
    anything, so that a refused run leaves the directory as it was."""
    refuse_held_here(run_dir)
    problem = wrong_kind(run_dir)
    if problem:
        raise SetupError(problem)
    refuse_live_lock(run_dir)
    if resume:
        require_checkpoint(run_dir)
    else:
        refuse_new_run_dir(run_dir, overwrite)


def claim_new_run_dir(run_dir: Path, overwrite: bool) -> None:
    """Make ``run_dir`` ready for a new run (:func:`refuse_new_run_dir`); with ``overwrite``
    the files of a crashed attempt are removed. Call it while holding the lock."""
    refuse_new_run_dir(run_dir, overwrite)
    if not (run_dir / TRAINER_FILES[0]).exists():
        return
    for name in TRAINER_FILES:
        (run_dir / name).unlink(missing_ok=True)
    shutil.rmtree(run_dir / TENSORBOARD_DIR, ignore_errors=True)


def refuse_new_run_dir(run_dir: Path, overwrite: bool) -> None:
    """SetupError saying what to do instead when ``run_dir`` cannot take a new run: a study's
    or sweep's own folder, whose files a run would mix with, or a directory that already
    holds a run (``config.json``), with ``--resume`` as the way on when it has a checkpoint
    and ``--overwrite`` when it has none (a study's run: never)."""
    if (kind := folder_kind(run_dir)) is not None:
        raise SetupError(
            f"--run-dir {run_dir} is {kind}; a new run there would write its files among its "
            "records. Pass a --run-dir outside it"
        )
    if not (run_dir / TRAINER_FILES[0]).exists():
        return
    if (run_dir / CHECKPOINT_NAME).exists():
        raise SetupError(
            f"{run_dir} already holds a run with a checkpoint; continue it with --resume "
            f"{run_dir}, or pass another --run-dir (--overwrite never deletes a checkpoint)"
        )
    if (study := study_of(run_dir)) is not None:
        raise study_run_refusal(run_dir, study)
    if not overwrite:
        raise SetupError(
            f"{run_dir} holds a run that stopped before its first checkpoint, so there is "
            "nothing to resume; pass --overwrite to start over in it, or another --run-dir"
        )


STUDY_RECORD = "study.json"
"""The record at the root of a simoun-study directory and of its archive."""
ARCHIVE_PHASES = ("tuning", "evaluation")
"""The folders of a study's runs, in its directory and its archive."""
TRIAL_RECORD = "trial.json"
"""What a run trained by simoun-sweep or simoun-study keeps beside its config."""


SWEEP_RECORD = "sweep.json"
"""The record at the root of a simoun-sweep directory."""


def folder_kind(path: Path) -> str | None:
    """What the folder ``path`` is when another command keeps it and it is no run directory:
    a study's (``study.json``) or a sweep's (``sweep.json``), with the command that reads it as
    a whole; None for any other folder. Commands that take a run directory name it so, rather
    than call it a run that stopped early."""
    if (path / STUDY_RECORD).is_file():
        return (
            f"a simoun-study directory or archive (it holds {STUDY_RECORD}), which `simoun-study "
            f"report SPEC --study-dir {path}` reports and `simoun-study run SPEC --study-dir DIR "
            "--resume` resumes"
        )
    if (path / SWEEP_RECORD).is_file():
        return (
            f"a simoun-sweep directory (it holds {SWEEP_RECORD}), which `simoun-report {path}` "
            f"reports and `simoun-sweep --resume --sweep-dir {path}` resumes"
        )
    return None


MINIGRID_SPEC = "spec.json"
"""A MiniGrid PPO study's spec, kept at the root of its archive."""
MINIGRID_RUN_KEYS = frozenset({"run", "seeds", "spec"})
"""Keys of a MiniGrid PPO study run's config.json (an SB3 PPO agent, no simoun config)."""
MINIGRID_COMMAND = "python -m simoun_lab.minigrid_study"


def json_keys(path: Path) -> set[str]:
    """The keys of the JSON object in ``path``; empty when it is missing, damaged or no object
    (the reader that needs the file names its problem)."""
    try:
        return set(read_json_object(path)) if path.is_file() else set()
    except Damaged:
        return set()


def minigrid_archive(path: Path) -> Path | None:
    """The MiniGrid PPO study archive ``path`` is or lies in: the nearest folder, ``path``
    itself first, whose ``spec.json`` has the study's ``tasks`` and ``arms``; None for none."""
    folder = Path(os.path.abspath(path))
    for where in (folder, *folder.parents):
        if {"tasks", "arms"} <= json_keys(where / MINIGRID_SPEC):
            return shown(where)
    return None


def minigrid_folder(path: Path) -> str | None:
    """What the folder ``path`` is when it is the MiniGrid PPO study's (SB3 PPO agents, which
    simoun-train neither trains nor reads): one of its runs (its config.json names the study's
    run, seeds and spec), its archive, or a folder of that archive; None otherwise."""
    archive = minigrid_archive(path)
    report = f"`{MINIGRID_COMMAND} report --archive {archive or 'ARCHIVE'}` reports"
    if MINIGRID_RUN_KEYS <= json_keys(path / CONFIG_NAME):
        return (
            f"a run of a MiniGrid PPO study (its {CONFIG_NAME} names the study's run, seeds and "
            f"spec): an SB3 PPO agent, which `{MINIGRID_COMMAND} run` trains and {report}"
        )
    if archive is None:
        return None
    study = f"a MiniGrid PPO study ({archive / MINIGRID_SPEC}), whose SB3 PPO runs {report}"
    if Path(os.path.abspath(path)) == archive.absolute():
        return f"the archive of {study}"
    return f"a folder of {archive}, the archive of {study}"


def not_a_simoun_run(path: Path, flag: str = "") -> SetupError | None:
    """The refusal of ``path`` given (as ``flag``, or as the command's run) where a
    simoun-train run goes, when it is the MiniGrid PPO study's (:func:`minigrid_folder`):
    without it, its missing checkpoint or its config's keys would be blamed. None otherwise."""
    kind = minigrid_folder(path)
    if kind is None:
        return None
    given = f"{flag} {path}" if flag else str(path)
    return SetupError(
        f"{given} is {kind}; it is not a simoun-train run, and simoun-train, simoun-eval and "
        "simoun-analyze work on simoun-train runs only (those of simoun-train, simoun-sweep and "
        "a SAC simoun-study): pass the directory of such a run"
    )


def study_of(run_dir: Path) -> Path | None:
    """The study folder (a simoun-study directory or archive) the run directory ``run_dir``
    lies in: the nearest folder above it with a study.json, or, for an archive copied without
    one, the folder above a tuning/ or evaluation/ folder when the run keeps a trial.json;
    None for a run of no study."""
    folder = Path(os.path.abspath(run_dir))
    for above in folder.parents:
        if (above / STUDY_RECORD).is_file():
            return shown(above)
    if (folder / TRIAL_RECORD).is_file():
        for above in folder.parents:
            if above.name in ARCHIVE_PHASES:
                return shown(above.parent)
    return None


def shown(path: Path) -> Path:
    """``path`` relative to the working directory when it lies in it, as a user types it."""
    relative = os.path.relpath(path)
    return Path(relative) if not relative.startswith("..") else path


def study_run_refusal(run_dir: Path, study: Path) -> SetupError:
    """The refusal of ``--resume`` (or a new run) in the run directory ``run_dir`` of the study
    in ``study``: a study archive keeps no checkpoints, and the run there is the study's record,
    so the way on is the study's own command or a new run elsewhere, never ``--overwrite``."""
    return SetupError(
        f"{run_dir} is a run of the study in {study} (its {STUDY_RECORD}), part of the study's "
        f"record, which must not be overwritten; a study archive keeps no {CHECKPOINT_NAME}, so "
        "there is nothing to resume there. Resume the study's own runs with `simoun-study run "
        "SPEC --study-dir STUDY_DIR --resume`, or train this setting anew with the flags in "
        f"{run_dir / CONFIG_NAME} and a new --run-dir outside {study}"
    )


def require_checkpoint(run_dir: Path) -> None:
    """Raise SetupError for ``--resume`` of a run that never wrote a checkpoint, or whose
    checkpoint is a link to nothing."""
    problem = broken_link(run_dir / CHECKPOINT_NAME)
    if problem:
        raise SetupError(
            f"{run_dir / CHECKPOINT_NAME} is damaged: {problem}. Restore the file it stands for "
            "from a copy (or point the link at it), or start a new run"
        )
    if (run_dir / TRAINER_FILES[0]).exists() and not (run_dir / CHECKPOINT_NAME).exists():
        if (study := study_of(run_dir)) is not None:
            raise study_run_refusal(run_dir, study)
        raise SetupError(
            f"{run_dir} has no {CHECKPOINT_NAME}: the run stopped before its first checkpoint, "
            "or the file was moved or deleted, so there is nothing to resume. Restore it from a "
            f"copy, or start the run over with its flags plus --run-dir {run_dir} --overwrite"
        )


def refuse_held_here(run_dir: Path) -> None:
    """A SetupError when a run this process created (or resumed) still holds ``run_dir``: a
    second run there would take its directory from under it."""
    held = _held.get((run_dir / LOCK_NAME).resolve())
    if held is not None and not held.closed:
        raise SetupError(
            f"the run directory {run_dir} is in use by a run created in this process "
            "(create_run or resume_run returned it, and it holds the directory until train(run) "
            "ends); train that run, close it with run.close(), or pass another run_dir"
        )


def take_run_dir(run_dir: Path, *, resume: bool = False, overwrite: bool = False) -> IO[str]:
    """Lock ``run_dir`` and check that it suits the run: a new one (:func:`claim_new_run_dir`,
    ``overwrite`` clearing a run that crashed before its first checkpoint) or a resumed one
    (it must have a checkpoint). On a refusal the lock is released and SetupError raised.

    Trainers call it once to fail fast, before building anything (closing what it returns),
    and again right before they write, keeping the lock until they are done.
    """
    refuse_held_here(run_dir)
    handle = lock_run_dir(run_dir)
    try:
        if resume:
            require_checkpoint(run_dir)
        else:
            claim_new_run_dir(run_dir, overwrite)
    except BaseException:
        handle.close()
        raise
    return handle
