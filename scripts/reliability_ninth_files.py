"""The ninth reliability trial's cases: files (see reliability_trial.py).

Kept files as a power loss, a file manager, a mix-up or a hand edit leaves them, on surfaces
earlier trials did not reach. Files whose last block a power loss left zero-filled (NUL bytes
after the text) in a run (config.json, eval.csv, train.csv, summary.json), a sweep
(sweep.json, a trial's eval.csv), a study archive (study.json, update_cost.json, a run's
eval.csv, trial.json) and the MiniGrid archives; the files a file manager adds (``.DS_Store``,
AppleDouble ``._*`` files, an unzip's ``__MACOSX/``); one kept file copied over another (the
replay over checkpoint.pt, train.csv over eval.csv, config.json over summary.json, sweep.json
or a MiniGrid spec.json, selection.json over study.json); a checkpoint re-saved with its
weights only or gzipped in place; hand edits that contradict the checkpoint (num_filters,
image_size, the recipe, the env's version) or the machine (a CUDA device for the analyses);
spreadsheet exports (every field quoted) and an infinite return; update_cost.json with a bool,
a negative or a misspelled ratio, as a folder or a link to nothing, and on ``run --resume``.
Output paths occupied by a file, a link to nothing or a file above them (``--out`` of
simoun-eval, simoun-report and simoun-analyze, ``eval-40-random`` of ``--random-policy``). A
kept folder given to the wrong command (a study archive to simoun-report and simoun-sweep
``--resume``, an archived run without a checkpoint to simoun-eval, ``--resume`` and
``simoun-analyze masks``, the archive's ``report/`` or ``evaluation/`` as ``--study-dir``), a
sweep moved to another folder, an archive reached through a link. The loaders ``load_run``,
``load_checkpoint``, ``read_csv`` (its ``columns`` too), ``read_log`` and ``SweepSpec.load``
given such files. Permissions are not tried: the trial runs as root here, where they do not
bite.
"""

from __future__ import annotations

import gzip
import json
import shutil
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
)
from reliability_trial import (
    ARCH,
    DMC100K,
    EV_RUN,
    FILE_COMMANDS,
    MG,
    MG_RUN,
    MGT_RUN,
    STUDIES,
    SW,
    SW_RUN,
    TU_RUN,
    api,
    bom,
    edit_json,
    edit_text,
    fifth,
    spoil,
)

EVAL, RESUME, REPORT, MASKS = (FILE_COMMANDS[c] for c in ("eval", "train", "report", "analyze"))


def dangling(name: str):
    """Work: ``name`` a symbolic link to a path of another machine (its file removed first)."""

    def work(here: Path) -> None:
        path = here / name
        if path.exists() or path.is_symlink():
            path.unlink()
        path.parent.mkdir(parents=True, exist_ok=True)
        path.symlink_to("/mnt/old-disk/" + path.name)

    return work


def copied_over(source: str, target: str):
    """Work: the file ``source`` copied over ``target`` (a mix-up of ``cp``'s arguments)."""
    return lambda here: shutil.copyfile(here / source, here / target)


def moved(source: str, target: str):
    """Work: ``source`` moved to ``target`` (its parents made)."""

    def work(here: Path) -> None:
        (here / target).parent.mkdir(parents=True, exist_ok=True)
        shutil.move(here / source, here / target)

    return work


def linked(link: str, target: str):
    """Work: ``link`` a symbolic link to the case's ``target``."""
    return lambda here: (here / link).symlink_to(here / target)


def zero_tail(path: Path) -> None:
    """The file's last block zero-filled, as a power loss leaves a file being appended to."""
    path.write_bytes(path.read_bytes() + bytes(512))


DS_STORE = b"\x00\x00\x00\x01Bud1" + bytes(200)
APPLE_DOUBLE = b"\x00\x05\x16\x07\x00\x02\x00\x00Mac OS X        " + bytes(64)


def finder(*folders: str):
    """Work: the ``.DS_Store`` a macOS file manager leaves in each of ``folders``."""
    return lambda here: [add(f"{name}/.DS_Store", DS_STORE)(here) for name in folders]


def first_replay(here: Path) -> Path:
    return next((here / "run").glob("replay-*.npz"))


def replay_as_checkpoint(here: Path) -> None:
    """The replay copied over checkpoint.pt (``cp replay-40.npz checkpoint.pt``)."""
    shutil.copyfile(first_replay(here), here / "run/checkpoint.pt")


def checkpoint_as_replay(here: Path) -> None:
    """checkpoint.pt copied over the replay."""
    shutil.copyfile(here / "run/checkpoint.pt", first_replay(here))


def weights_only(path: Path) -> None:
    """checkpoint.pt re-saved with the agent's weights only (to share a smaller file)."""
    import torch

    torch.save(torch.load(path, weights_only=False)["agent"], path)


def gzip_checkpoint(here: Path) -> None:
    """checkpoint.pt gzipped in place (``gzip checkpoint.pt``: only checkpoint.pt.gz is left)."""
    path = here / "run/checkpoint.pt"
    with gzip.open(f"{path}.gz", "wb") as f:
        f.write(path.read_bytes())
    path.unlink()


def quoted(text: str) -> str:
    """Every field in double quotes, as spreadsheets export CSV."""
    return "".join(",".join(f'"{c}"' for c in line.split(",")) + "\n" for line in text.splitlines())


def agent_set(**values):
    return edit_json(lambda data: data["agent"].update(values))


def config_set(**values):
    return edit_json(lambda data: data.update(values))


def last_return(value: str):
    """eval.csv with the last row's return_mean ``value``."""

    def change(text: str) -> str:
        lines = text.splitlines()
        cells = lines[-1].split(",")
        cells[1] = value
        return "\n".join([*lines[:-1], ",".join(cells)]) + "\n"

    return edit_text(change)


def runs_folder(here: Path) -> None:
    """``runs/``: the run unzipped with the ``__MACOSX/`` folder of a zip made on a Mac."""
    shutil.move(here / "run", here / "runs/tiny")
    add("runs/__MACOSX/tiny/._config.json", APPLE_DOUBLE)(here)
    add("runs/__MACOSX/tiny/._eval.csv", APPLE_DOUBLE)(here)


EVAL_OUT = ["{run}", "--episodes", "1", "--no-video", "--out"]
CRLF = edit_text(lambda text: text.replace("\n", "\r\n"))

# a run's kept files: a power loss's zero-filled tail, file-manager files, mix-ups, hand edits
RUN_CASES = [
    *on_run("eval train bias", "config.json's last block zero-filled (a power loss)",
            (run_file("config.json", zero_tail),), "config.json"),
    *on_run("train report", "eval.csv's last block zero-filled (a power loss)",
            (run_file("eval.csv", zero_tail),), "eval.csv"),
    *on_run("train", "train.csv's last block zero-filled (a power loss)",
            (run_file("train.csv", zero_tail),), "train.csv"),
    *on_run("report", "summary.json's last block zero-filled (a power loss)",
            (run_file("summary.json", zero_tail),), "summary.json"),
    *on_run("report", "a .DS_Store and an AppleDouble ._config.json in the run",
            (add("run/.DS_Store", DS_STORE), add("run/._config.json", APPLE_DOUBLE)), "", True),
    *on_run("eval", "the replay copied over checkpoint.pt", (replay_as_checkpoint,),
            "checkpoint.pt"),
    *on_run("train", "checkpoint.pt copied over the replay", (checkpoint_as_replay,), "replay"),
    *on_run("train report", "train.csv copied over eval.csv",
            (copied_over("run/train.csv", "run/eval.csv"),), "eval.csv"),
    *on_run("report", "config.json copied over summary.json",
            (copied_over("run/config.json", "run/summary.json"),), "summary.json"),
    *on_run("eval train", "checkpoint.pt re-saved with the agent's weights only",
            (run_file("checkpoint.pt", weights_only),), "checkpoint.pt"),
    *on_run("eval", "checkpoint.pt gzipped in place (only checkpoint.pt.gz)", (gzip_checkpoint,),
            "checkpoint"),
    *on_run("eval masks", "config.json's agent.num_filters changed by hand (4 to 8)",
            (run_file("config.json", agent_set(num_filters=8)),),
            ("num_filters", "config.json")),
    *on_run("eval bias", "config.json's image_size changed by hand (32 to 48)",
            (run_file("config.json", config_set(image_size=48)),), ("image_size", "config.json")),
    *on_run("train", "config.json's agent.recipe set to drq by hand",
            (run_file("config.json", agent_set(recipe="drq")),), ("recipe", "config.json")),
    *on_run("train", "config.json's agent.lr NaN (json.dumps of a float('nan'))",
            (run_file("config.json", agent_set(lr=float("nan"))),), "lr"),
    *on_run("eval", "config.json's env bumped by hand to simoun/PointReach-v1",
            (run_file("config.json", config_set(env="simoun/PointReach-v1")),), "PointReach-v1"),
    *on_run("bias", "config.json's device cuda:0 (trained on a GPU), analysed without one",
            (run_file("config.json", config_set(device="cuda:0")),), ("cuda", "device"), True),
    *on_run("report", "summary.json without final_eval (an older version)",
            (run_file("summary.json", edit_json(lambda d: d.pop("final_eval"))),),
            "summary.json", True),
    *on_run("report", "eval.csv with every field quoted (a spreadsheet's export)",
            (run_file("eval.csv", edit_text(quoted)),), "eval.csv", True),
    *on_run("report", "eval.csv with the last return inf", (run_file("eval.csv",
                                                                     last_return("inf")),),
            ("eval.csv", "inf")),
]  # fmt: skip

# output paths occupied, and kept folders given to the wrong command
OUTPUT_CASES = [
    fifth("files", "eval", ["{run}", "--random-policy", "--episodes", "1", "--no-video"],
          "eval-40-random", works=(add("run/eval-40-random", "notes\n"),),
          what="eval-40-random a file (notes kept under that name)"),
    fifth("files", "eval", [*EVAL_OUT, "o"], "", True, works=(folder("o"),),
          what="--out an existing empty folder"),
    fifth("files", "eval", [*EVAL_OUT, "notes.txt/eval"], ("notes.txt", "--out"),
          works=(add("notes.txt"),), what="--out below a file"),
    fifth("files", "report", ["{run}", "--out", "notes.txt"], ("notes.txt", "--out"),
          works=(add("notes.txt"),), what="--out an existing file"),
    fifth("files", "report", ["{run}", "--out", "out"], ("old-disk", "--out", "out"),
          works=(dangling("out"),), what="--out a symbolic link to another machine's folder"),
    fifth("files", "analyze", ["masks", "{run}", "--steps", "1", "--out", "notes.txt"],
          ("notes.txt", "--out"), works=(add("notes.txt"),), what="--out an existing file"),
    fifth("files", "report", ["runs"], "", True, works=(runs_folder,),
          what="a folder of runs unzipped with its __MACOSX/ folder"),
    fifth("files", "report", ["arch"], ("simoun-study", "study.json"), True, works=(ARCH,),
          what="a study archive given to simoun-report"),
    fifth("files", "report", ["mg"], ("minigrid_study", "MiniGrid", "spec.json"), works=(MG,),
          what="the MiniGrid archive given to simoun-report"),
    fifth("files", "eval", [EV_RUN, "--episodes", "1", "--no-video"], "checkpoint",
          works=(ARCH,), what="an archived evaluation run (no checkpoint) given to simoun-eval"),
    fifth("files", "analyze", ["masks", EV_RUN, "--steps", "1"], "checkpoint", works=(ARCH,),
          what="an archived evaluation run (no checkpoint) given to masks"),
    fifth("files", "train", ["--resume", TU_RUN, "--total-env-steps", "60"], "checkpoint",
          works=(ARCH,), what="an archived tuning run (no checkpoint) given to --resume"),
]  # fmt: skip

SW_REPORT, SW_RESUME = ["sw"], ["--resume", "--sweep-dir", "sw"]
# a sweep directory: (command, argv, what, works, names[, valid])
SWEEP_CASES = [
    ("sweep", SW_RESUME, "sweep.json reindented with its keys sorted (an editor's format)",
     (SW, spoil("sw/sweep.json", edit_text(lambda t: json.dumps(json.loads(t), indent=4,
                                                                 sort_keys=True)))),
     "", True),
    ("report", SW_REPORT, "sweep.json's last block zero-filled", (SW, spoil("sw/sweep.json",
                                                                          zero_tail)),
     "sweep.json"),
    ("sweep", SW_RESUME, "sweep.json's last block zero-filled", (SW, spoil("sw/sweep.json",
                                                                         zero_tail)),
     "sweep.json"),
    ("sweep", SW_RESUME, "a .DS_Store in the sweep and in its trial",
     (SW, finder("sw", "sw/base", SW_RUN)), "", True),
    ("report", ["moved/sw2"], "the sweep moved to another folder",
     (SW, moved("sw", "moved/sw2")), "", True),
    ("sweep", ["--resume", "--sweep-dir", "moved/sw2"], "the sweep moved to another folder",
     (SW, moved("sw", "moved/sw2")), "", True),
    ("report", SW_REPORT, "the trial s1's config.json of seed 2 (copied from a neighbour)",
     (SW, spoil(f"{SW_RUN}/config.json", config_set(seed=2))), ("seed", "s1")),
    ("sweep", SW_RESUME, "the trial s1's config.json of seed 2 (copied from a neighbour)",
     (SW, spoil(f"{SW_RUN}/config.json", config_set(seed=2))), ("seed", "s1")),
    ("sweep", ["--resume", "--sweep-dir", "{run}"], "a run directory given as --sweep-dir",
     (), "sweep.json"),
    ("sweep", ["--resume", "--sweep-dir", "arch"], "a study archive given as --sweep-dir",
     (ARCH,), ("sweep.json", "simoun-study")),
    ("report", SW_REPORT, "the trial's config.json copied over sweep.json",
     (SW, copied_over(f"{SW_RUN}/config.json", "sw/sweep.json")), "sweep.json"),
    ("sweep", SW_RESUME, "the trial's config.json copied over sweep.json",
     (SW, copied_over(f"{SW_RUN}/config.json", "sw/sweep.json")), "sweep.json"),
    ("sweep", SW_RESUME, "the trial's summary.json copied over its config.json",
     (SW, copied_over(f"{SW_RUN}/summary.json", f"{SW_RUN}/config.json")), "config.json"),
    ("report", SW_REPORT, "a trial's eval.csv with its last block zero-filled",
     (SW, spoil(f"{SW_RUN}/eval.csv", zero_tail)), "eval.csv"),
]  # fmt: skip


def cost_file(**change):
    return add(COSTS, costs(**change))


# the dmc100k archive: (argv, what, works, names[, valid])
STUDY_CASES = [
    (STUDY_REPORT, "update_cost.json with simoun's ratio true (a bool)",
     (cost_file(ratio={"simoun": True, "drq": 1.0}),), ("ratio", "simoun")),
    (STUDY_REPORT, "update_cost.json with simoun's ratio negative (-2.1)",
     (cost_file(ratio={"simoun": -2.1, "drq": 1.0}),), ("ratio", "-2.1")),
    (STUDY_REPORT, "update_cost.json with simoun's ratio keyed by its tuning folder",
     (cost_file(ratio={"simoun/agent.n_step=3": 2.1, "drq": 1.0},
                ms_per_update={"simoun/agent.n_step=3": 21.0, "drq": 10.0}),),
     "simoun/agent.n_step=3"),
    (STUDY_REPORT, "update_cost.json saved with a byte-order mark",
     (cost_file(), spoil(COSTS, bom)), "", True),
    (STUDY_REPORT, "update_cost.json without drq's ms_per_update",
     (cost_file(ms_per_update={"simoun": 21.0}),), ("ms_per_update", "drq")),
    (STUDY_REPORT, "update_cost.json a folder", (folder(COSTS),), "update_cost.json"),
    (STUDY_REPORT, "update_cost.json a symbolic link to another machine's",
     (dangling(COSTS),), "update_cost.json"),
    (STUDY_REPORT, "update_cost.json's last block zero-filled",
     (cost_file(), spoil(COSTS, zero_tail)), "update_cost.json"),
    (STUDY_RESUME, "update_cost.json in the study directory cut in half, on run --resume",
     (add("s/update_cost.json", '{"baseline": "drq", "ra'),), "update_cost.json"),
    (STUDY_REPORT, "study.json's last block zero-filled", (spoil("arch/study.json", zero_tail),),
     "study.json"),
    (STUDY_REPORT, "selection.json copied over study.json",
     (copied_over("arch/selection.json", "arch/study.json"),), "study.json"),
    (STUDY_REPORT, "an evaluation run's summary.json copied over its config.json",
     (copied_over(f"{EV_RUN}/summary.json", f"{EV_RUN}/config.json"),), "config.json"),
    (STUDY_REPORT, "an evaluation run's eval.csv with its last block zero-filled",
     (spoil(f"{EV_RUN}/eval.csv", zero_tail),), "eval.csv"),
    (STUDY_REPORT, "a .DS_Store in the archive, its phases and a recipe's folder",
     (finder("arch", "arch/evaluation", "arch/evaluation/simoun", "arch/tuning"),), "", True),
    (STUDY_RESUME, "a .DS_Store in the archive's phases and a recipe's folder",
     (finder("arch/evaluation", "arch/evaluation/simoun", "arch/tuning"),), "", True),
    (["report", "dmc100k.toml", "--study-dir", "arch/report"],
     "the archive's report/ given as --study-dir", (), ("arch/report", "study.json")),
    (["report", "dmc100k.toml", "--study-dir", "arch/evaluation"],
     "the archive's evaluation/ given as --study-dir", (), ("arch/evaluation", "study.json")),
    (STUDY_REPORT, "the spec with CRLF line endings (edited on Windows)",
     (spoil("dmc100k.toml", CRLF),), "", True),
]  # fmt: skip


MG_TASK = "mg/MiniGrid-DoorKey-6x6-v0"
# the MiniGrid archives: (command, argv, what, works, names[, valid])
MINIGRID_CASES = [
    ("minigrid", MG_REPORT, "a run's eval.csv with its last block zero-filled",
     (MG, spoil(f"{MG_RUN}/eval.csv", zero_tail)), "eval.csv"),
    ("study", ["report", "mg/spec.json", "--study-dir", "mg"],
     "a run's eval.csv with its last block zero-filled",
     (MG, spoil(f"{MG_RUN}/eval.csv", zero_tail)), "eval.csv"),
    ("minigrid", MG_REPORT, "a .DS_Store in a task's and an arm's folder",
     (MG, finder(MG_TASK, f"{MG_TASK}/ppo")), "", True),
    ("minigrid", MG_REPORT, "probe/ deleted to save space", (MG, removed("mg/probe")), "probe",
     True),
    ("minigrid", MGT_SELECT, "an earlier selection.json cut short",
     (mgt_light, add("mgt/selection.json", '{"rule": "auc", "recip')), "selection.json", True),
    ("minigrid", MGT_SELECT, "a run's summary.json with its last block zero-filled",
     (mgt_light, spoil(f"{MGT_RUN}/summary.json", zero_tail)), "summary.json"),
    ("minigrid", MGT_SELECT, "a run's config.json copied over its summary.json",
     (mgt_light, copied_over(f"{MGT_RUN}/config.json", f"{MGT_RUN}/summary.json")),
     "summary.json"),
    ("minigrid", MG_REPORT, "a run's config.json copied over spec.json",
     (MG, copied_over(f"{MG_RUN}/config.json", "mg/spec.json")), "spec.json"),
    ("minigrid", MG_REPORT, "report/report.md a symbolic link to another machine's",
     (MG, dangling("mg/report/report.md")), "report.md"),
    ("minigrid", ["report", "--archive", "mg-link"], "the archive reached through a link",
     (MG, linked("mg-link", "mg")), "", True),
    ("minigrid", MGT_RUN_ARGV, "a finished run's eval.csv with its last block zero-filled",
     (mgt_light, spoil(f"{MGT_RUN}/eval.csv", zero_tail)), "eval.csv"),
]  # fmt: skip

# the Python API's loaders, in a case directory beside the tiny run (../tiny)
RUN = "import shutil; from pathlib import Path; shutil.copytree('../tiny', 'run'); "
LOAD = RUN + "from simoun_agent.run.load import load_run; "
CSV = RUN + "from simoun_agent.run.logger import read_csv, read_log; "
CKPT = RUN + "from simoun_agent.run.checkpoint import load_checkpoint; "
SWEEP = (RUN + "import reliability_trial as t; t.sweep_dir(Path('.')); "
         "from simoun_lab.sweep.grid import SweepSpec; ")  # fmt: skip
ZERO = "p = Path('run/{}'); p.write_bytes(p.read_bytes() + bytes(512)); "
QUOTE = ("p = Path('run/eval.csv'); p.write_text(''.join(','.join(chr(34) + c + chr(34) for c "
         "in line.split(',')) + chr(10) for line in p.read_text().splitlines())); ")  # fmt: skip
ARCHIVED = str(STUDIES / "dmc100k" / EV_RUN.removeprefix("arch/"))
MG_EVAL = str(STUDIES / "minigrid" / MG_RUN.removeprefix("mg/") / "eval.csv")
API_CASES = [
    api(LOAD + ZERO.format("config.json") + "load_run('run')", "config.json"),
    api(LOAD + "import torch; r = load_run(Path('run'), device=torch.device('cpu')); "
        "assert r.env_step == 40", "", True),
    api(LOAD + f"load_run({ARCHIVED!r})", "checkpoint"),
    api(CSV + QUOTE + "rows = read_csv(p); assert rows[-1]['env_step'] == 40", "eval.csv", True),
    api(CSV + "open('e.csv', 'w').close(); assert read_csv('e.csv') == []", "e.csv", True),
    api(CSV + ZERO.format("train.csv") + "read_log(p)", "train.csv"),
    api(CSV + "read_csv('run/eval.csv', columns=('success_rate',))", "success_rate"),
    api(CSV + "read_csv('run/eval.csv', columns='return_mean')", "columns"),
    api(CSV + f"rows = read_csv({MG_EVAL!r}); assert rows[-1]['success_rate'] >= 0", "eval.csv",
        True),
    api(CKPT + "import torch; p = Path('run/checkpoint.pt'); torch.save(torch.load(p, "
        "weights_only=False)['agent'], p); load_checkpoint(p)", "checkpoint.pt"),
    api(CKPT + "p = Path('run/checkpoint.pt'); p.unlink(); p.symlink_to('/mnt/old-disk/c.pt'); "
        "load_checkpoint(p)", "checkpoint.pt"),
    api(SWEEP + "SweepSpec.load('sw')", "sw", True),
    api(SWEEP + "SweepSpec.load(Path('sw/base'))", "sweep.json"),
    api(SWEEP + "p = Path('sw/sweep.json'); p.write_bytes(p.read_bytes() + bytes(512)); "
        "SweepSpec.load(Path('sw'))", "sweep.json"),
]  # fmt: skip

CASES: list[dict] = [
    *RUN_CASES,
    *OUTPUT_CASES,
    *(fifth("files", command, argv, names, *ok, works=works, what=what)
      for command, argv, what, works, names, *ok in SWEEP_CASES + MINIGRID_CASES),
    *(fifth("files", "study", argv, names, *ok, works=(ARCH, DMC100K, *works), what=what)
      for argv, what, works, names, *ok in STUDY_CASES),
    *({**case, "area": "files"} for case in API_CASES),
]  # fmt: skip
