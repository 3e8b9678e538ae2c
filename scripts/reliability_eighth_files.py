"""The eighth reliability trial's cases: files (see reliability_trial.py).

Kept files as users tidy, move, compress and rewrite them, given to the commands that read them
and to the Python API's loaders. A run's files renamed or compressed by hand (checkpoint.pt kept
as checkpoint-40.pt, the replay gzipped), a run unpacked one folder too deep, JSON written by
other tools (escaped slashes, 1e-3 for 0.001, every number a float), CSV logs without their final
newline or with blank lines after the last row; the outputs of earlier commands left in or beside
a run (an evaluation's ``eval-40/``, an analysis' ``analysis/``, an earlier report, ``bias.json``)
damaged, replaced by a file or by a link to nothing, on ``simoun-eval``, ``simoun-report`` (also
at an equal wall-time or step budget, with ``wall_time_s`` damaged) and ``simoun-analyze masks``
and ``bias``. A sweep without its ``sweep.json``, extended by editing it, with a STOP file a
killed sweep left, a trial renamed, a backup of the sweep kept inside it. A study archive with a
damaged ``update_cost.json`` or ``references.json``, its ``report/`` replaced, its tuning phase
deleted, its evaluation folder moved to another disk and linked back. The MiniGrid archives'
in-progress checkpoints damaged (in the archive and in the work directory) for ``run``, and
their ``report/``, ``selection.*`` and ``probe/`` outputs damaged. The loaders ``load_run``,
``load_checkpoint``, ``read_csv``, ``read_log``, ``SweepSpec.load`` and the MiniGrid
``load_spec`` given the right files, the wrong files and damaged ones. Permissions are not tried:
the trial runs as root here, where they do not bite.
"""

from __future__ import annotations

import gzip
import json
import shutil
from pathlib import Path

from reliability_trial import (
    ARCH,
    DMC100K,
    EV_RUN,
    FILE_COMMANDS,
    MG,
    MG_RUN,
    MGT,
    MGT_RUN,
    STUDIES,
    SW,
    SW_RUN,
    TU_RUN,
    api,
    csv_rows,
    edit_json,
    edit_text,
    fifth,
    spoil,
)

EVAL, RESUME, REPORT, MASKS = (FILE_COMMANDS[c] for c in ("eval", "train", "report", "analyze"))
BIAS = ["bias", "{run}", "--pairs", "8", "--out", "b"]
RUN_COMMANDS = {"eval": ("eval", EVAL), "train": ("train", RESUME), "report": ("report", REPORT),
                "masks": ("analyze", MASKS), "bias": ("analyze", BIAS)}  # fmt: skip


def on_run(commands: str, what: str, works, names, ok: bool = False) -> list[dict]:
    """One case per command of ``commands`` (space-separated keys of :data:`RUN_COMMANDS`)."""
    return [fifth("files", RUN_COMMANDS[key][0], RUN_COMMANDS[key][1], names, ok, works=works,
                  what=what) for key in commands.split()]  # fmt: skip


def run_file(name: str, how):
    return spoil(f"run/{name}", how)


def renamed(source: str, target: str):
    """Work: ``source`` renamed ``target`` (paths in the case's directory)."""
    return lambda here: (here / source).rename(here / target)


def gzip_replay(here: Path) -> None:
    """The run's replay compressed by hand to save space (``gzip replay-40.npz``)."""
    path = next((here / "run").glob("replay-*.npz"))
    with gzip.open(f"{path}.gz", "wb") as f:
        f.write(path.read_bytes())
    path.unlink()


def one_deeper(here: Path) -> None:
    """The run's files one folder deeper (an archive unpacked into the folder it was named for)."""
    inner = here / "run.tmp"
    shutil.move(here / "run", inner)
    (here / "run").mkdir()
    shutil.move(inner, here / "run/pointreach-s1")


def add(name: str, data: str | bytes = "kept by hand\n"):
    """Work: a file ``name`` written (its folders made)."""

    def work(here: Path) -> None:
        (here / name).parent.mkdir(parents=True, exist_ok=True)
        (here / name).write_bytes(data.encode() if isinstance(data, str) else data)

    return work


def folder(name: str):
    """Work: a folder ``name`` (and its parents)."""
    return lambda here: (here / name).mkdir(parents=True, exist_ok=True)


def dangling(name: str):
    """Work: ``name`` a symbolic link to a path of another machine."""

    def work(here: Path) -> None:
        path = here / name
        if path.is_dir() and not path.is_symlink():
            shutil.rmtree(path)
        elif path.exists() or path.is_symlink():
            path.unlink()
        path.parent.mkdir(parents=True, exist_ok=True)
        path.symlink_to("/mnt/old-disk/" + path.name)

    return work


def removed(name: str):
    """Work: ``name`` (a file or a tree) deleted."""

    def work(here: Path) -> None:
        path = here / name
        shutil.rmtree(path) if path.is_dir() else path.unlink()

    return work


def evaluated_into(out: str):
    """Work: the run evaluated by simoun-eval (1 episode) into ``out``."""

    def work(here: Path) -> None:
        from simoun_agent.cli import eval as evaluate

        evaluate.main([str(here / "run"), "--no-video", "--episodes", "1", "--no-progress",
                       "--out", str(here / out)])  # fmt: skip

    return work


def utf16(path: Path) -> None:
    """The file saved as UTF-16 (with its byte-order mark), as PowerShell's ``>`` writes text."""
    path.write_bytes(path.read_text().encode("utf-16"))


def floats_everywhere(data: dict) -> None:
    """Every whole number written as a float, as tools that keep one number type do."""
    for section in (data, data["agent"]):
        for key, value in section.items():
            if type(value) is int:
                section[key] = float(value)


NO_FINAL_NEWLINE = edit_text(lambda text: text.rstrip("\n"))
NO_HEADER = edit_text(lambda text: text.split("\n", 1)[1])
ESCAPED_SLASH = edit_text(lambda text: text.replace("/", "\\/"))
LR_E = edit_text(lambda text: text.replace('"lr": 0.001', '"lr": 1e-3'))
SPACES = csv_rows(lambda rows: [[f" {c}" if i else c for i, c in enumerate(r)] for r in rows])
REINDENT = edit_text(lambda text: json.dumps(json.loads(text), indent=4, sort_keys=True) + "\n")
HALF = "half"
WALL_NA = csv_rows(lambda rows: [*rows[:-1], [*rows[-1][:-1], "n/a"]])
NO_WALL = csv_rows(lambda rows: [row[:-1] for row in rows])
ROW_20_GONE = csv_rows(lambda rows: [row for row in rows if row[0] != "20"])
COMMENT_FIRST = edit_text(lambda text: "# tuned by hand\n" + text)
TRAILING_COMMA = edit_text(lambda text: text.rstrip().rstrip("}").rstrip() + ",\n}\n")
OLD_PNG = add("run/analysis/masks-40/ep0-step0002.png", b"\x89PNG\r\n\x1a\n")

# a run's files renamed, compressed, moved one folder deeper, rewritten by other tools
RUN_TIDIED = [
    *on_run("train eval bias", "checkpoint.pt renamed checkpoint-40.pt (a version kept)",
            (renamed("run/checkpoint.pt", "run/checkpoint-40.pt"),), "checkpoint"),
    fifth("files", "eval", ["{run}/checkpoint-40.pt", "--episodes", "1", "--no-video"], "", True,
          works=(renamed("run/checkpoint.pt", "run/checkpoint-40.pt"),),
          what="the renamed checkpoint-40.pt given by its path"),
    *on_run("train", "the replay gzipped by hand (replay-40.npz.gz)", (gzip_replay,), "replay"),
    *on_run("train eval", "the run unpacked one folder deeper (run/pointreach-s1/...)",
            (one_deeper,), ("checkpoint.pt", "pointreach-s1")),
    *on_run("train", "config.json with its slashes escaped (simoun\\/PointReach-v0)",
            (run_file("config.json", ESCAPED_SLASH),), "", True),
    *on_run("train", "config.json with agent.lr written 1e-3 (the same value)",
            (run_file("config.json", LR_E),), "", True),
    *on_run("train", "config.json with every whole number written as a float (seed 1.0)",
            (run_file("config.json", edit_json(floats_everywhere)),),
            ("config.json", "seed", "float"), True),
    *on_run("train", "eval.csv without its final newline (an editor's save)",
            (run_file("eval.csv", NO_FINAL_NEWLINE),), "eval.csv", True),
    *on_run("train report", "eval.csv saved as UTF-16 (a PowerShell redirection)",
            (run_file("eval.csv", utf16),), "eval.csv"),
    *on_run("train", "train.csv saved as UTF-16 (a PowerShell redirection)",
            (run_file("train.csv", utf16),), "train.csv"),
    *on_run("train report", "eval.csv with its header line deleted",
            (run_file("eval.csv", NO_HEADER),), "eval.csv"),
]  # fmt: skip
# what earlier commands wrote in or beside the run, left there and damaged
RUN_OUTPUTS = [
    *on_run("eval", "eval-40 a symbolic link to a folder of another machine",
            (dangling("run/eval-40"),), "eval-40"),
    *on_run("eval", "eval-40 a file (notes kept under that name)",
            (add("run/eval-40", "seed 1 looked fine\n"),), "eval-40"),
    fifth("files", "eval", ["{run}", "--episodes", "1", "--no-video", "--out", "o",
                            "--overwrite"], "metrics.json",
          works=(evaluated_into("o"), spoil("o/metrics.json", lambda p: (p.unlink(),
                                                                          p.mkdir()))),
          what="--overwrite of an earlier evaluation whose metrics.json is a folder"),
    *on_run("train", "an evaluation by simoun-eval kept in the run (eval-40/)",
            (evaluated_into("run/eval-40"),), "", True),
    fifth("files", "report", ["{run}"], "report-run",
          works=(add("report-run", "notes\n"),), what="report-run beside the run a file"),
    fifth("files", "report", ["{run}", "--at-wall-time", "0.1"], ("eval.csv", "wall_time_s"),
          works=(run_file("eval.csv", WALL_NA),), what="eval.csv's last wall_time_s 'n/a'"),
    fifth("files", "report", ["{run}", "--at-wall-time", "0.1"], ("eval.csv", "wall_time_s"),
          works=(run_file("eval.csv", NO_WALL),),
          what="eval.csv without wall_time_s (an older version), at an equal wall time"),
    fifth("files", "report", ["{run}", "--at-step", "20"], "env_step",
          works=(run_file("eval.csv", csv_rows(lambda rows: [row[1:] for row in rows])),),
          what="eval.csv without its env_step column, at --at-step 20"),
    fifth("files", "report", ["{run}", "--at-step", "20"], ("20", "short", "--at-step"), True,
          works=(run_file("eval.csv", ROW_20_GONE),),
          what="eval.csv without its step-20 row, at --at-step 20"),
    *on_run("bias", "config.json with a // comment line first",
            (run_file("config.json", edit_text(lambda t: "// seed 1\n" + t)),), "config.json"),
    fifth("files", "analyze", BIAS, ("bias.json", "--overwrite"),
          works=(add("b/bias.json", '{"runs": ['),),
          what="an earlier bias.json in --out, cut short, without --overwrite"),
    fifth("files", "analyze", [*BIAS, "--overwrite"], "bias.json",
          works=(folder("b/bias.json"),), what="--overwrite with bias.json a folder in --out"),
    *on_run("masks", "analysis a file in the run (notes)", (add("run/analysis", "notes\n"),),
            "analysis"),
    *on_run("masks", "an earlier masks-40/ in the run, without --overwrite", (OLD_PNG,),
            ("masks-40", "--overwrite")),
]  # fmt: skip

SW_REPORT, SW_RESUME = ["sw"], ["--resume", "--sweep-dir", "sw"]
SW_DIR = "sw/base/simoun-PointReach-v0"


def more_seeds(data: dict) -> None:
    data["seeds"] = [*data["seeds"], max(data["seeds"]) + 1]


def failed_trial(here: Path) -> None:
    """The trial failed: its files without summary.json, and an error.txt in UTF-16."""
    (here / f"{SW_RUN}/summary.json").unlink()
    (here / f"{SW_RUN}/error.txt").write_bytes("RayTaskError: out of memory\n".encode("utf-16"))


# a sweep directory: (command, argv, what, works, names[, valid])
SWEEP_CASES = [
    ("report", SW_REPORT, "sweep.json deleted (the trials kept)",
     (SW, removed("sw/sweep.json")), "sweep.json", True),
    ("sweep", SW_RESUME, "sweep.json deleted (the trials kept)",
     (SW, removed("sw/sweep.json")), "sweep.json"),
    ("sweep", SW_RESUME, "sweep.json's seeds extended by hand (one more seed)",
     (SW, spoil("sw/sweep.json", edit_json(more_seeds))), "seeds", True),
    ("sweep", SW_RESUME, "sweep.json's base total_env_steps raised by hand to 60",
     (SW, spoil("sw/sweep.json", edit_json(lambda d: d["base"].update(total_env_steps=60)))),
     "total_env_steps", True),
    ("sweep", SW_RESUME, "a STOP file a killed sweep left", (SW, add("sw/STOP", "SIGTERM\n")),
     "STOP", True),
    ("sweep", SW_RESUME, "the trial s1 renamed seed1 by hand",
     (SW, renamed(SW_RUN, f"{SW_DIR}/seed1")), "seed1", True),
    ("report", SW_REPORT, "a failed trial's error.txt in UTF-16 (binary)", (SW, failed_trial),
     "error.txt", True),
    ("sweep", SW_RESUME, "sweep.json's base agent.lr changed by hand after a trial finished",
     (SW, spoil("sw/sweep.json", edit_json(lambda d: d["base"].update({"agent.lr": 0.01})))),
     "lr"),
    ("sweep", SW_RESUME, "sweep.json's base image_size changed by hand after a trial finished",
     (SW, spoil("sw/sweep.json", edit_json(lambda d: d["base"].update(image_size=48)))),
     "image_size"),
    ("report", SW_REPORT, "sweep.json of another sweep (seeds 5 and 6)",
     (SW, spoil("sw/sweep.json", edit_json(lambda d: d.update(seeds=[5, 6])))),
     ("sweep.json", "s1", "seed")),
    ("sweep", SW_RESUME, "a finished trial's config.json saved as UTF-16",
     (SW, spoil(f"{SW_RUN}/config.json", utf16)), "config.json", True),
    ("report", SW_REPORT, "a trial's eval.csv a symbolic link to another machine's",
     (SW, dangling(f"{SW_RUN}/eval.csv")), "eval.csv"),
    ("sweep", SW_RESUME, "a finished trial's summary.json cut in half",
     (SW, spoil(f"{SW_RUN}/summary.json", HALF)), "summary.json"),
]  # fmt: skip

STUDY_REPORT = ["report", "dmc100k.toml", "--study-dir", "arch"]
STUDY_RESUME = ["run", "dmc100k.toml", "--study-dir", "s", "--archive", "arch", "--resume",
                "--allow-other-commit"]  # fmt: skip
COSTS = "arch/update_cost.json"


def costs(**change) -> str:
    """An update_cost.json as benchmarks/recipe_update.py writes it, with ``change``."""
    data = {"baseline": "drq", "ratio": {"simoun": 2.1, "drq": 1.0},
            "ms_per_update": {"simoun": 21.0, "drq": 10.0}, "task": "cartpole-swingup",
            "action_repeat": 8, "command": "python benchmarks/recipe_update.py", "commit": "abc",
            "machine": "laptop"}  # fmt: skip
    return json.dumps({**data, **change})


# the dmc100k archive: (argv, what, works, names[, valid])
STUDY_CASES = [
    (STUDY_REPORT, "update_cost.json cut in half", (add(COSTS, '{"baseline": "drq", "ra'),),
     "update_cost.json"),
    (STUDY_REPORT, "update_cost.json with its ratio a list",
     (add(COSTS, costs(ratio=[1.0, 2.1])),),
     ("update_cost.json", "ratio")),
    (STUDY_REPORT, "update_cost.json an empty object", (add(COSTS, "{}"),), "update_cost.json"),
    (STUDY_REPORT, "update_cost.json with a baseline the study does not have (sac)",
     (add(COSTS, costs(baseline="sac")),), ("update_cost.json", "sac")),
    (STUDY_REPORT, "update_cost.json with a ratio written as text (2.1x)",
     (add(COSTS, costs(ratio={"simoun": "2.1x", "drq": 1.0})),), ("update_cost.json", "2.1x")),
    (STUDY_REPORT, "report/ a symbolic link to another machine's folder",
     (dangling("arch/report"),), "report"),
    (STUDY_REPORT, "report/report.md a folder", (removed("arch/report/report.md"),
                                                 folder("arch/report/report.md")), "report.md"),
    (STUDY_REPORT, "an evaluation run's trial.json deleted",
     (removed(f"{EV_RUN}/trial.json"),), "trial.json", True),
    (STUDY_REPORT, "an evaluation run's summary.json one level deeper ({\"summary\": ...})",
     (spoil(f"{EV_RUN}/summary.json", edit_text(lambda t: '{"summary": ' + t + "}")),),
     "summary.json"),
    (STUDY_REPORT, "an evaluation run's eval.csv with its header line deleted",
     (spoil(f"{EV_RUN}/eval.csv", NO_HEADER),), "eval.csv"),
    (STUDY_RESUME, "a tuning run's eval.csv with its header line deleted",
     (spoil(f"{TU_RUN}/eval.csv", NO_HEADER),), "eval.csv"),
    (STUDY_REPORT, "tuning/ deleted to save space", (removed("arch/tuning"),), "tuning"),
    (STUDY_RESUME, "an evaluation run's config.json reformatted (indent 4, keys sorted)",
     (spoil(f"{EV_RUN}/config.json", REINDENT),), "", True),
    (STUDY_REPORT, "an evaluation run's eval.csv with a space after each comma",
     (spoil(f"{EV_RUN}/eval.csv", SPACES),), "eval.csv", True),
    (STUDY_REPORT, "an evaluation run's eval.csv with a comment line first",
     (spoil(f"{EV_RUN}/eval.csv", COMMENT_FIRST),), "eval.csv"),
]  # fmt: skip

MG_REPORT = ["report", "--archive", "mg"]
MGT_SELECT = ["select", "--archive", "mgt"]
MGT_RUN_ARGV = ["run", "--archive", "mgt", "--work-dir", "wd"]
MGT_STUDY = ["run", "mgt/spec.json", "--study-dir", "s", "--archive", "mgt", "--resume"]
ARM = "MiniGrid-DoorKey-6x6-v0/rnd,normalization=paper,scale=0.1/s100"
MGT_PART = f"mgt/{ARM}/checkpoint.pt"  # an in-progress run's checkpoint in the archive


def work_dir_checkpoint(here: Path) -> None:
    """The in-progress run's checkpoint in the work directory (``wd/runs/...``), cut in half."""
    data = (here / MGT_PART).read_bytes()
    (here / f"wd/runs/{ARM}").mkdir(parents=True)
    (here / f"wd/runs/{ARM}/checkpoint.pt").write_bytes(data[: len(data) // 2])


def mgt_light(here: Path) -> None:
    """``mgt`` without its in-progress checkpoints (large), for the commands that do not read
    them."""
    shutil.copytree(STUDIES / "minigrid-v2/tuning", here / "mgt",
                    ignore=shutil.ignore_patterns("checkpoint.pt"))  # fmt: skip


# the MiniGrid archives: (command, argv, what, works, names[, valid])
MINIGRID_CASES = [
    ("minigrid", MGT_RUN_ARGV, "an in-progress run's checkpoint.pt cut in half",
     (MGT, spoil(MGT_PART, HALF)), "checkpoint.pt"),
    ("minigrid", MGT_RUN_ARGV, "an in-progress run's checkpoint.pt empty",
     (MGT, spoil(MGT_PART, b"")), "checkpoint.pt"),
    ("minigrid", MGT_RUN_ARGV, "an in-progress run's checkpoint.pt in --work-dir cut in half",
     (MGT, work_dir_checkpoint), "checkpoint.pt"),
    ("study", MGT_STUDY, "an in-progress run's checkpoint.pt zero-filled",
     (MGT, spoil(MGT_PART, lambda p: p.write_bytes(bytes(p.stat().st_size)))), "checkpoint.pt"),
    ("minigrid", MGT_SELECT, "an in-progress run's checkpoint.pt cut in half",
     (MGT, spoil(MGT_PART, HALF)), "", True),
    ("minigrid", MGT_RUN_ARGV, "a finished run's summary.json with a trailing comma",
     (mgt_light, spoil(f"{MGT_RUN}/summary.json", TRAILING_COMMA)), "summary.json"),
    ("minigrid", MG_REPORT, "report a file", (MG, removed("mg/report"), add("mg/report")),
     "report"),
    ("minigrid", MG_REPORT, "report/report.md a folder",
     (MG, removed("mg/report/report.md"), folder("mg/report/report.md")), "report.md"),
    ("study", ["report", "mg/spec.json", "--study-dir", "mg"], "report a file",
     (MG, removed("mg/report"), add("mg/report")), "report"),
    ("minigrid", MGT_RUN_ARGV, "an in-progress run's checkpoint.pt a link to another machine's",
     (MGT, dangling(MGT_PART)), "checkpoint.pt"),
    ("minigrid", MGT_RUN_ARGV, "an in-progress run's checkpoint.pt a folder",
     (MGT, removed(MGT_PART), folder(MGT_PART)), "checkpoint.pt"),
    ("minigrid", MGT_SELECT, "selection.md a folder", (mgt_light, folder("mgt/selection.md")),
     "selection.md"),
    ("minigrid", MG_REPORT, "a run's eval.csv with a space after each comma",
     (MG, spoil(f"{MG_RUN}/eval.csv", SPACES)), "eval.csv", True),
    ("minigrid", MG_REPORT, "a run's eval.csv saved as UTF-16",
     (MG, spoil(f"{MG_RUN}/eval.csv", utf16)), "eval.csv"),
    ("minigrid", MG_REPORT, "a run's eval.csv with its header line deleted",
     (MG, spoil(f"{MG_RUN}/eval.csv", NO_HEADER)), "eval.csv"),
    ("minigrid", MGT_SELECT, "a run's final_success_rate written as a percentage (100)",
     (mgt_light, spoil(f"{MGT_RUN}/summary.json",
                       edit_json(lambda d: d.update(final_success_rate=100.0)))),
     ("summary.json", "final_success_rate")),
    ("minigrid", MGT_SELECT, "a run's eval.csv with a comment line first",
     (mgt_light, spoil(f"{MGT_RUN}/eval.csv", COMMENT_FIRST)), "eval.csv"),
    ("minigrid", MG_REPORT, "a run's eval.csv without its final newline",
     (MG, spoil(f"{MG_RUN}/eval.csv", NO_FINAL_NEWLINE)), "", True),
]  # fmt: skip

# the Python API's loaders, in a case directory beside the tiny run (../tiny)
RUN = "import shutil; shutil.copytree('../tiny', 'run'); "
LOAD = RUN + "from simoun_agent.run.load import load_run; "
CSV = RUN + "from simoun_agent.run.logger import read_csv, read_log; "
CKPT = RUN + "from simoun_agent.run.checkpoint import load_checkpoint; "
SWEEP = (RUN + "from pathlib import Path; import reliability_trial as t; t.sweep_dir(Path('.')); "
         "from simoun_lab.sweep.grid import SweepSpec; ")  # fmt: skip
MG_SPEC = "from pathlib import Path; from simoun_lab.minigrid_study.spec import load_spec; "
HALVE = "p = Path('run/checkpoint.pt'); p.write_bytes(p.read_bytes()[:1000]); "
LR = ("import json; from pathlib import Path; p = Path('run/config.json'); c = json.loads("
      "p.read_text()); c['agent']['lr'] = 0.01; p.write_text(json.dumps(c)); ")  # fmt: skip
CUT = "from pathlib import Path; p = Path('run/eval.csv'); p.write_text(p.read_text()[:-30]); "
HASH = ("from pathlib import Path; p = Path('run/eval.csv'); "
        "p.write_text('# n\\n' + p.read_text()); ")  # fmt: skip
API_CASES = [
    api(LOAD + "r = load_run('run'); assert r.env_step == 40", "", True),
    api(LOAD + "from pathlib import Path; load_run(Path('run/checkpoint.pt'), device='cpu')", "",
        True),
    api(LOAD + "load_run('run', device='cuda')", ("cuda", "device")),
    api(LOAD + "load_run('run', device='gpu')", ("gpu", "device")),
    api(LOAD + "load_run('run', torch_threads=0)", "torch_threads"),
    api(LOAD + "load_run('run/config.json')", ("config.json", "checkpoint")),
    api(LOAD + "load_run('runs/pointreach-s1')", "runs/pointreach-s1"),
    api(LOAD + "from pathlib import Path; " + HALVE + "load_run('run')", "checkpoint.pt"),
    api(LOAD + LR + "load_run('run')", ("lr", "config.json")),
    api(CSV + "rows = read_csv('run/eval.csv'); assert rows[-1]['env_step'] == 40", "", True),
    api(CSV + HASH + "read_csv(p)", ("eval.csv", "comment")),
    api(CSV + "from pathlib import Path; read_csv(Path('run/summary.json'))", "summary.json"),
    api(CSV + "from pathlib import Path; read_csv(Path('run'))", "run"),
    api(CSV + "from pathlib import Path; p = Path('run/train.csv'); "
        "p.write_bytes(p.read_text().encode('utf-16')); read_log(p)", "train.csv"),
    api(CSV + "from pathlib import Path; p = Path('run/eval.csv'); "
        "p.write_text(p.read_text().split(chr(10), 1)[1]); read_csv(p)", "eval.csv"),
    api(CSV + CUT + "read_log(Path('run/eval.csv'))", "eval.csv"),
    api(CKPT + "p = load_checkpoint('run/checkpoint.pt'); assert p['state']['env_step'] == 40", "",
        True),
    api(CKPT + "load_checkpoint('run/replay-40.npz')", "replay-40.npz"),
    api(CKPT + "load_checkpoint('run/config.json')", "config.json"),
    api(CKPT + "load_checkpoint('run')", "", True),
    api(CKPT + "open('run/checkpoint.pt', 'w').close(); load_checkpoint('run/checkpoint.pt')",
        "checkpoint.pt"),
    api(LOAD + "import os; os.remove('run/checkpoint.pt'); os.mkdir('run/checkpoint.pt'); "
        "load_run('run')", "checkpoint.pt"),
    api(SWEEP + "SweepSpec.load(Path('sw'))", "", True),
    api(SWEEP + "p = Path('sw/sweep.json'); p.write_text(p.read_text()[:40]); SweepSpec.load("
        "Path('sw'))", "sweep.json"),
    api(SWEEP + "SweepSpec.load(Path('sw/sweep.json'))", "sweep.json", True),
    api(SWEEP + "SweepSpec.load(Path('run'))", "sweep.json"),
    api(MG_SPEC + f"load_spec(Path({str(STUDIES / 'dmc100k/study.json')!r}))", "study.json"),
    api(MG_SPEC + f"load_spec(Path({str(STUDIES / 'minigrid')!r}))", ("minigrid", "spec.json")),
]  # fmt: skip

CASES: list[dict] = [
    *RUN_TIDIED,
    *RUN_OUTPUTS,
    *(fifth("files", command, argv, names, *ok, works=works, what=what)
      for command, argv, what, works, names, *ok in SWEEP_CASES + MINIGRID_CASES),
    *(fifth("files", "study", argv, names, *ok, works=(ARCH, DMC100K, *works), what=what)
      for argv, what, works, names, *ok in STUDY_CASES),
    *({**case, "area": "files"} for case in API_CASES),
]  # fmt: skip
