"""The tenth reliability trial's cases: files (see reliability_trial.py).

Kept files as version control, notebooks, editors and other machines leave them, on every
command that reads them. Runs, sweeps and archives kept in git: a file left as a Git LFS
pointer by a clone without ``git lfs`` (checkpoint.pt, the replay, eval.csv, train.csv, a
trial's or an archived run's summary.json and eval.csv, a MiniGrid in-progress checkpoint), and
files with merge-conflict markers (config.json, eval.csv, train.csv, summary.json, sweep.json,
study.json, update_cost.json, the specs, archived runs' files). The folders and files other
tools add, which must be passed over: Jupyter's ``.ipynb_checkpoints/`` in runs, sweeps and
archives, an editor's ``sweep.json~`` and swap file, the ``NAME:Zone.Identifier`` files of a
copy from Windows to WSL. Kept JSON saved as UTF-16 by PowerShell on surfaces earlier trials did
not reach (sweep.json, a MiniGrid spec.json, update_cost.json, a run's config.json), an eval.csv
with the CR line endings of a spreadsheet's CSV for Macintosh, and run folders named in Latin-1
bytes (a zip made on Windows) or with commas and blanks. A run in training (its ``.lock`` held)
evaluated, reported and resumed a second time. A replay re-saved by numpy (compressed, an array
dropped), an older replay left beside the current one, checkpoint.pt a link to a versioned copy
in the run or re-saved in torch's legacy format. Runs, sweeps and archives packed to ``.zip`` or
``.tar.gz`` given where the folder goes; an archive's inner folder (a task's, a recipe's,
``report-1500s-wall/``) given as the archive; report outputs occupied (a link to nothing, a
file or folder where the report writes); a report written again over a report.md with the
user's notes; a spec with its tables reordered. The loaders (``load_run``, ``load_checkpoint``,
``read_csv``, ``SweepSpec.load``, the MiniGrid ``load_spec``) given LFS pointers, conflict
markers, UTF-16 and a legacy checkpoint. Permissions are not tried: the trial runs as root here,
where they do not bite.
"""

from __future__ import annotations

import fcntl
import json
import os
import shutil
import tarfile
import zipfile
from pathlib import Path

from reliability_eighth_files import (  # the eighth trial's case helpers, shared
    COSTS,
    MG_REPORT,
    MGT_RUN_ARGV,
    MGT_SELECT,
    STUDY_REPORT,
    STUDY_RESUME,
    add,
    costs,
    folder,
    mgt_light,
    on_run,
    removed,
    run_file,
    utf16,
)
from reliability_ninth_files import dangling, moved  # the ninth trial's case helpers, shared
from reliability_trial import (
    ARCH,
    DMC100K,
    EV_RUN,
    MG,
    MG_RUN,
    MGT,
    MGT_RUN,
    STUDIES,
    SW,
    SW_RUN,
    TU_RUN,
    api,
    edit_text,
    fifth,
    spoil,
)

LFS = (
    "version https://git-lfs.github.com/spec/v1\n"
    "oid sha256:4d7a214614ab2935c943f9e0ff69d22eadbb8f32b1258daaa5e2ca24d17e2393\n"
    "size 20864795\n"
)


def lfs_pointer(path: Path) -> None:
    """The file as a clone without ``git lfs`` leaves it: the pointer text in its place."""
    path.write_text(LFS)


def conflict(path: Path) -> None:
    """The file as ``git merge`` leaves a conflict in it: its middle line in both versions."""
    lines = path.read_text().splitlines()
    at = len(lines) // 2
    theirs = lines[at].replace("1", "2", 1)
    marked = ["<<<<<<< HEAD", lines[at], "=======", theirs, ">>>>>>> laptop"]
    path.write_text("\n".join([*lines[:at], *marked, *lines[at + 1 :]]) + "\n")


def in_progress_checkpoint(here: Path) -> Path:
    """An in-progress run's checkpoint.pt in the MiniGrid v2 tuning archive."""
    return next((here / "mgt").glob("*/*/s*/checkpoint.pt"))


def lfs_in_progress(here: Path) -> None:
    lfs_pointer(in_progress_checkpoint(here))


def notebook(*folders: str):
    """Work: the ``.ipynb_checkpoints/`` Jupyter leaves in each of ``folders``."""
    return lambda here: [add(f"{name}/.ipynb_checkpoints/plots-checkpoint.ipynb",
                             '{"cells": [], "nbformat": 4}\n')(here)
                         for name in folders]  # fmt: skip


_HELD: list = []  # the lock handles of the cases' "trainer in progress", open for the case's life


def training(here: Path) -> None:
    """The run's ``.lock`` held, as a trainer in progress holds it (its PID inside)."""
    handle = (here / "run/.lock").open("a+")
    handle.truncate(0)
    handle.write(f"{os.getpid()}\n")
    handle.flush()
    fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
    _HELD.append(handle)


def first_replay(here: Path) -> Path:
    return next((here / "run").glob("replay-*.npz"))


def lfs_replay(here: Path) -> None:
    lfs_pointer(first_replay(here))


def resave_replay(compressed: bool, drop: str | None = None):
    """Work: the replay loaded and saved again by numpy (``drop``: that array left out)."""

    def work(here: Path) -> None:
        import numpy as np

        path = first_replay(here)
        with np.load(path) as data:
            arrays = {key: data[key] for key in data.files if key != drop}
        save = np.savez_compressed if compressed else np.savez
        with path.open("wb") as f:
            save(f, **arrays)

    return work


def drop_first_array(here: Path) -> None:
    import numpy as np

    with np.load(first_replay(here)) as data:
        name = data.files[0]
    resave_replay(True, name)(here)


def older_replay(here: Path) -> None:
    """An older replay (``replay-20.npz``) left beside the current one."""
    shutil.copyfile(first_replay(here), here / "run/replay-20.npz")


def versioned_checkpoint(here: Path) -> None:
    """checkpoint.pt moved to ``checkpoints/ckpt-40.pt`` and linked back (relative)."""
    (here / "run/checkpoints").mkdir()
    shutil.move(here / "run/checkpoint.pt", here / "run/checkpoints/ckpt-40.pt")
    (here / "run/checkpoint.pt").symlink_to("checkpoints/ckpt-40.pt")


def legacy_checkpoint(path: Path) -> None:
    """checkpoint.pt re-saved in torch's legacy (non-zip) format, for an older torch."""
    import torch

    data = torch.load(path, weights_only=False)
    torch.save(data, path, _use_new_zipfile_serialization=False)


def zone_identifiers(here: Path) -> None:
    """``NAME:Zone.Identifier`` beside each file, as Windows' downloads appear under WSL."""
    for path in [p for p in (here / "run").iterdir() if p.is_file()]:
        path.with_name(f"{path.name}:Zone.Identifier").write_text("[ZoneTransfer]\r\nZoneId=3\r\n")


def runs_named(name: str):
    """Work: ``runs/<name>``: the run moved into a folder of runs under ``name``."""
    return moved("run", f"runs/{name}")


def non_utf8_runs(here: Path) -> None:
    """``runs/`` with a run folder whose name is Latin-1 bytes (a zip made on Windows)."""
    (here / "runs").mkdir()
    shutil.move(here / "run", os.fsdecode(bytes(here / "runs") + b"/r\xe9sultats-s1"))


def packed_tar(tree: str, name: str):
    """Work: ``tree`` packed into ``name`` (tar.gz) and removed."""

    def work(here: Path) -> None:
        with tarfile.open(here / name, "w:gz") as tar:
            tar.add(here / tree, arcname=tree)
        shutil.rmtree(here / tree)

    return work


def packed_zip(tree: str, name: str):
    """Work: ``tree`` packed into ``name`` (zip) and removed."""

    def work(here: Path) -> None:
        with zipfile.ZipFile(here / name, "w") as archive:
            for path in sorted((here / tree).rglob("*")):
                archive.write(path, path.relative_to(here))
        shutil.rmtree(here / tree)

    return work


def notes_in(name: str):
    """Work: a note typed into ``name`` (a report written earlier) by the user."""
    return lambda here: (here / name).write_text((here / name).read_text() + "\nMY NOTES\n")


def reorder_toml(text: str) -> str:
    """The spec's first two top-level ``[tables]`` swapped (same spec, another order)."""
    parts = text.split("\n[")
    if len(parts) > 2:
        parts[1], parts[2] = parts[2], parts[1]
    return "\n[".join(parts)


CR_ONLY = edit_text(lambda text: text.replace("\n", "\r"))
REINDENT = edit_text(lambda text: json.dumps(json.loads(text), indent=2, sort_keys=True) + "\n")
TASK = "MiniGrid-DoorKey-6x6-v0"
MGT_STUDY = ["run", "mgt/spec.json", "--study-dir", "s", "--archive", "mgt", "--resume"]

# runs kept in git: LFS pointers and merge conflicts, on every command that reads the file
GIT_RUN = [
    *on_run("eval train masks bias", "checkpoint.pt a Git LFS pointer (cloned without git lfs)",
            (run_file("checkpoint.pt", lfs_pointer),), "checkpoint.pt"),
    *on_run("train", "the replay a Git LFS pointer (cloned without git lfs)",
            (lfs_replay,), "replay"),
    *on_run("eval train bias masks", "config.json with merge-conflict markers (git merge)",
            (run_file("config.json", conflict),), "config.json"),
    *on_run("train report", "eval.csv with merge-conflict markers (git merge)",
            (run_file("eval.csv", conflict),), "eval.csv"),
    *on_run("train report", "eval.csv a Git LFS pointer (cloned without git lfs)",
            (run_file("eval.csv", lfs_pointer),), "eval.csv"),
    *on_run("report", "summary.json with merge-conflict markers (git merge)",
            (run_file("summary.json", conflict),), "summary.json"),
    *on_run("train", "train.csv with merge-conflict markers (git merge)",
            (run_file("train.csv", conflict),), "train.csv"),
    *on_run("train", "train.csv a Git LFS pointer (cloned without git lfs)",
            (run_file("train.csv", lfs_pointer),), "train.csv"),
    fifth("files", "eval", ["{run}", "--random-policy", "--episodes", "1", "--no-video"],
          "config.json", works=(run_file("config.json", conflict),),
          what="config.json with merge-conflict markers (git merge)"),
]  # fmt: skip

# a run in training, notebooks and editors beside it, numpy and torch re-saves, odd names
RUN_CASES = [
    *on_run("eval report", "the run in training (its .lock held by a live trainer)",
            (training,), "", True),
    *on_run("train", "the run in training (its .lock held by a live trainer), resumed again",
            (training,), ("PID", "lock", "process")),
    *on_run("train", "Zone.Identifier files beside each file (copied from Windows to WSL)",
            (zone_identifiers,), "", True),
    *on_run("report", "eval.csv with CR line endings (a spreadsheet's CSV for Macintosh)",
            (run_file("eval.csv", CR_ONLY),), "eval.csv", True),
    *on_run("report", "a .ipynb_checkpoints/ folder in the run (Jupyter)",
            (notebook("run"),), "", True),
    *on_run("train", "the replay re-saved compressed by numpy (np.savez_compressed)",
            (resave_replay(True),), "replay", True),
    *on_run("train", "the replay re-saved by numpy without its first array",
            (drop_first_array,), "replay"),
    *on_run("train", "an older replay-20.npz left beside the current replay",
            (older_replay,), "replay", True),
    *on_run("eval", "checkpoint.pt a relative link to checkpoints/ckpt-40.pt",
            (versioned_checkpoint,), "", True),
    *on_run("eval", "config.json saved as UTF-16 (PowerShell)",
            (run_file("config.json", utf16),), "config.json", True),
    fifth("files", "report", ["runs"], "", True, works=(non_utf8_runs,),
          what="a folder of runs, one named in Latin-1 bytes (a zip made on Windows)"),
    fifth("files", "report", ["runs"], "", True, works=(runs_named("lr=1e-3, seed 1"),),
          what="a folder of runs, one named with a comma and blanks"),
    fifth("files", "eval", ["run.zip", "--episodes", "1", "--no-video"], ("run.zip", "unzip"),
          works=(packed_zip("run", "run.zip"),), what="the run as a .zip file"),
    fifth("files", "train", ["--resume", "run.zip", "--total-env-steps", "60"],
          ("run.zip", "unzip"), works=(packed_zip("run", "run.zip"),),
          what="the run as a .zip file"),
    fifth("files", "report", ["run.zip"], ("run.zip", "unzip"),
          works=(packed_zip("run", "run.zip"),), what="the run as a .zip file"),
    fifth("files", "report", ["{run}"], "report.md", works=(dangling("report-run/report.md"),),
          what="report-run/report.md a link to another machine's file"),
    fifth("files", "report", ["{run}", "--out", "o"], "curves_env_steps",
          works=(folder("o/curves_env_steps.png"),),
          what="--out holding a folder named as the report's figure"),
]  # fmt: skip

SW_REPORT, SW_RESUME = ["sw"], ["--resume", "--sweep-dir", "sw"]
SW_ENV = "sw/base/simoun-PointReach-v0"
# a sweep directory: (command, argv, what, works, names[, valid])
SWEEP_CASES = [
    ("report", SW_REPORT, "sweep.json with merge-conflict markers",
     (SW, spoil("sw/sweep.json", conflict)), "sweep.json"),
    ("sweep", SW_RESUME, "sweep.json with merge-conflict markers",
     (SW, spoil("sw/sweep.json", conflict)), "sweep.json"),
    ("sweep", SW_RESUME, "sweep.json saved as UTF-16 (PowerShell)",
     (SW, spoil("sw/sweep.json", utf16)), "sweep.json", True),
    ("sweep", SW_RESUME, "a sweep.json~ and a .sweep.json.swp an editor left",
     (SW, add("sw/sweep.json~", "{"), add("sw/.sweep.json.swp", b"b0VIM 9.0\x00" + bytes(64))),
     "", True),
    ("report", SW_REPORT, ".ipynb_checkpoints/ in the sweep and its env folder",
     (SW, notebook("sw", SW_ENV)), "", True),
    ("report", SW_REPORT, "a finished trial's checkpoint.pt a Git LFS pointer",
     (SW, spoil(f"{SW_RUN}/checkpoint.pt", lfs_pointer)), "", True),
    ("report", SW_REPORT, "a finished trial's summary.json a Git LFS pointer",
     (SW, spoil(f"{SW_RUN}/summary.json", lfs_pointer)), "summary.json"),
    ("sweep", SW_RESUME, "a finished trial's eval.csv a Git LFS pointer",
     (SW, spoil(f"{SW_RUN}/eval.csv", lfs_pointer)), "eval.csv"),
    ("report", ["sw.tar.gz"], "the sweep as a .tar.gz", (SW, packed_tar("sw", "sw.tar.gz")),
     ("sw.tar.gz", "tar")),
    ("sweep", ["--resume", "--sweep-dir", "sw.tar.gz"], "the sweep as a .tar.gz",
     (SW, packed_tar("sw", "sw.tar.gz")), ("sw.tar.gz", "tar")),
    ("sweep", SW_RESUME, "a finished trial's config.json with merge-conflict markers",
     (SW, spoil(f"{SW_RUN}/config.json", conflict)), "config.json"),
]  # fmt: skip

# the dmc100k archive: (argv, what, works, names[, valid])
STUDY_CASES = [
    (STUDY_REPORT, "study.json with merge-conflict markers", (spoil("arch/study.json", conflict),),
     "study.json"),
    (STUDY_REPORT, "update_cost.json with merge-conflict markers",
     (add(COSTS, json.dumps(json.loads(costs()), indent=2)), spoil(COSTS, conflict)),
     "update_cost.json"),
    (STUDY_REPORT, "update_cost.json saved as UTF-16 (PowerShell)",
     (add(COSTS, costs()), spoil(COSTS, utf16)), "update_cost.json", True),
    (STUDY_REPORT, "the spec with merge-conflict markers", (spoil("dmc100k.toml", conflict),),
     "dmc100k.toml"),
    (STUDY_REPORT, "an evaluation run's eval.csv a Git LFS pointer",
     (spoil(f"{EV_RUN}/eval.csv", lfs_pointer),), "eval.csv"),
    (STUDY_RESUME, "a tuning run's eval.csv a Git LFS pointer, on run --resume",
     (spoil(f"{TU_RUN}/eval.csv", lfs_pointer),), "eval.csv"),
    (STUDY_REPORT, "an evaluation run's summary.json with merge-conflict markers",
     (spoil(f"{EV_RUN}/summary.json", REINDENT), spoil(f"{EV_RUN}/summary.json", conflict)),
     "summary.json"),
    (STUDY_REPORT, ".ipynb_checkpoints/ in the archive, evaluation/ and a recipe's folder",
     (notebook("arch", "arch/evaluation", "arch/evaluation/simoun"),), "", True),
    (STUDY_RESUME, "a tuning run's summary.json with merge-conflict markers, on run --resume",
     (spoil(f"{TU_RUN}/summary.json", REINDENT), spoil(f"{TU_RUN}/summary.json", conflict)),
     "summary.json"),
    (STUDY_REPORT, "an evaluation run's summary.json a Git LFS pointer",
     (spoil(f"{EV_RUN}/summary.json", lfs_pointer),), "summary.json"),
    (STUDY_REPORT, "an evaluation run's config.json with merge-conflict markers",
     (spoil(f"{EV_RUN}/config.json", conflict),), "config.json"),
    (STUDY_REPORT, "the spec's tables in another order (same spec)",
     (spoil("dmc100k.toml", edit_text(reorder_toml)),), "", True),
    (["report", "dmc100k.toml", "--study-dir", "arch/report-1500s-wall"],
     "the archive's report-1500s-wall/ given as --study-dir", (),
     ("report-1500s-wall", "study.json")),
    (["report", "dmc100k.toml", "--study-dir", "arch/tuning/simoun"],
     "a recipe's tuning folder given as --study-dir", (), ("arch/tuning/simoun", "study.json")),
    (["report", "dmc100k.toml", "--study-dir", "arch.tar.gz"], "the archive as a .tar.gz",
     (packed_tar("arch", "arch.tar.gz"),), ("arch.tar.gz", "tar")),
    (["run", "dmc100k.toml", "--study-dir", "s", "--archive", "arch.tar.gz", "--resume",
      "--allow-other-commit"], "the archive as a .tar.gz, on run --resume",
     (packed_tar("arch", "arch.tar.gz"),), ("arch.tar.gz", "tar")),
    (STUDY_REPORT, "report/scores.csv a link to another machine's file",
     (dangling("arch/report/scores.csv"),), "scores.csv"),
    (STUDY_REPORT, "report/tuning a file", (removed("arch/report/tuning"),
                                            add("arch/report/tuning")), "tuning"),
    (STUDY_REPORT, "report/report.md annotated by the user, reported again",
     (notes_in("arch/report/report.md"),), "", True),
]  # fmt: skip

MG_TASK = f"mg/{TASK}"
MG_SUCCESS = f"mg/report/{TASK}_success.png"
# the MiniGrid archives: (command, argv, what, works, names[, valid])
MINIGRID_CASES = [
    ("minigrid", MG_REPORT, "spec.json with merge-conflict markers",
     (MG, spoil("mg/spec.json", conflict)), "spec.json"),
    ("minigrid", MG_REPORT, "spec.json saved as UTF-16 (PowerShell)",
     (MG, spoil("mg/spec.json", utf16)), "spec.json", True),
    ("minigrid", MG_REPORT, "a run's summary.json with merge-conflict markers",
     (MG, spoil(f"{MG_RUN}/summary.json", REINDENT), spoil(f"{MG_RUN}/summary.json", conflict)),
     "summary.json"),
    ("study", ["report", "mg/spec.json", "--study-dir", "mg"],
     "a run's eval.csv with merge-conflict markers", (MG, spoil(f"{MG_RUN}/eval.csv", conflict)),
     "eval.csv"),
    ("minigrid", MG_REPORT, "a run's eval.csv a Git LFS pointer",
     (MG, spoil(f"{MG_RUN}/eval.csv", lfs_pointer)), "eval.csv"),
    ("minigrid", MGT_RUN_ARGV, "an in-progress run's checkpoint.pt a Git LFS pointer",
     (MGT, lfs_in_progress), "checkpoint.pt"),
    ("study", MGT_STUDY, "an in-progress run's checkpoint.pt a Git LFS pointer",
     (MGT, lfs_in_progress), "checkpoint.pt"),
    ("minigrid", MG_REPORT, ".ipynb_checkpoints/ in the archive and a task's folder",
     (MG, notebook("mg", MG_TASK)), "", True),
    ("minigrid", MG_REPORT, "a run's config.json with merge-conflict markers",
     (MG, spoil(f"{MG_RUN}/config.json", conflict)), "config.json"),
    ("minigrid", MGT_SELECT, "a run's eval.csv a Git LFS pointer",
     (mgt_light, spoil(f"{MGT_RUN}/eval.csv", lfs_pointer)), "eval.csv"),
    ("minigrid", MGT_SELECT, "a run's summary.json a Git LFS pointer",
     (mgt_light, spoil(f"{MGT_RUN}/summary.json", lfs_pointer)), "summary.json"),
    ("minigrid", MGT_RUN_ARGV, "a finished run's eval.csv a Git LFS pointer",
     (mgt_light, spoil(f"{MGT_RUN}/eval.csv", lfs_pointer)), "eval.csv"),
    ("minigrid", ["select", "--archive", "mgt.zip"], "the tuning archive as a .zip",
     (mgt_light, packed_zip("mgt", "mgt.zip")), ("mgt.zip", "unzip")),
    ("minigrid", ["report", "--archive", MG_TASK], "a task's folder given as --archive", (MG,),
     ("spec.json", TASK)),
    ("minigrid", ["report", "--archive", "mg.tar.gz"], "the archive as a .tar.gz",
     (MG, packed_tar("mg", "mg.tar.gz")), ("mg.tar.gz", "tar")),
    ("minigrid", MG_REPORT, "report/'s success figure a folder",
     (MG, removed(MG_SUCCESS), folder(MG_SUCCESS)), "success.png"),
    ("minigrid", MGT_SELECT, "selection.json a link to another machine's file",
     (mgt_light, dangling("mgt/selection.json")), "selection.json"),
    ("minigrid", MGT_RUN_ARGV, "a finished run's summary.json with merge-conflict markers",
     (mgt_light, spoil(f"{MGT_RUN}/summary.json", REINDENT),
      spoil(f"{MGT_RUN}/summary.json", conflict)), "summary.json"),
]  # fmt: skip

# the Python API's loaders, in a case directory beside the tiny run (../tiny)
RUN = "import shutil; from pathlib import Path; shutil.copytree('../tiny', 'run'); "
LOAD = RUN + "from simoun_agent.run.load import load_run; "
CSV = RUN + "from simoun_agent.run.logger import read_csv, read_log; "
CKPT = RUN + "from simoun_agent.run.checkpoint import load_checkpoint; "
SWEEP = (RUN + "import reliability_trial as t; t.sweep_dir(Path('.')); "
         "from simoun_lab.sweep.grid import SweepSpec; ")  # fmt: skip
MG_SPEC = "from pathlib import Path; from simoun_lab.minigrid_study.spec import load_spec; "
POINTER = f"{LFS!r}"
CONFLICT = "import reliability_tenth_files as f; "
API_CASES = [
    api(CKPT + f"p = Path('run/checkpoint.pt'); p.write_text({POINTER}); load_checkpoint(p)",
        "checkpoint.pt"),
    api(LOAD + f"Path('run/checkpoint.pt').write_text({POINTER}); load_run('run')",
        "checkpoint.pt"),
    api(LOAD + CONFLICT + "f.conflict(Path('run/config.json')); load_run('run')", "config.json"),
    api(CSV + CONFLICT + "p = Path('run/eval.csv'); f.conflict(p); read_csv(p)", "eval.csv"),
    api(CSV + f"p = Path('run/eval.csv'); p.write_text({POINTER}); read_csv(p)", "eval.csv"),
    api(SWEEP + CONFLICT + "f.conflict(Path('sw/sweep.json')); SweepSpec.load(Path('sw'))",
        "sweep.json"),
    api(MG_SPEC + "import shutil; shutil.copy(" + repr(str(STUDIES / "minigrid/spec.json"))
        + ", 's.json'); import reliability_tenth_files as f; f.conflict(Path('s.json')); "
        "load_spec(Path('s.json'))", "s.json"),
    api(MG_SPEC + "import shutil; shutil.copy(" + repr(str(STUDIES / "minigrid/spec.json"))
        + ", 's.json'); import reliability_tenth_files as f; f.utf16(Path('s.json')); "
        "load_spec(Path('s.json'))", "s.json", True),
    api(LOAD + "import torch, reliability_tenth_files as f; "
        "f.legacy_checkpoint(Path('run/checkpoint.pt')); "
        "r = load_run('run', device=torch.device('cpu')); assert r.env_step == 40", "", True),
]  # fmt: skip

CASES: list[dict] = [
    *GIT_RUN,
    *RUN_CASES,
    *(fifth("files", command, argv, names, *ok, works=works, what=what)
      for command, argv, what, works, names, *ok in SWEEP_CASES + MINIGRID_CASES),
    *(fifth("files", "study", argv, names, *ok, works=(ARCH, DMC100K, *works), what=what)
      for argv, what, works, names, *ok in STUDY_CASES),
    *({**case, "area": "files"} for case in API_CASES),
]  # fmt: skip
