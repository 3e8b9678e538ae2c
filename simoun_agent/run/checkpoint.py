"""Atomic checkpoints that make a resumed run continue exactly where it stopped.

A checkpoint is two files in the run directory: ``checkpoint.pt`` (agent networks and
optimizers, running maxima, counters, the RNG states of python, numpy, torch and the trainer,
and the config) and ``replay-<step>.npz`` (the replay, with its own RNG state), named in the
checkpoint. Each file is written to a temporary name in the same directory and renamed over
the old one (``os.replace`` is atomic on POSIX and Windows), the replay first: a crash at any
moment leaves the previous complete checkpoint in place, and a full disk too (:class:`NoSpace`).
A process killed while writing (``kill -9``) leaves its temporary behind; the next trainer of
the directory removes it (:func:`remove_leftovers`).
"""

from __future__ import annotations

import errno
import io
import random
import shutil
from pathlib import Path
from typing import Any

import numpy as np
import torch

from simoun_agent.config import SetupError
from simoun_agent.config.keys import config_sections
from simoun_agent.config.train import RESUMABLE_FIELDS
from simoun_agent.run.atomic import SPACE_ERRNOS, atomic_write, dead_temporaries
from simoun_agent.run.kept import binary_problem, broken_link, packed_problem, present
from simoun_agent.run.layout import CHECKPOINT_NAME, REPLAY_GLOB, replay_name
from simoun_agent.run.rundir import folder_kind, not_a_simoun_run, study_of
from simoun_agent.run.seeds import SEED_SCHEME

FORMAT = "simoun-checkpoint/1"
_REQUIRED = ("format", "config", "agent", "replay_file", "rng", "state")


class NoSpace(OSError):
    """A checkpoint did not fit (:data:`SPACE_ERRNOS`, or too little free space to start); the
    previous checkpoint is intact. ``str()`` is ``no space left on <dir>: N MB needed, ...``."""

    def __init__(self, directory: Path, needed: int, reason: str) -> None:
        message = f"no space left on {directory}: {_mb(needed)} needed, {reason}"
        super().__init__(errno.ENOSPC, message)
        self.directory = directory
        self.needed = needed
        """bytes the new checkpoint needs beside the old one"""

    def __str__(self) -> str:
        return self.strerror


def _mb(size: float) -> str:
    return f"{size / 1e6:.1f} MB"


def remove_leftovers(run_dir: Path, replay_file: str | None = None) -> list[Path]:
    """Remove what writers killed halfway left in ``run_dir`` and return it: the temporaries of
    :func:`atomic_write` whose process is dead (a live one may still be writing), and every
    ``replay-*.npz`` but ``replay_file`` (the one the checkpoint names; none for a new run), which
    a kill between a checkpoint's two renames leaves. Call it holding the run directory's lock."""
    removed = []
    for path in dead_temporaries(run_dir):
        path.unlink(missing_ok=True)
        removed.append(path)
    for path in run_dir.glob(REPLAY_GLOB):
        if path.name != replay_file:
            path.unlink(missing_ok=True)
            removed.append(path)
    return removed


def capture_rng() -> dict[str, Any]:
    """The global RNG states of python, numpy and torch (CPU and, when present, CUDA)."""
    state = {
        "python": random.getstate(),
        "numpy": np.random.get_state(),  # noqa: NPY002  (libraries may draw from it)
        "torch": torch.get_rng_state(),
    }
    if torch.cuda.is_available():
        state["torch_cuda"] = torch.cuda.get_rng_state_all()
    return state


def restore_rng(state: dict[str, Any]) -> None:
    """Inverse of :func:`capture_rng`."""
    random.setstate(state["python"])
    np.random.set_state(state["numpy"])  # noqa: NPY002
    torch.set_rng_state(state["torch"])
    if "torch_cuda" in state and torch.cuda.is_available():
        torch.cuda.set_rng_state_all(state["torch_cuda"])


def save_checkpoint(
    run_dir: Path, *, config: dict, agent: Any, replay: Any, state: dict[str, Any]
) -> Path:
    """Write the checkpoint of a run atomically; return the path of ``checkpoint.pt``.

    Raises :class:`NoSpace`, with nothing of the new checkpoint left behind and the previous one
    intact, when the free space is short of what it needs (checked first: a disk filled to the
    last byte fails other writers too) or a write fails for lack of space.

    Args:
        run_dir: the run directory.
        config: the run's config as a dict (``simoun_agent.config.to_dict``).
        agent: the SimounAgent (its ``state_dict()`` is saved).
        replay: the FrameReplay (``replay.save(path)``).
        state: the trainer's counters and its own RNG state, restored as given.
    """
    replay_path = run_dir / replay_name(state["env_step"])
    payload = {
        "format": FORMAT,
        "seed_scheme": SEED_SCHEME,
        "config": config,
        "agent": agent.state_dict(),
        "replay_file": replay_path.name,
        "replay_mark": replay_mark(replay),
        "rng": capture_rng(),
        "state": state,
    }
    # Serialized in memory first: torch.save's own file writer turns a full disk into an opaque
    # "RuntimeError: [enforce fail at inline_container.cc]"; a plain write raises OSError(ENOSPC).
    buffer = io.BytesIO()
    torch.save(payload, buffer)
    needed = _replay_file_bytes(replay) + buffer.getbuffer().nbytes
    free = shutil.disk_usage(run_dir).free
    if free < needed:
        raise NoSpace(run_dir, needed, f"{_mb(free)} free")
    replaced = replay_path.exists()  # a second checkpoint at the same step: the same replay
    path = run_dir / CHECKPOINT_NAME
    try:
        atomic_write(replay_path, replay.save)
        atomic_write(path, lambda tmp: tmp.write_bytes(buffer.getbuffer()))
    except OSError as err:
        if err.errno not in SPACE_ERRNOS:
            raise
        if not replaced:
            replay_path.unlink(missing_ok=True)
        limit = " (a file size limit: ulimit -f)" if err.errno == errno.EFBIG else ""
        raise NoSpace(run_dir, needed, f"a write failed: {err.strerror}{limit}") from None
    for old in run_dir.glob(REPLAY_GLOB):
        if old != replay_path:
            old.unlink(missing_ok=True)
    return path


def replay_mark(replay: Any) -> dict[str, Any]:
    """What tells the replay saved with a checkpoint from another run's of the same shapes:
    transitions written and the RNG state, seeded from the run's seed and moved by every batch
    drawn, so a replay of another seed, or of the same run at another step, differs."""
    return {"written": int(replay.written), "rng": replay.rng.bit_generator.state}


def check_replay_mark(payload: dict, replay: Any) -> None:
    """Refuse the replay file ``replay`` (loaded) when it is not the one saved with the
    checkpoint ``payload``: copied or linked from another run, or left from another step.
    Checkpoints written before the mark was kept are taken as they are."""
    mark = payload.get("replay_mark")
    if mark is None or mark == replay_mark(replay):
        return
    path = payload["replay_path"]
    if replay.written != mark["written"]:
        found = f"{replay.written} transitions in the file, {mark['written']} at the checkpoint"
    else:
        found = "its random state is another run's: another seed, or another point of a run"
    raise SetupError(
        f"{path} (the replay of the checkpoint) is not the one saved with "
        f"{path.parent / CHECKPOINT_NAME} ({found}), so it was copied or linked from another "
        "run. Restore this run's own replay and checkpoint from a copy, or start a new run"
    )


def _replay_file_bytes(replay: Any) -> int:
    """Size of the replay's ``.npz``: uncompressed, it is the stored part of its arrays."""
    return int(replay.nbytes * min(replay.written, replay.slots) / replay.slots)


def load_checkpoint(path: Path) -> dict[str, Any]:
    """Read a checkpoint written by :func:`save_checkpoint`.

    ``path`` is a run directory or a ``checkpoint.pt`` file. Raises ``SetupError`` naming the
    problem and the fix for a missing, corrupt or foreign file: a missing one is told apart
    from a packed copy beside it (``checkpoint.pt.gz``), a run of a study archive (which keeps
    no checkpoints) and a study's or a sweep's folder given in place of a run directory.
    """
    path = Path(path)
    for link in (path, path / CHECKPOINT_NAME):
        problem = broken_link(link)
        if problem:
            raise SetupError(
                f"{link} is damaged: {problem}. Restore the file it stands for from a copy "
                f"(or point the link at it), or start a new run"
            )
    if not path.exists() and (packed := packed_problem(path)):
        raise SetupError(f"{packed} and run the command again")
    if not path.exists():
        raise SetupError(
            f"{path} does not exist; pass a run directory that simoun-train created, or its "
            f"{CHECKPOINT_NAME}"
        )
    if foreign := not_a_simoun_run(path if path.is_dir() else path.parent):
        raise foreign
    if path.is_dir():
        if not present(path / CHECKPOINT_NAME) and (kind := folder_kind(path)) is not None:
            raise SetupError(
                f"{path} is {kind}, not a run directory; pass the directory of one of its runs "
                f"that holds {CHECKPOINT_NAME} (a study archive keeps none: pass the study "
                "directory's run)"
            )
        path = path / CHECKPOINT_NAME
    elif path.suffix != ".pt":
        # not a checkpoint's name: say so rather than call the file corrupt and advise deleting it
        raise SetupError(
            f"{path} is a file that is not a checkpoint (.pt); pass a run directory that "
            f"simoun-train created, or its {CHECKPOINT_NAME}"
        )
    if path.exists() and not path.is_file():
        raise SetupError(
            f"{path} is not a file, so it holds no checkpoint; move it aside (mv {path} "
            f"{path}.damaged) and restore {CHECKPOINT_NAME} from a copy, or start a new run"
        )
    if packed := packed_problem(path):
        raise SetupError(f"{packed} and run the command again")
    if not path.is_file() and (study := study_of(path.parent)) is not None:
        raise SetupError(
            f"no checkpoint at {path}: {path.parent} is a run of the study in {study}, and a "
            "study archive keeps no checkpoints (only the runs' logs and records). Pass the run "
            "of the study directory, which keeps its checkpoint, or read this run's eval.csv "
            "and summary.json"
        )
    if not path.is_file():
        raise SetupError(
            f"no checkpoint at {path}: the run stopped before its first checkpoint, or the path "
            "is wrong. Pass a run directory that holds checkpoint.pt, or start a new run."
        )
    try:
        # Checkpoints hold numpy RNG states and python objects, so they are full pickles:
        # load only files you wrote yourself.
        payload = torch.load(path, map_location="cpu", weights_only=False)
    except Exception as err:  # damaged bytes fail anywhere in torch.load (zeros: a KeyError)
        problem = binary_problem(path)
        if problem.startswith("it cannot be read"):
            problem += f": {type(err).__name__}: {str(err).split('. ')[0]}"
        raise SetupError(
            f"checkpoint {path} is corrupt or incomplete: {problem}. Restore a good copy, or "
            "delete it and start a new run."
        ) from None
    if not isinstance(payload, dict) or payload.get("format") != FORMAT:
        found = payload.get("format") if isinstance(payload, dict) else type(payload).__name__
        raise SetupError(
            f"{path} is not a simoun checkpoint (format {found!r}, expected {FORMAT!r}); "
            "pass the checkpoint.pt that simoun-train wrote."
        )
    missing = [key for key in _REQUIRED if key not in payload]
    if missing:
        raise SetupError(f"checkpoint {path} lacks {missing}; it is incomplete, start a new run.")
    replay_path = path.parent / payload["replay_file"]
    payload["replay_path"] = replay_path
    return payload


def config_differences(saved: dict, current: dict, prefix: str = "") -> list[str]:
    """``["agent.lr: 0.001 in the checkpoint, 0.0003 now", ...]`` ignoring resumable fields."""
    differences = []
    for key in sorted(set(saved) | set(current)):
        name = prefix + key
        if not prefix and key in (*RESUMABLE_FIELDS, "run_dir"):
            continue
        old, new = saved.get(key, "<missing>"), current.get(key, "<missing>")
        if isinstance(old, dict) and isinstance(new, dict) and name + "." in config_sections():
            differences += config_differences(old, new, prefix=name + ".")
        elif old != new:
            differences.append(f"{name}: {old!r} in the checkpoint, {new!r} now")
    return differences


def check_seed_scheme(payload: dict, path: Path) -> None:
    """Refuse to continue a run whose episodes were seeded another way (runs started before
    :mod:`simoun_agent.run.seeds`): its training and evaluation episodes would change halfway,
    so its curve would no longer compare with itself. ``simoun-eval`` still reads it."""
    found = payload.get("seed_scheme")
    if found != SEED_SCHEME:
        was = (
            "before seed streams, when training episode i reset with seed + i and evaluation "
            "episode i with seed + 1000000 + i"
            if found is None
            else f"under seed scheme {found!r}"
        )
        raise SetupError(
            f"{path} was started {was}; this version seeds episodes from SeedSequence streams "
            f"({SEED_SCHEME}) and cannot continue it exactly. Start a new run, or resume it "
            "with the simoun version that started it."
        )


def check_config(payload: dict, current: dict, path: Path, saved: Path | None = None) -> None:
    """Refuse a checkpoint written under another config (resumable fields may differ);
    ``saved``: ``current`` is that file's config, before any override, so the file is named."""
    differences = config_differences(payload["config"], current)
    if differences:
        listed = "; ".join(differences)
        if saved is not None:
            raise SetupError(
                f"{saved} does not hold the config of the checkpoint in {path} ({listed}): the "
                "file was edited or damaged, or the checkpoint copied from another run. Restore "
                "them from a copy, or start a new run in another directory."
            )
        raise SetupError(
            f"checkpoint {path} comes from another config ({listed}). Resume without those "
            "overrides, or start a new run in another directory."
        )
