"""The sixth reliability trial's cases: files (see reliability_trial.py).

The files users keep, mixed up rather than broken: a file of another run or of an older version
of the same run put in a run's place, a symbolic link to another run's file, a run or sweep
directory handed over as a tar file, CSV files as spreadsheets and pandas save them (columns
moved, an index column, semicolons, CRLF with a byte-order mark, steps as floats), very long
lines and huge numbers, JSON of valid syntax with a wrong type deep inside, files appended to
themselves, and valid variants that must be accepted (CRLF JSON, stray files a command does not
read). Each is given to the commands that read it: a run to ``simoun-eval``, ``simoun-train
--resume``, ``simoun-report`` and ``simoun-analyze``; a sweep to ``simoun-report`` and
``simoun-sweep --resume``; the study archives of docs/studies to ``simoun-study report`` and
``run --resume``; the MiniGrid archives to ``python -m simoun_lab.minigrid_study report|select``.
Permissions are not tried: the trial runs as root here, where they do not bite.
"""

from __future__ import annotations

import os
import shutil
import tarfile
from pathlib import Path

from reliability_trial import (
    ARCH,
    DMC100K,
    DRQ_RUN,
    EV_RUN,
    FILE_COMMANDS,
    MG,
    MG_RUN,
    MGT_RUN,
    STUDIES,
    SW,
    SW_RUN,
    csv_rows,
    edit_json,
    edit_text,
    fifth,
    lab_copy,
    put,
    spoil,
    trained,
    tree_to_file,
)

SEED2 = trained("seed2", "--seed", "2")
EASY_ARCH = lab_copy("dmc100k-drqv2-easy", "arch2")
EASY_SPEC = put("dmc100k-drqv2-easy.toml", (STUDIES / "dmc100k-drqv2-easy.toml").read_text())
EV2_RUN = "arch2/evaluation/drqv2_easy/cartpole-swingup/s1"
EV_S2 = "arch/evaluation/simoun/cartpole-swingup/s2"
MG_S1 = "mg/MiniGrid-DoorKey-6x6-v0/ppo/s1"


def mgt_light(here: Path) -> None:
    """``mgt``: the MiniGrid v2 tuning archive without its in-progress checkpoints (large)."""
    shutil.copytree(STUDIES / "minigrid-v2/tuning", here / "mgt",
                    ignore=shutil.ignore_patterns("checkpoint.pt"))  # fmt: skip


def twin(here: Path) -> None:
    """``other``: a copy of the run, as a second run of the same config."""
    shutil.copytree(here / "run", here / "other")


def remove(path: Path) -> None:
    if path.is_dir() and not path.is_symlink():
        shutil.rmtree(path)
    else:
        path.unlink(missing_ok=True)


def replace(target: str, source: str):
    """Work: the case's ``target`` replaced by a copy of its ``source`` (a file or a tree)."""

    def work(here: Path) -> None:
        remove(here / target)
        src = here / source
        if src.is_dir():
            shutil.copytree(src, here / target)
        else:
            shutil.copy2(src, here / target)

    return work


def link(target: str, source: str):
    """Work: the case's ``target`` replaced by a relative symbolic link to its ``source``."""

    def work(here: Path) -> None:
        remove(here / target)
        (here / target).symlink_to(os.path.relpath(here / source, (here / target).parent))

    return work


def replay_of(source: str, linked: bool = False):
    """Work: the run's replay replaced by ``source``'s (copied, or a symbolic link to it)."""

    def work(here: Path) -> None:
        for old in (here / "run").glob("replay-*.npz"):
            old.unlink()
        theirs = next((here / source).glob("replay-*.npz"))
        mine = here / "run" / theirs.name
        if linked:
            mine.symlink_to(os.path.relpath(theirs, mine.parent))
        else:
            shutil.copy2(theirs, mine)

    return work


def tarred(tree: str, name: str):
    """Work: the case's ``tree`` packed into the tar file ``name`` (and the tree removed)."""

    def work(here: Path) -> None:
        with tarfile.open(here / name, "w") as tar:
            tar.add(here / tree, arcname=tree)
        shutil.rmtree(here / tree)

    return work


def add(name: str, data: str):
    """Work: a file ``name`` written in the case's directory (its folders made)."""

    def work(here: Path) -> None:
        (here / name).parent.mkdir(parents=True, exist_ok=True)
        (here / name).write_text(data)

    return work


def strays(here: Path) -> None:
    """Files a user leaves in a run: a backup, a copy named by a file manager, notes, OS files."""
    for name in ("eval (1).csv", "config.json.bak", ".DS_Store", "notes.md", "videos/clip.mp4"):
        add(f"run/{name}", "kept by hand\n")(here)


def drop_column(name: str):
    return csv_rows(lambda rows: [[c for i, c in enumerate(r) if i != rows[0].index(name)]
                                  for r in rows])  # fmt: skip


def value_at(column: int, value: str):
    """A damage setting the last row's ``column`` to ``value``."""
    return csv_rows(lambda rows: [*rows[:-1], [*rows[-1][:column], value,
                                               *rows[-1][column + 1 :]]])  # fmt: skip


CRLF = edit_text(lambda text: text.replace("\n", "\r\n"))
EXCEL = edit_text(lambda text: "\ufeff" + text.replace("\n", "\r\n"))
SEMICOLONS = edit_text(lambda text: text.replace(",", ";").replace(".", ","))
TWICE = edit_text(lambda text: text + text)
REORDERED = csv_rows(lambda rows: [[*row[1:], row[0]] for row in rows])
FLOAT_STEPS = csv_rows(lambda rows: [rows[0], *([str(float(r[0])), *r[1:]] for r in rows[1:])])
PANDAS_INDEX = csv_rows(lambda rows: [["", *rows[0]],
                                      *([str(i), *r] for i, r in enumerate(rows[1:]))])  # fmt: skip
LONG_LINE = edit_text(lambda text: text + "x" * 200_000 + "\n")
HAND_NOTE = edit_text(lambda text: text + "stopped here, resume later\n")
HUGE = 10**30

EVAL, RESUME, REPORT, MASKS = (FILE_COMMANDS[c] for c in ("eval", "train", "report", "analyze"))
RUN_COMMANDS = {"eval": EVAL, "train": RESUME, "report": REPORT, "analyze": MASKS}


def on_run(
    commands: str, what: str, works, names, ok: bool = False, valid_for: str = ""
) -> list[dict]:
    """One case per command of ``commands`` (space-separated keys of :data:`RUN_COMMANDS`) on
    the run changed by ``works``; valid (``ok``) for all, or for those of ``valid_for``."""
    return [
        fifth("files", command, RUN_COMMANDS[command], names, ok or command in valid_for.split(),
              works=works, what=what)
        for command in commands.split()
    ]  # fmt: skip


def run_file(name: str, how):
    return spoil(f"run/{name}", how)


# a run with a file of another run, of an older version of itself, or linked to another run's
RUN_MIXED = [
    *on_run("eval train analyze", "checkpoint.pt of another recipe's run",
            (DRQ_RUN, replace("run/checkpoint.pt", "drq/checkpoint.pt")),
            ("checkpoint", "recipe")),
    *on_run("report", "checkpoint.pt of another recipe's run",
            (DRQ_RUN, replace("run/checkpoint.pt", "drq/checkpoint.pt")), "checkpoint.pt", True),
    *on_run("eval train", "config.json of another recipe's run",
            (DRQ_RUN, replace("run/config.json", "drq/config.json")), ("config.json", "recipe")),
    *on_run("train", "the replay of another seed's run", (SEED2, replay_of("seed2")), "replay"),
    *on_run("train", "checkpoint.pt of another seed's run",
            (SEED2, replace("run/checkpoint.pt", "seed2/checkpoint.pt")),
            ("checkpoint", "seed")),
    *on_run("train", "train.csv of another recipe's run",
            (DRQ_RUN, replace("run/train.csv", "drq/train.csv")), "train.csv", True),
    *on_run("train", "an older eval.csv (before the checkpoint's evaluations)",
            (run_file("eval.csv", csv_rows(lambda rows: rows[:2])),), "eval.csv"),
    *on_run("train", "an older train.csv (an episode before the checkpoint missing)",
            (run_file("train.csv", csv_rows(lambda rows: rows[:2])),), "train.csv"),
    *on_run("eval train", "config.json of a version with another eval_every",
            (run_file("config.json", edit_json(lambda d: d.update(eval_every=10))),),
            "eval_every", True),
    *on_run("eval train", "config.json a link to a copy of the run's own",
            (twin, link("run/config.json", "other/config.json")), "", True),
    *on_run("eval", "checkpoint.pt a link to another recipe's run's",
            (DRQ_RUN, link("run/checkpoint.pt", "drq/checkpoint.pt")), ("checkpoint", "recipe")),
    *on_run("train", "eval.csv a link to another run's", (twin, link("run/eval.csv",
            "other/eval.csv")), "eval.csv", True),
    *on_run("train", "the replay a link to another seed's run's",
            (SEED2, replay_of("seed2", linked=True)), "replay"),
]  # fmt: skip
# the run handed over packed into a tar file
RUN_TARRED = [
    fifth("files", command, [("run.tar" if a == "{run}" else a) for a in argv], "run.tar",
          works=(tarred("run", "run.tar"),), what="the run as a tar file")
    for command, argv in RUN_COMMANDS.items()
]  # fmt: skip
# CSV logs as spreadsheets and pandas save them, long lines, huge values
RUN_CSV = [
    *on_run("train report", "eval.csv with its columns in another order",
            (run_file("eval.csv", REORDERED),), "eval.csv", True),
    *on_run("train report", "train.csv with its columns in another order",
            (run_file("train.csv", REORDERED),), "train.csv", True),
    *on_run("train report", "eval.csv with a 200,000-character line",
            (run_file("eval.csv", LONG_LINE),), "eval.csv"),
    *on_run("train report", "eval.csv saved by a spreadsheet (BOM, CRLF)",
            (run_file("eval.csv", EXCEL),), "eval.csv", True),
    *on_run("train report", "eval.csv saved with semicolons and decimal commas",
            (run_file("eval.csv", SEMICOLONS),), "eval.csv"),
    *on_run("train report", "eval.csv with steps written as floats (20.0)",
            (run_file("eval.csv", FLOAT_STEPS),), ("eval.csv", "env_step"), True),
    *on_run("train report", "eval.csv saved by pandas with its index column",
            (run_file("eval.csv", PANDAS_INDEX),), "eval.csv", True),
]  # fmt: skip
# JSON files of valid syntax with a wrong type or size deep inside, and valid variants; a damaged
# config.json is a file simoun-eval does not need (it rebuilds the run from the checkpoint's own)
RUN_JSON = [
    *on_run("eval train", "config.json with agent.lr as a string",
            (run_file("config.json", edit_json(lambda d: d["agent"].update(lr="0.001"))),),
            "lr", valid_for="eval"),
    *on_run("eval", "config.json with agent a list",
            (run_file("config.json", edit_json(lambda d: d.update(agent=[]))),), "agent",
            True),
    *on_run("eval", "config.json with env_kwargs a list",
            (run_file("config.json", edit_json(lambda d: d.update(env_kwargs=[]))),),
            "env_kwargs", True),
    *on_run("train", "config.json with eval_distraction a string",
            (run_file("config.json", edit_json(
                lambda d: d.update(eval_distraction="color_easy"))),),
            "eval_distraction"),
    *on_run("eval", "config.json with agent.batch_size 8.0",
            (run_file("config.json", edit_json(lambda d: d["agent"].update(batch_size=8.0))),),
            "batch_size", True),
    *on_run("eval train", "config.json with a 31-digit seed",
            (run_file("config.json", edit_json(lambda d: d.update(seed=HUGE))),), "seed",
            valid_for="eval"),
    *on_run("eval train", "config.json with CRLF line endings",
            (run_file("config.json", CRLF),), "config.json", True),
    *on_run("eval train", "config.json appended to itself",
            (run_file("config.json", TWICE),), "config.json", valid_for="eval"),
    *on_run("train", "config.json with agent.lr a list",
            (run_file("config.json", edit_json(lambda d: d["agent"].update(lr=[0.001]))),),
            "lr"),
    *on_run("eval", "config.json with image_size 32.5",
            (run_file("config.json", edit_json(lambda d: d.update(image_size=32.5))),),
            "image_size", True),
    *on_run("train", "config.json with total_env_steps 1e30",
            (run_file("config.json", edit_json(lambda d: d.update(total_env_steps=1e30))),),
            "total_env_steps"),
    *on_run("report", "summary.json with env_step true",
            (run_file("summary.json", edit_json(lambda d: d.update(env_step=True))),),
            ("summary.json", "env_step")),
    *on_run("report", "summary.json with final_eval a list",
            (run_file("summary.json", edit_json(lambda d: d.update(final_eval=[]))),),
            "summary.json"),
    *on_run("report", "summary.json with a return as a word",
            (run_file("summary.json", edit_json(
                lambda d: d["final_eval"].update(return_mean="high"))),), "summary.json"),
    *on_run("report", "summary.json with a step of 1e30",
            (run_file("summary.json", edit_json(lambda d: d.update(env_step=1e30))),),
            "summary.json"),
    *on_run("report", "summary.json with files null",
            (run_file("summary.json", edit_json(lambda d: d.update(files=None))),),
            "summary.json", True),
    *on_run("train report", "stray files (a backup, a copy, notes, .DS_Store, a video)",
            (strays,), "", True),
]  # fmt: skip

STUDY_REPORT = ["report", "dmc100k.toml", "--study-dir", "arch"]
STUDY_RESUME = ["run", "dmc100k.toml", "--study-dir", "s", "--archive", "arch", "--resume",
                "--allow-other-commit"]  # fmt: skip
# the dmc100k archive, and the drqv2-easy one: (argv, what, works, names[, valid])
STUDY_CASES = [
    (STUDY_REPORT, "an evaluation run's eval.csv with CRLF", (spoil(f"{EV_RUN}/eval.csv", CRLF),),
     "eval.csv", True),
    (STUDY_REPORT, "an evaluation run's eval.csv with its columns in another order",
     (spoil(f"{EV_RUN}/eval.csv", REORDERED),), "eval.csv", True),
    (STUDY_REPORT, "an evaluation run's eval.csv without wall_time_s",
     (spoil(f"{EV_RUN}/eval.csv", drop_column("wall_time_s")),), ("eval.csv", "wall_time_s")),
    (STUDY_REPORT, "an evaluation run's eval.csv appended to itself",
     (spoil(f"{EV_RUN}/eval.csv", TWICE),), "eval.csv"),
    (STUDY_REPORT, "an evaluation run's eval.csv with a 400-digit return",
     (spoil(f"{EV_RUN}/eval.csv", value_at(1, "9" * 400)),), ("eval.csv", "return_mean")),
    (STUDY_REPORT, "s1's config.json replaced by s2's", (replace(f"{EV_RUN}/config.json",
     f"{EV_S2}/config.json"),), ("config.json", "seed")),
    (STUDY_REPORT, "a run of the drqv2-easy archive mixed in as s6",
     (EASY_ARCH, replace("arch/evaluation/simoun/cartpole-swingup/s6", EV2_RUN)), "s6", True),
    (STUDY_REPORT, "study.json of the drqv2-easy archive",
     (EASY_ARCH, replace("arch/study.json", "arch2/study.json")), "study.json"),
    (STUDY_REPORT, "study.json with CRLF", (spoil("arch/study.json", CRLF),), "study.json", True),
    (STUDY_REPORT, "study.json with parts an object",
     (spoil("arch/study.json", edit_json(lambda d: d.update(parts={}))),),
     ("study.json", "parts")),
    (STUDY_REPORT, "study.json with a note typed after it",
     (spoil("arch/study.json", HAND_NOTE),), "study.json"),
    (STUDY_REPORT, "a trial.json with a load average as a word",
     (spoil(f"{EV_RUN}/trial.json", edit_json(lambda d: d["parts"][0].update(loadavg="high"))),),
     "trial.json", True),
    (STUDY_REPORT, "an evaluation run's summary.json with final_eval a list",
     (spoil(f"{EV_RUN}/summary.json", edit_json(lambda d: d.update(final_eval=[]))),),
     "summary.json"),
    (STUDY_REPORT, "an evaluation run's summary.json with a 31-digit step",
     (spoil(f"{EV_RUN}/summary.json", edit_json(lambda d: d.update(env_step=HUGE))),),
     "summary.json"),
    (STUDY_REPORT, "study.json with spec.recipes a string",
     (spoil("arch/study.json", edit_json(lambda d: d["spec"].update(recipes="simoun"))),),
     ("study.json", "recipes")),
    (STUDY_REPORT, "an evaluation run a file", (spoil(EV_RUN, tree_to_file),), "s1"),
    (["report", "dmc100k.toml", "--study-dir", "arch2"], "the drqv2-easy archive given dmc100k's"
     " spec", (EASY_ARCH,), ("study.json", "spec", "recipes")),
    (["report", "dmc100k-drqv2-easy.toml", "--study-dir", "arch2"],
     "a drqv2-easy run's eval.csv with semicolons",
     (EASY_ARCH, EASY_SPEC, spoil(f"{EV2_RUN}/eval.csv", SEMICOLONS)), "eval.csv"),
    (["report", "dmc100k-drqv2-easy.toml", "--study-dir", "arch2"],
     "the drqv2-easy archive without its comparison folder",
     (EASY_ARCH, EASY_SPEC, lambda here: shutil.rmtree(here / "arch2/cartpole-with-dmc100k")),
     "", True),
    (STUDY_RESUME, "study.json of the drqv2-easy archive",
     (EASY_ARCH, replace("arch/study.json", "arch2/study.json")), "study.json"),
    (STUDY_RESUME, "a finished run's eval.csv with semicolons",
     (spoil(f"{EV_RUN}/eval.csv", SEMICOLONS),), "eval.csv"),
    (STUDY_RESUME, "study.json with CRLF", (spoil("arch/study.json", CRLF),), "study.json", True),
]  # fmt: skip
MG_REPORT = ["report", "--archive", "mg"]
MGT_SELECT = ["select", "--archive", "mgt"]
MGT_RESUME = ["run", "mgt/spec.json", "--study-dir", "s", "--archive", "mgt", "--resume"]
MGT_PPO_S100 = "mgt/MiniGrid-DoorKey-6x6-v0/rnd,normalization=paper,scale=0.5/s100"
# the MiniGrid archives: (command, argv, what, works, names[, valid])
MINIGRID_CASES = [
    ("minigrid", MG_REPORT, "a run's eval.csv with CRLF", (MG, spoil(f"{MG_RUN}/eval.csv",
     CRLF)), "eval.csv", True),
    ("minigrid", MG_REPORT, "spec.json with a task's seeds a string",
     (MG, spoil("mg/spec.json", edit_json(lambda d: d["tasks"][0].update(seeds="0-4")))),
     ("spec.json", "seeds")),
    ("minigrid", MG_REPORT, "a run's eval.csv without success_rate",
     (MG, spoil(f"{MG_RUN}/eval.csv", drop_column("success_rate"))),
     ("eval.csv", "success_rate")),
    ("minigrid", MG_REPORT, "a run's eval.csv appended to itself",
     (MG, spoil(f"{MG_RUN}/eval.csv", TWICE)), "eval.csv"),
    ("minigrid", MG_REPORT, "a run's eval.csv with a note typed after it",
     (MG, spoil(f"{MG_RUN}/eval.csv", HAND_NOTE)), "eval.csv"),
    ("minigrid", MG_REPORT, "s0's summary.json replaced by s1's",
     (MG, replace(f"{MG_RUN}/summary.json", f"{MG_S1}/summary.json")), "summary.json"),
    ("minigrid", MG_REPORT, "s0's config.json replaced by s1's",
     (MG, replace(f"{MG_RUN}/config.json", f"{MG_S1}/config.json")), "config.json"),
    ("minigrid", MG_REPORT, "a run of the v2 tuning archive mixed in as ppo/s100",
     (MG, mgt_light, replace("mg/MiniGrid-DoorKey-6x6-v0/ppo/s100", MGT_RUN)), "s100", True),
    ("minigrid", MG_REPORT, "spec.json of the v2 tuning archive",
     (MG, mgt_light, replace("mg/spec.json", "mgt/spec.json")), ("spec.json", "config.json")),
    ("minigrid", MG_REPORT, "a run's summary.json with a 31-digit env_steps",
     (MG, spoil(f"{MG_RUN}/summary.json", edit_json(lambda d: d.update(env_steps=HUGE)))),
     ("summary.json", "env_steps")),
    ("minigrid", MG_REPORT, "a run's summary.json with parts a string",
     (MG, spoil(f"{MG_RUN}/summary.json", edit_json(lambda d: d.update(parts="two")))),
     "summary.json", True),
    ("minigrid", MG_REPORT, "a run's config.json with spec.ppo a list",
     (MG, spoil(f"{MG_RUN}/config.json", edit_json(lambda d: d["spec"].update(ppo=[])))),
     "config.json"),
    ("minigrid", MG_REPORT, "a run a file", (MG, spoil(MG_RUN, tree_to_file)), "s0"),
    ("minigrid", MGT_SELECT, "a run's eval.csv with a success rate of 1e400",
     (mgt_light, spoil(f"{MGT_RUN}/eval.csv", value_at(2, "1e400"))),
     ("eval.csv", "success_rate")),
    ("minigrid", MGT_SELECT, "spec.json with CRLF", (mgt_light, spoil("mgt/spec.json", CRLF)),
     "spec.json", True),
    ("minigrid", MGT_SELECT, "an arm the spec does not have (a copy of ppo)",
     (mgt_light, replace(MGT_PPO_S100, MGT_RUN)), "scale=0.5", True),
    ("study", ["report", "mg/spec.json", "--study-dir", "mg"], "a run's train.csv with CRLF",
     (MG, spoil(f"{MG_RUN}/train.csv", CRLF)), "train.csv", True),
    ("study", MGT_RESUME, "a run's config.json of another arm",
     (mgt_light, replace(f"{MGT_RUN}/config.json",
      "mgt/MiniGrid-DoorKey-6x6-v0/consistency,normalization=paper,scale=0.01/s100/config.json")),
     "config.json"),
]  # fmt: skip
SW_REPORT = ["sw"]
SW_RESUME = ["--resume", "--sweep-dir", "sw"]
# a sweep directory: (command, argv, what, works, names[, valid])
SWEEP_CASES = [
    ("report", SW_REPORT, "sweep.json with CRLF", (SW, spoil("sw/sweep.json", CRLF)),
     "sweep.json", True),
    ("report", SW_REPORT, "sweep.json with a note typed after it",
     (SW, spoil("sw/sweep.json", HAND_NOTE)), "sweep.json"),
    ("report", SW_REPORT, "sweep.json with a 31-digit seed",
     (SW, spoil("sw/sweep.json", edit_json(lambda d: d.update(seeds=[HUGE])))), "seed"),
    ("sweep", SW_RESUME, "sweep.json with a 31-digit seed",
     (SW, spoil("sw/sweep.json", edit_json(lambda d: d.update(seeds=[HUGE])))), "seed"),
    ("report", SW_REPORT, "sweep.json with base a list",
     (SW, spoil("sw/sweep.json", edit_json(lambda d: d.update(base=[])))),
     ("sweep.json", "base")),
    ("report", SW_REPORT, "sweep.json with a grid value a list of lists",
     (SW, spoil("sw/sweep.json", edit_json(lambda d: d.update(grid={"agent.lr": [[0.1]]})))),
     ("sweep.json", "lr")),
    ("report", SW_REPORT, "a trial the sweep does not have (a copy as s7)",
     (SW, replace("sw/base/simoun-PointReach-v0/s7", SW_RUN)), "s7", True),
    ("sweep", SW_RESUME, "a finished trial's checkpoint.pt of another recipe's run",
     (SW, DRQ_RUN, replace(f"{SW_RUN}/checkpoint.pt", "drq/checkpoint.pt")), "checkpoint.pt",
     True),
    ("report", ["sw.tar"], "the sweep as a tar file", (SW, tarred("sw", "sw.tar")), "sw.tar"),
]  # fmt: skip
CASES: list[dict] = [
    *RUN_MIXED,
    *RUN_TARRED,
    *RUN_CSV,
    *RUN_JSON,
    *(fifth("files", "study", argv, names, *ok, works=(ARCH, DMC100K, *works), what=what)
      for argv, what, works, names, *ok in STUDY_CASES),
    *(fifth("files", command, argv, names, *ok, works=works, what=what)
      for command, argv, what, works, names, *ok in MINIGRID_CASES + SWEEP_CASES),
]  # fmt: skip
