"""The seventh reliability trial's cases: files (see reliability_trial.py).

Kept files as a crash, a full disk, a copy from another machine or a tidy-up leave them, given
to the commands that read them: leftovers of interrupted atomic writes (``.NAME.PID.tmp.SUFFIX``
beside the real file, whole or cut short), files cut mid-row or emptied on the surfaces earlier
trials did not cut (the archives' and a sweep's runs, sweep.json), a run copied from another
machine (absolute paths of that machine inside, a GPU device), files with timestamps in the
future, archives holding folders their spec does not name (an unknown task, recipe or arm, a
copy named by a file manager, an empty run folder of a crash), run folders that are symbolic
links (to a copy, to nothing, to their own parent), runs moved into another task's or arm's
folder, logs with rows written after the last checkpoint, hand edits (comments in JSON and
CSV, a trailing comma, a learning rate changed by hand, the budget raised in config.json), and
a path to a file of the run given where the run is expected. Permissions are not tried: the
trial runs as root here, where they do not bite.
"""

from __future__ import annotations

import json
import os
import shutil
from pathlib import Path

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
    checkpoint_edit,
    csv_rows,
    cut_mid_row,
    edit_json,
    edit_text,
    fifth,
    spoil,
    trained,
)

SEED2 = trained("seed2", "--seed", "2")
DEAD_PID = 999_999  # a writer long gone: above the pid_max of most machines (32768 here)
FUTURE = 2_000_000_000  # a time stamp years ahead, seconds since the epoch
ELSEWHERE = "/home/alice/experiments/pointreach-s1"


def mgt_light(here: Path) -> None:
    """``mgt``: the MiniGrid v2 tuning archive without its in-progress checkpoints (large)."""
    shutil.copytree(STUDIES / "minigrid-v2/tuning", here / "mgt",
                    ignore=shutil.ignore_patterns("checkpoint.pt"))  # fmt: skip


def leftover(target: str, how: str = "whole", pid: int = DEAD_PID):
    """Work: the temporary an atomic write of ``target`` leaves when killed (``.STEM.PID.tmp
    SUFFIX`` beside it): a whole copy of the file, its first half (a full disk), or empty."""

    def work(here: Path) -> None:
        path = here / target
        data = path.read_bytes() if path.is_file() else b"{}"
        data = {"whole": data, "half": data[: len(data) // 2], "empty": b""}[how]
        path.with_name(f".{path.stem}.{pid}.tmp{path.suffix}").write_bytes(data)

    return work


def replay_leftover(here: Path) -> None:
    """Half the replay, as the next checkpoint's temporary ``.replay-60.PID.tmp.npz``."""
    data = next((here / "run").glob("replay-*.npz")).read_bytes()
    (here / f"run/.replay-60.{DEAD_PID}.tmp.npz").write_bytes(data[: len(data) // 2])


def future(tree: str):
    """Work: every file and folder under ``tree`` dated 2033 (a machine with a wrong clock)."""

    def work(here: Path) -> None:
        for path in [here / tree, *(here / tree).rglob("*")]:
            os.utime(path, (FUTURE, FUTURE), follow_symlinks=False)

    return work


def copy_of(target: str, source: str):
    """Work: ``source`` (a file or a tree) copied to ``target`` (which must not exist)."""

    def work(here: Path) -> None:
        (here / target).parent.mkdir(parents=True, exist_ok=True)
        if (here / source).is_dir():
            shutil.copytree(here / source, here / target, symlinks=True)
        else:
            shutil.copy2(here / source, here / target)

    return work


def moved(target: str, source: str):
    """Work: ``source`` moved to ``target``, replacing what was there."""

    def work(here: Path) -> None:
        if (here / target).is_dir():
            shutil.rmtree(here / target)
        (here / target).parent.mkdir(parents=True, exist_ok=True)
        shutil.move(here / source, here / target)

    return work


def linked_run(target: str, source: str | None):
    """Work: ``target`` made a symbolic link: to a copy of itself at ``source`` (moved there),
    to nothing (``source`` None), or, where ``source`` is ``..``, to its own parent (a loop)."""

    def work(here: Path) -> None:
        path = here / target
        if source is None:
            shutil.rmtree(path)
            path.symlink_to("nowhere")
        elif source == "..":
            shutil.rmtree(path)
            path.symlink_to("..")
        else:
            shutil.move(path, here / source)
            path.symlink_to(os.path.relpath(here / source, path.parent))

    return work


def add(name: str, data: str | bytes = "kept by hand\n"):
    """Work: a file ``name`` written (its folders made)."""

    def work(here: Path) -> None:
        (here / name).parent.mkdir(parents=True, exist_ok=True)
        raw = data.encode() if isinstance(data, str) else data
        (here / name).write_bytes(raw)

    return work


def folder(name: str):
    """Work: an empty folder ``name`` (a run a crash left before its first file)."""
    return lambda here: (here / name).mkdir(parents=True)


def both_configs(change):
    """Works: ``change`` made to the run's config.json and to the config its checkpoint holds
    (the run as it was trained elsewhere, not a mix)."""
    return (spoil("run/config.json", edit_json(change)),
            spoil("run/checkpoint.pt", checkpoint_edit(lambda p: change(p["config"]))))  # fmt: skip


HALF = "half"
EMPTY = b""
COMMENT_FIRST = edit_text(lambda text: "# trained on the lab laptop, 40 steps\n" + text)
JSON_COMMENT = edit_text(lambda text: "// PointReach, seed 1\n" + text)
TRAILING_COMMA = edit_text(lambda text: text.rstrip().rstrip("}").rstrip() + ",\n}\n")
SPACES = csv_rows(lambda rows: [[f" {c}" if i else c for i, c in enumerate(r)] for r in rows])
MIDDLE_ROW_GONE = csv_rows(lambda rows: [rows[0], rows[1], *rows[3:]])
INDENT4 = edit_text(lambda text: json.dumps(json.loads(text), indent=4, sort_keys=True) + "\n")
RESUMED_ONE_ROW = csv_rows(lambda rows: [*rows, ["50", *rows[-1][1:]]])
RESUMED_EVAL_ROW = csv_rows(lambda rows: [*rows, ["60", *rows[-1][1:]]])

EVAL, RESUME, REPORT, MASKS = (FILE_COMMANDS[c] for c in ("eval", "train", "report", "analyze"))
RUN_COMMANDS = {"eval": EVAL, "train": RESUME, "report": REPORT, "analyze": MASKS}


def on_run(commands: str, what: str, works, names, ok: bool = False) -> list[dict]:
    """One case per command of ``commands`` (space-separated keys of :data:`RUN_COMMANDS`)."""
    return [fifth("files", command, RUN_COMMANDS[command], names, ok, works=works, what=what)
            for command in commands.split()]  # fmt: skip


def run_file(name: str, how):
    return spoil(f"run/{name}", how)


# a run with what an interrupted write (a kill, a full disk) leaves beside its files
RUN_LEFTOVERS = [
    *on_run("train", "a whole .checkpoint.PID.tmp.pt of a dead writer",
            (leftover("run/checkpoint.pt"),), "", True),
    *on_run("eval", "half a .checkpoint.PID.tmp.pt (the disk filled up)",
            (leftover("run/checkpoint.pt", HALF),), "", True),
    *on_run("report", "half a .eval.PID.tmp.csv",
            (leftover("run/eval.csv", HALF),), "", True),
    *on_run("train", "half a .replay-60.PID.tmp.npz beside replay-40.npz",
            (replay_leftover,), "", True),
    *on_run("train", "tb/'s events file cut in half",
            (lambda here: [spoil(str(p.relative_to(here)), HALF)(here)
                           for p in (here / "run/tb").iterdir()],), "", True),
]  # fmt: skip
# a run copied from another machine, or one whose clock was wrong
RUN_ELSEWHERE = [
    *on_run("train", "config.json's run_dir a path of another machine",
            both_configs(lambda c: c.update(run_dir=ELSEWHERE)), "", True),
    *on_run("report", "summary.json naming its files by another machine's absolute paths",
            (run_file("summary.json", edit_json(lambda d: d.update(files={
                "learning_curve": f"{ELSEWHERE}/learning_curve.png",
                "checkpoint": f"{ELSEWHERE}/checkpoint.pt"}))),), "", True),
    *on_run("train", "a run trained on a GPU (device cuda) resumed on a machine without one",
            both_configs(lambda c: c.update(device="cuda")), ("cuda", "device")),
    *on_run("eval", "a run trained on a GPU (device cuda) evaluated on a machine without one",
            both_configs(lambda c: c.update(device="cuda")), ("cuda", "device"), True),
    *on_run("train", "every file dated 2033 (a wrong clock)", (future("run"),), "",
            True),
]  # fmt: skip
# logs that go on past the checkpoint: a kill after a row was written, before the next checkpoint
RUN_PAST_CHECKPOINT = [
    *on_run("train", "train.csv with an episode logged after the checkpoint (step 50)",
            (run_file("train.csv", RESUMED_ONE_ROW),), "train.csv", True),
    *on_run("train", "eval.csv with an evaluation logged after the checkpoint (step 60)",
            (run_file("eval.csv", RESUMED_EVAL_ROW),), "eval.csv", True),
]  # fmt: skip
# files edited by hand
RUN_HAND = [
    *on_run("train report", "eval.csv with a comment line first",
            (run_file("eval.csv", COMMENT_FIRST),), "eval.csv"),
    *on_run("train", "train.csv with a comment line first",
            (run_file("train.csv", COMMENT_FIRST),), "train.csv"),
    *on_run("train report", "eval.csv with a space after each comma",
            (run_file("eval.csv", SPACES),), "eval.csv", True),
    *on_run("report", "eval.csv with a middle evaluation deleted (an outlier removed)",
            (run_file("eval.csv", MIDDLE_ROW_GONE),), "eval.csv", True),
    *on_run("train", "eval.csv with a middle evaluation deleted (an outlier removed)",
            (run_file("eval.csv", MIDDLE_ROW_GONE),), "eval.csv"),
    *on_run("eval train", "config.json with a // comment line first",
            (run_file("config.json", JSON_COMMENT),), "config.json", False),
    *on_run("report", "summary.json with a // comment line first",
            (run_file("summary.json", JSON_COMMENT),), "summary.json"),
    *on_run("analyze", "config.json with a // comment line first",
            (run_file("config.json", JSON_COMMENT),), "config.json"),
    *on_run("train", "config.json with a trailing comma", (run_file("config.json",
            TRAILING_COMMA),), "config.json"),
    *on_run("train", "config.json reformatted (indent 4, keys sorted)",
            (run_file("config.json", INDENT4),), "", True),
    *on_run("train", "config.json with agent.lr lowered by hand to fine-tune",
            (run_file("config.json", edit_json(lambda d: d["agent"].update(lr=1e-5))),), "lr"),
    *on_run("report", "summary.json of another seed's run (its final return)",
            (SEED2, spoil("run/summary.json", lambda p: shutil.copy(p.parent.parent /
             "seed2/summary.json", p))), "summary.json"),
]  # fmt: skip
RUN_TOTAL_60 = run_file("config.json", edit_json(lambda d: d.update(total_env_steps=60)))
# a file of the run given where the run is expected, the run a symlink, a half-made run beside it
RUN_PATHS = [
    fifth("files", "eval", ["{run}/checkpoint.pt", "--episodes", "1", "--no-video"],
          "checkpoint.pt", True, what="the run's checkpoint.pt given for the run"),
    fifth("files", "train", ["--resume", "{run}/checkpoint.pt", "--total-env-steps", "60"],
          "checkpoint.pt", True, what="the run's checkpoint.pt given to --resume"),
    fifth("files", "train", ["--resume", "{run}"], "total_env_steps", True,
          works=(RUN_TOTAL_60,), what="config.json's total_env_steps raised to 60 by hand, "
          "--resume without --total-env-steps"),
    fifth("files", "report", ["."], "half", True,
          works=(folder("half"), add("half/config.json", "{}")),
          what="a folder of runs, one killed in set-up (only an empty-object config.json)"),
    fifth("files", "train", ["--resume", "{run}", "--total-env-steps", "60"], "tb", True,
          works=(spoil("run/tb", lambda p: (shutil.rmtree(p), p.symlink_to("/nowhere/tb"))),),
          what="tb a symbolic link to a folder of another machine (dangling)"),
]  # fmt: skip

STUDY_REPORT = ["report", "dmc100k.toml", "--study-dir", "arch"]
STUDY_RESUME = ["run", "dmc100k.toml", "--study-dir", "s", "--archive", "arch", "--resume",
                "--allow-other-commit"]  # fmt: skip
EV_DIR = "arch/evaluation/simoun/cartpole-swingup"
# the dmc100k archive: (argv, what, works, names[, valid])
STUDY_CASES = [
    (STUDY_REPORT, "an evaluation run's eval.csv cut mid-row",
     (spoil(f"{EV_RUN}/eval.csv", cut_mid_row),), "eval.csv"),
    (STUDY_REPORT, "an evaluation run's summary.json empty (the disk filled up)",
     (spoil(f"{EV_RUN}/summary.json", EMPTY),), "summary.json"),
    (STUDY_REPORT, "a tuning run's eval.csv cut mid-row",
     (spoil(f"{TU_RUN}/eval.csv", cut_mid_row),), "eval.csv"),
    (STUDY_REPORT, "a tuning run's config.json cut in half",
     (spoil(f"{TU_RUN}/config.json", HALF),), "config.json"),
    (STUDY_REPORT, "an evaluation run's config.json with a trailing comma (a hand edit)",
     (spoil(f"{EV_RUN}/config.json", TRAILING_COMMA),), "config.json"),
    (STUDY_REPORT, "a .study.PID.tmp.json left by a killed writer",
     (leftover("arch/study.json", HALF),), "", True),
    (STUDY_REPORT, "every file dated 2033", (future("arch"),), "", True),
    (STUDY_REPORT, "an evaluation run of a task the spec does not have (walker-walk/s1)",
     (copy_of("arch/evaluation/simoun/walker-walk/s1", EV_RUN),), "walker-walk", True),
    (STUDY_REPORT, "a copy of s1 named by a file manager ('s1 (copy)')",
     (copy_of(f"{EV_DIR}/s1 (copy)", EV_RUN),), "s1 (copy)", True),
    (STUDY_REPORT, "an empty run folder s9 (a crash before its first file)",
     (folder(f"{EV_DIR}/s9"),), "s9", True),
    (STUDY_REPORT, "a cartpole run moved into cheetah-run's s1",
     (moved("arch/evaluation/simoun/cheetah-run/s1", EV_RUN),), ("config.json", "cheetah")),
    (STUDY_REPORT, "an evaluation run a symbolic link to its copy outside the archive",
     (linked_run(EV_RUN, "outside-s1"),), "", True),
    (STUDY_REPORT, "an evaluation run a symbolic link to nothing",
     (linked_run(EV_RUN, None),), "s1"),
    (STUDY_REPORT, "an evaluation run a symbolic link to its own parent (a loop)",
     (linked_run(EV_RUN, ".."),), "s1"),
    (STUDY_REPORT, "an evaluation run's summary.json with a // comment line first",
     (spoil(f"{EV_RUN}/summary.json", JSON_COMMENT),), "summary.json"),
    (STUDY_REPORT, "study.json with a // comment line first",
     (spoil("arch/study.json", JSON_COMMENT),), "study.json"),
    (STUDY_RESUME, "an evaluation run's eval.csv cut mid-row",
     (spoil(f"{EV_RUN}/eval.csv", cut_mid_row),), "eval.csv"),
    (STUDY_RESUME, "an evaluation run a symbolic link to nothing",
     (linked_run(EV_RUN, None),), "s1"),
    (STUDY_RESUME, "an evaluation run's summary.json empty",
     (spoil(f"{EV_RUN}/summary.json", EMPTY),), "summary.json"),
]  # fmt: skip
MG_REPORT = ["report", "--archive", "mg"]
MG_STUDY = ["report", "mg/spec.json", "--study-dir", "mg"]
MGT_SELECT = ["select", "--archive", "mgt"]
MGT_RUN_ARGV = ["run", "--archive", "mgt", "--work-dir", "wd"]
MG_PPO = "mg/MiniGrid-DoorKey-6x6-v0/ppo"
MGT_ARM = "mgt/MiniGrid-DoorKey-6x6-v0/consistency,normalization=paper,scale=0.01/s100"
# the MiniGrid archives: (command, argv, what, works, names[, valid])
MINIGRID_CASES = [
    ("minigrid", MG_REPORT, "a run's eval.csv cut mid-row",
     (MG, spoil(f"{MG_RUN}/eval.csv", cut_mid_row)), "eval.csv"),
    ("minigrid", MG_REPORT, "a run's train.csv cut mid-row",
     (MG, spoil(f"{MG_RUN}/train.csv", cut_mid_row)), "train.csv", True),
    ("minigrid", MG_REPORT, "a run's summary.json empty (the disk filled up)",
     (MG, spoil(f"{MG_RUN}/summary.json", EMPTY)), "summary.json"),
    ("minigrid", MG_REPORT, "a .spec.PID.tmp.json left in the archive",
     (MG, leftover("mg/spec.json", HALF)), "", True),
    ("minigrid", MG_REPORT, "a task the spec does not have (Empty-5x5/ppo/s0)",
     (MG, copy_of("mg/MiniGrid-Empty-5x5-v0/ppo/s0", MG_RUN)), "Empty-5x5", True),
    ("minigrid", MG_REPORT, "a run's summary.json with a trailing comma (a hand edit)",
     (MG, spoil(f"{MG_RUN}/summary.json", TRAILING_COMMA)), "summary.json"),
    ("minigrid", MG_REPORT, "an empty run folder s9 (a crash before its first file)",
     (MG, folder(f"{MG_PPO}/s9")), "s9", True),
    ("minigrid", MG_REPORT, "a 6x6 run moved into 8x8's ppo/s0",
     (MG, moved("mg/MiniGrid-DoorKey-8x8-v0/ppo/s0", MG_RUN)), ("config.json", "8x8")),
    ("minigrid", MG_REPORT, "a run a symbolic link to its copy outside the archive",
     (MG, linked_run(MG_RUN, "outside-s0")), "", True),
    ("minigrid", MG_REPORT, "a run a symbolic link to nothing", (MG, linked_run(MG_RUN, None)),
     "s0"),
    ("minigrid", MG_REPORT, "a run a symbolic link to its own parent (a loop)",
     (MG, linked_run(MG_RUN, "..")), "s0"),
    ("minigrid", MG_REPORT, "spec.json with a // comment line first",
     (MG, spoil("mg/spec.json", JSON_COMMENT)), "spec.json"),
    ("minigrid", MG_REPORT, "a run's config.json with a // comment line first",
     (MG, spoil(f"{MG_RUN}/config.json", JSON_COMMENT)), "config.json"),
    ("minigrid", MG_REPORT, "a run's eval.csv with a comment line first",
     (MG, spoil(f"{MG_RUN}/eval.csv", COMMENT_FIRST)), "eval.csv"),
    ("minigrid", MGT_SELECT, "a run's eval.csv cut mid-row",
     (mgt_light, spoil(f"{MGT_RUN}/eval.csv", cut_mid_row)), "eval.csv"),
    ("minigrid", MGT_SELECT, "spec.json cut in half (the disk filled up)",
     (mgt_light, spoil("mgt/spec.json", HALF)), "spec.json"),
    ("minigrid", MGT_SELECT, "a run's config.json empty",
     (mgt_light, spoil(f"{MGT_RUN}/config.json", EMPTY)), "config.json"),
    ("minigrid", MGT_SELECT, "ppo/s100 moved into another arm's s100",
     (mgt_light, moved(MGT_ARM, MGT_RUN)), "config.json"),
    ("minigrid", MGT_SELECT, "an arm folder with a typo (scale=O.5, a letter O)",
     (mgt_light, copy_of("mgt/MiniGrid-DoorKey-6x6-v0/rnd,normalization=paper,scale=O.5/s100",
                         MGT_RUN)), "scale=O.5", True),
    ("minigrid", MGT_SELECT, "spec.json with a trailing comma (a hand edit)",
     (mgt_light, spoil("mgt/spec.json", TRAILING_COMMA)), "spec.json"),
    ("minigrid", MGT_RUN_ARGV, "a run's summary.json empty (the disk filled up)",
     (mgt_light, spoil(f"{MGT_RUN}/summary.json", EMPTY)), "summary.json"),
    ("minigrid", MGT_RUN_ARGV, "a run a symbolic link to nothing",
     (mgt_light, linked_run(MGT_RUN, None)), "s100"),
    ("study", MG_STUDY, "a run's eval.csv cut mid-row",
     (MG, spoil(f"{MG_RUN}/eval.csv", cut_mid_row)), "eval.csv"),
    ("study", MG_STUDY, "a run a symbolic link to nothing", (MG, linked_run(MG_RUN, None)),
     "s0"),
    ("study", ["report", "mgt/spec.json", "--study-dir", "mgt"], "a run's summary.json empty",
     (mgt_light, spoil(f"{MGT_RUN}/summary.json", EMPTY)), "summary.json"),
]  # fmt: skip
SW_REPORT = ["sw"]
SW_RESUME = ["--resume", "--sweep-dir", "sw"]
SW_DIR = "sw/base/simoun-PointReach-v0"
# a sweep directory: (command, argv, what, works, names[, valid])
SWEEP_CASES = [
    ("report", SW_REPORT, "sweep.json cut in half (the disk filled up)",
     (SW, spoil("sw/sweep.json", HALF)), "sweep.json"),
    ("sweep", SW_RESUME, "sweep.json cut in half (the disk filled up)",
     (SW, spoil("sw/sweep.json", HALF)), "sweep.json"),
    ("report", SW_REPORT, "a trial's eval.csv cut mid-row",
     (SW, spoil(f"{SW_RUN}/eval.csv", cut_mid_row)), "eval.csv"),
    ("sweep", SW_RESUME, "a finished trial's eval.csv cut mid-row",
     (SW, spoil(f"{SW_RUN}/eval.csv", cut_mid_row)), "eval.csv"),
    ("report", SW_REPORT, "a trial's summary.json empty",
     (SW, spoil(f"{SW_RUN}/summary.json", EMPTY)), "summary.json"),
    ("report", SW_REPORT, "a trial's config.json with a trailing comma (a hand edit)",
     (SW, spoil(f"{SW_RUN}/config.json", TRAILING_COMMA)), "config.json"),
    ("sweep", SW_RESUME, "a finished trial's config.json with a trailing comma (a hand edit)",
     (SW, spoil(f"{SW_RUN}/config.json", TRAILING_COMMA)), "config.json"),
    ("sweep", SW_RESUME, "sweep.json with a trailing comma (a hand edit)",
     (SW, spoil("sw/sweep.json", TRAILING_COMMA)), "sweep.json"),
    ("sweep", SW_RESUME, "a .sweep.PID.tmp.json left by a killed writer",
     (SW, leftover("sw/sweep.json", HALF)), "", True),
    ("sweep", SW_RESUME, "a finished trial's checkpoint.pt zero-filled",
     (SW, spoil(f"{SW_RUN}/checkpoint.pt", lambda p: p.write_bytes(bytes(p.stat().st_size)))),
     "checkpoint.pt", True),
    ("sweep", SW_RESUME, "a copy of a trial as 's1 (copy)'",
     (SW, copy_of(f"{SW_DIR}/s1 (copy)", SW_RUN)), "s1 (copy)", True),
    ("report", SW_REPORT, "a trial a symbolic link to its copy outside the sweep",
     (SW, linked_run(SW_RUN, "outside-s1")), "", True),
    ("sweep", SW_RESUME, "a finished trial a symbolic link to nothing",
     (SW, linked_run(SW_RUN, None)), "s1"),
    ("report", SW_REPORT, "a trial a symbolic link to its own parent (a loop)",
     (SW, linked_run(SW_RUN, "..")), "s1"),
    ("report", SW_REPORT, "sweep.json with a // comment line first",
     (SW, spoil("sw/sweep.json", JSON_COMMENT)), "sweep.json"),
]  # fmt: skip
CASES: list[dict] = [
    *RUN_LEFTOVERS,
    *RUN_ELSEWHERE,
    *RUN_PAST_CHECKPOINT,
    *RUN_HAND,
    *RUN_PATHS,
    *(fifth("files", "study", argv, names, *ok, works=(ARCH, DMC100K, *works), what=what)
      for argv, what, works, names, *ok in STUDY_CASES),
    *(fifth("files", command, argv, names, *ok, works=works, what=what)
      for command, argv, what, works, names, *ok in MINIGRID_CASES + SWEEP_CASES),
]  # fmt: skip
