"""The eleventh reliability trial's cases: files (see reliability_trial.py).

Kept files as other users, other operating systems and other download tools leave them, on every
command that reads them. Permissions, which earlier trials could not try as root: each such
case drops root's capabilities and goes on as an ordinary user who owns its directory, with a
kept file another user's, mode 600, as ``sudo cp`` leaves it (checkpoint.pt, config.json,
eval.csv, the replay, summary.json, .lock, study.json, sweep.json, an in-progress MiniGrid
checkpoint), or a run, a sweep, an archive, the folder beside a run or an existing ``--out``,
``--work-dir`` or ``--study-dir`` another user's (readable, not writable) for the commands that
write there, a colleague's run private (mode 700) in a folder of runs, a study archive and
a MiniGrid archive; and the valid ways round it (``--out`` elsewhere, a report written beside a
read-only run, files made read-only with ``chmod a-w``, a teammate's selection written again,
evaluating past another user's .lock, ``load_run`` of a read-only run). Writes that fail
part-way: a file size limit (``ulimit -f``, a quota nearly used up) under the figures of
simoun-report (a run, a sweep), ``simoun-study report``, the MiniGrid report and
``simoun-analyze masks``. File names as a case-insensitive or Windows file system leaves them
(``Config.json``, ``Checkpoint.pt``, ``EVAL.CSV``, a trailing blank, ``config.json.json``, a
task's or a recipe's folder in other capitals, a trial ``S1``). A kept file that is not what
its name says: GitHub's HTML page saved by ``wget`` of the blob URL (eval.csv, config.json,
checkpoint.pt, train.csv, a spec, sweep.json, update_cost.json, a MiniGrid run's config.json
and in-progress checkpoint), its bytes gzip-compressed under its own name, JSON written as a
Python dict's repr, CSV with tabs (a spreadsheet's text export under .csv), a spreadsheet
workbook saved over a CSV log, typographic quotes typed by macOS TextEdit or pasted from a
document (sweep.json, config.json, the specs), a symbolic link to itself (a loop). Spec files
under other names and encodings (``dmc100k.toml.txt`` as Notepad saves it, ``DMC100K.TOML``, a
byte-order mark, a Latin-1 comment; the MiniGrid spec as TOML with the same keys, given to
``--spec`` and to simoun-study, and as ``spec.json.txt``). Valid leftovers of other tools: a
``.git/`` in an archive, an rsync partial file, a report written into the run with ``--out``, a
replay moved to a scratch disk and linked back, a folder of runs holding a relative link, a
reindented study.json, values in exponent notation, a summary saved as UTF-16. The loaders from
Python: the SAC study's ``simoun_lab.study.spec.load_spec`` (no earlier trial reached it) given
a BOM, UTF-16, a directory, the archive's study.json, a MiniGrid spec, merge-conflict markers
and an HTML page; the MiniGrid ``load_spec`` given its TOML form; ``read_csv``,
``SweepSpec.load``, ``load_run`` and ``load_checkpoint`` given tabs, a repr, a gzipped
checkpoint and files another user owns or a read-only run.
"""

from __future__ import annotations

import gzip
import json
import os
import resource
import shutil
import signal
import subprocess
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
    folder,
    mgt_light,
    renamed,
    run_file,
)
from reliability_tenth_files import (  # the tenth trial's case helpers, shared
    TASK,
    in_progress_checkpoint,
    utf16,
)
from reliability_trial import (
    ARCH,
    DMC100K,
    EV_RUN,
    MG,
    MG_RUN,
    MGT,
    MGT_RUN,
    SPEC,
    STUDIES,
    SW,
    SW_RUN,
    api,
    bom,
    edit_text,
    fifth,
    put,
    spoil,
)

NOBODY = 65534  # the unprivileged user every Linux system has: here, the other user


def without_capabilities() -> None:
    """This process (and what it starts) as an ordinary user: root's capabilities dropped, so
    that file modes bite as they do for any user who owns the case's files. (A switch to
    another user instead would also lose this machine's Python, which lives under /root.)"""
    import ctypes

    libc = ctypes.CDLL(None, use_errno=True)
    for capability in range(64):  # from the bounding set too: no program started gets them back
        libc.prctl(24, capability, 0, 0, 0)  # PR_CAPBSET_DROP; past the last one it fails

    class Header(ctypes.Structure):
        _fields_ = [("version", ctypes.c_uint32), ("pid", ctypes.c_int)]

    class Sets(ctypes.Structure):
        _fields_ = [(name, ctypes.c_uint32) for name in ("effective", "permitted", "inherited")]

    if libc.capset(ctypes.byref(Header(0x20080522, 0)), (Sets * 2)()) != 0:
        raise OSError(ctypes.get_errno(), "capset: the case cannot run as an ordinary user")


def another_users(path: Path, mode: int | None = None) -> None:
    """``path`` (and all below it) made ``nobody``'s: readable and not writable by the user,
    or as ``mode`` says (of ``path`` itself)."""
    for each in [path, *(path.rglob("*") if path.is_dir() else ())]:
        os.lchown(each, NOBODY, NOBODY)
    if mode is not None:
        os.chmod(path, mode)


def as_user(files=(), trees=(), folders=(), protected=(), shared=(), private=()):
    """Work (the case's last): the case goes on as an ordinary user who owns its directory.
    ``files``: another user's, mode 600 (as ``sudo cp`` leaves a file for root); ``trees``:
    another user's, readable, not writable (another user's folder, a read-only share);
    ``folders``: that folder alone another user's; ``protected``: made read-only by the user
    (``chmod a-w``); ``shared``: another user's, readable by all (a teammate's file);
    ``private``: folders another user's, mode 700 (a colleague's run in a shared folder)."""

    def work(here: Path) -> None:
        for name in trees:
            another_users(here / name)
        for name in folders:
            os.lchown(here / name, NOBODY, NOBODY)
        for name in files:
            another_users(here / name, 0o600)
        for name in protected:
            os.chmod(here / name, 0o444)
        for name in shared:
            another_users(here / name, 0o444)
        for name in private:
            another_users(here / name, 0o700)
        without_capabilities()

    return work


def file_size_limit(here: Path) -> None:
    """Work (the case's last): files can grow to 10 kB only (``ulimit -f 10``, as on a login
    node; a write past it fails as a full disk's does, with the signal ignored as a shell's
    ``trap '' XFSZ`` leaves it)."""
    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
    # the study report's provenance runs ``git status`` in the checkout running the trial,
    # which would refresh its index under the limit and leave a stale index.lock there
    os.environ["GIT_OPTIONAL_LOCKS"] = "0"
    resource.setrlimit(resource.RLIMIT_FSIZE, (10_000, 10_000))


def smart_quotes(key: str):
    """Edit: ``key``'s quotes made typographic, as macOS TextEdit types them by default."""
    return edit_text(lambda text: text.replace(f'"{key}"', f"\u201c{key}\u201d", 1))


def replay_name(here: Path) -> str:
    """The run's replay file, relative to the case's directory."""
    return str(next((here / "run").glob("replay-*.npz")).relative_to(here))


def replay_theirs(here: Path) -> None:
    as_user(files=(replay_name(here),))(here)


def checkpoint_theirs(here: Path) -> None:
    as_user(files=(str(in_progress_checkpoint(here).relative_to(here)),))(here)


HTML = (
    '<!DOCTYPE html>\n<html lang="en" data-color-mode="auto">\n<head>\n<meta charset="utf-8">\n'
    "<title>runs/pointreach-s1 at main</title>\n</head>\n<body>\n"
    '<div class="application-main">Blob view</div>\n</body>\n</html>\n'
)


def html_page(path: Path) -> None:
    """The file as ``wget`` of its GitHub page (not the raw file) leaves it: the page's HTML."""
    path.write_text(HTML)


def gzipped_in_place(path: Path) -> None:
    """The file's bytes gzip-compressed under its own name (a download without
    ``--compressed`` from a server that sent it gzip-encoded)."""
    path.write_bytes(gzip.compress(path.read_bytes()))


def python_repr(path: Path) -> None:
    """The JSON file rewritten as ``str(dict)`` writes it (single quotes, True, None)."""
    path.write_text(repr(json.loads(path.read_text())) + "\n")


def spreadsheet_workbook(path: Path) -> None:
    """The CSV log saved over itself as a spreadsheet workbook (a zip of XML), name kept."""
    with zipfile.ZipFile(path, "w") as book:
        book.writestr("[Content_Types].xml", '<?xml version="1.0"?><Types/>')
        book.writestr("xl/workbook.xml", '<?xml version="1.0"?><workbook/>')


def self_link(path: Path) -> None:
    """The file a symbolic link to itself (``ln -sf`` with the link's own name)."""
    path.unlink()
    path.symlink_to(path.name)


TABS = edit_text(lambda text: text.replace(",", "\t"))


def exponents(text: str) -> str:
    """The CSV log with every value but the step in exponent notation (exact, 17 digits), as a
    tool that formats floats with ``%e`` writes it."""
    lines = text.splitlines()
    rows = [line.split(",") for line in lines[1:]]
    written = [[row[0], *(f"{float(c):.16e}" if c else c for c in row[1:])] for row in rows]
    return "\n".join([lines[0], *(",".join(row) for row in written)]) + "\n"


EXPONENTS = edit_text(exponents)
LATIN1_COMMENT = "# réglages de l'équipe (Chloé)\n".encode("latin-1") + SPEC.encode()
REINDENT = edit_text(lambda text: json.dumps(json.loads(text), indent=1, sort_keys=True) + "\n")


def toml_of_spec(text: str) -> str:
    """The MiniGrid JSON spec ``text`` written as TOML with the same keys."""

    def value(v) -> str:
        if isinstance(v, str):
            return json.dumps(v)
        if isinstance(v, list):
            return "[" + ", ".join(value(x) for x in v) + "]"
        return repr(v).lower() if isinstance(v, bool) else repr(v)

    spec = json.loads(text)
    lines = [f"{k} = {value(v)}" for k, v in spec.items() if not isinstance(v, dict | list)
             or (isinstance(v, list) and not (v and isinstance(v[0], dict)))]  # fmt: skip
    for key, v in spec.items():
        if isinstance(v, list) and v and isinstance(v[0], dict):
            for item in v:
                lines += ["", f"[[{key}]]", *(f"{k} = {value(x)}" for k, x in item.items())]
        elif isinstance(v, dict):
            lines += ["", f"[{key}]", *(f"{k} = {value(x)}" for k, x in v.items())]
    return "\n".join(lines) + "\n"


def spec_as_toml(source: str, target: str):
    """Work: the archive's spec ``source`` written as TOML into ``target``."""
    return lambda here: (here / target).write_text(toml_of_spec((here / source).read_text()))


def git_init(name: str):
    """Work: ``name`` made a git repository (``git init``), as a user versioning results does."""
    return lambda here: subprocess.run(["git", "init", "-q", str(here / name)], check=True)


def rsync_partial(here: Path) -> None:
    """The partial file an interrupted ``rsync --partial-dir``-less copy leaves beside a file."""
    data = (here / "run/checkpoint.pt").read_bytes()
    (here / "run/.checkpoint.pt.Xq3v9Z").write_bytes(data[: len(data) // 3])


def replay_on_scratch(here: Path) -> None:
    """The replay moved to a scratch disk (here ``scratch/``) and linked back (absolute)."""
    (here / "scratch").mkdir()
    source = next((here / "run").glob("replay-*.npz"))
    shutil.move(source, here / "scratch" / source.name)
    source.symlink_to(here / "scratch" / source.name)


def report_into_run(here: Path) -> None:
    """A report written into the run itself (``simoun-report run --out run``)."""
    from simoun_lab.cli import report

    assert report.main([str(here / "run"), "--out", str(here / "run")]) == 0


def relative_run_link(here: Path) -> None:
    """``runs/pointreach-s1``: a relative link to the run (``ln -s ../run runs/...``)."""
    (here / "runs").mkdir()
    (here / "runs/pointreach-s1").symlink_to("../run")


def shared_runs(here: Path) -> None:
    """``runs/``: the user's run and a colleague's copy of it, the colleague's private."""
    (here / "runs").mkdir()
    shutil.copytree(here / "run", here / "runs/colleague-s2")
    shutil.move(here / "run", here / "runs/mine-s1")
    as_user(private=("runs/colleague-s2",))(here)


def teammates_selection(here: Path) -> None:
    """mgt/selection.json and .md a teammate's select wrote: theirs, readable by all; the
    rest the user's."""
    from simoun_lab.minigrid_study import __main__ as minigrid

    assert minigrid.main(["select", "--archive", str(here / "mgt")]) == 0
    as_user(shared=("mgt/selection.json", "mgt/selection.md"))(here)


PERMS = ("Permission", "permission", "not writable", "read-only", "writable")
EVAL = ["{run}", "--episodes", "1", "--no-video"]
RESUME = ["--resume", "{run}", "--total-env-steps", "60"]
MASKS = ["masks", "{run}", "--steps", "1"]
BIAS = ["bias", "{run}", "--pairs", "8", "--out", "b"]
SW_REPORT, SW_RESUME = ["sw"], ["--resume", "--sweep-dir", "sw"]
SUDO = "another user's, mode 600 (as sudo cp leaves it), read as a user"

# permissions: another user's files and read-only folders, as a user (command, argv, what,
# works, names[, valid])
PERMISSION_CASES = [
    ("eval", EVAL, f"checkpoint.pt {SUDO}", (as_user(files=("run/checkpoint.pt",)),),
     "checkpoint.pt"),
    ("train", RESUME, f"config.json {SUDO}", (as_user(files=("run/config.json",)),),
     "config.json"),
    ("report", ["{run}"], f"eval.csv {SUDO}", (as_user(files=("run/eval.csv",)),), "eval.csv"),
    ("report", ["{run}"], f"summary.json {SUDO}", (as_user(files=("run/summary.json",)),),
     "summary.json"),
    ("analyze", MASKS, f"the replay {SUDO}", (replay_theirs,), "replay"),
    ("analyze", BIAS, f"config.json {SUDO}", (as_user(files=("run/config.json",)),),
     "config.json"),
    ("train", RESUME, "the run another user's folder (read-only), resumed",
     (as_user(trees=("run",)),), PERMS),
    ("eval", EVAL, "the run another user's folder (read-only), evaluated into it",
     (as_user(trees=("run",)),), ("--out", *PERMS)),
    ("analyze", MASKS, "the run another user's folder (read-only), masks written into it",
     (as_user(trees=("run",)),), ("--out", *PERMS)),
    ("report", ["{run}"], "the folder holding the run read-only (report-run cannot be made)",
     (as_user(folders=(".",)),), ("--out", *PERMS)),
    ("report", SW_REPORT, "the sweep another user's folder (read-only), reported into it",
     (SW, as_user(trees=("sw",))), ("--out", *PERMS)),
    ("sweep", SW_RESUME, "the sweep another user's folder (read-only), resumed",
     (SW, as_user(trees=("sw",))), PERMS),
    ("sweep", SW_RESUME, f"sweep.json {SUDO}", (SW, as_user(files=("sw/sweep.json",))),
     "sweep.json"),
    ("sweep", SW_RESUME, f"a finished trial's summary.json {SUDO}",
     (SW, as_user(files=(f"{SW_RUN}/summary.json",))), "summary.json"),
    ("study", STUDY_REPORT, "the archive another user's folder (read-only), reported into it",
     (ARCH, DMC100K, as_user(trees=("arch",))), PERMS),
    ("study", STUDY_REPORT, f"study.json {SUDO}",
     (ARCH, DMC100K, as_user(files=("arch/study.json",))), "study.json"),
    ("study", STUDY_RESUME, f"the archive's study.json {SUDO}, on run --resume",
     (ARCH, DMC100K, as_user(files=("arch/study.json",))), "study.json"),
    ("minigrid", MG_REPORT, f"a run's summary.json {SUDO}",
     (MG, as_user(files=(f"{MG_RUN}/summary.json",))), "summary.json"),
    ("minigrid", MG_REPORT, "report/ another user's folder (read-only)",
     (MG, as_user(trees=("mg/report",))), PERMS),
    ("minigrid", MGT_SELECT, "the tuning archive another user's folder (read-only)",
     (mgt_light, as_user(trees=("mgt",))), PERMS),
    ("minigrid", MGT_SELECT, f"a run's eval.csv {SUDO}",
     (mgt_light, as_user(files=(f"{MGT_RUN}/eval.csv",))), "eval.csv"),
    ("minigrid", MGT_RUN_ARGV, f"an in-progress run's checkpoint.pt {SUDO}",
     (MGT, checkpoint_theirs), "checkpoint.pt"),
    ("report", ["{run}", "--out", "o"], "--out an existing folder of another user's",
     (folder("o"), as_user(folders=("o",))), ("--out", *PERMS)),
    ("eval", [*EVAL, "--out", "o"], "--out an existing folder of another user's",
     (folder("o"), as_user(folders=("o",))), ("--out", *PERMS)),
    ("analyze", BIAS, "--out an existing folder of another user's",
     (folder("b"), as_user(folders=("b",))), ("--out", *PERMS)),
    ("minigrid", MGT_RUN_ARGV, "--work-dir an existing folder of another user's",
     (mgt_light, folder("wd"), as_user(folders=("wd",))), ("--work-dir", *PERMS)),
    ("study", STUDY_RESUME, "--study-dir an existing folder of another user's, on run --resume",
     (ARCH, DMC100K, folder("s"), as_user(folders=("s",))), ("--study-dir", *PERMS)),
    ("report", ["runs"], "a folder of runs shared with a colleague whose run is private (700)",
     (shared_runs,), "colleague-s2"),
    ("study", STUDY_REPORT, "an evaluation run a colleague's private folder (700)",
     (ARCH, DMC100K, as_user(private=(EV_RUN,))), "cartpole-swingup/s1"),
    ("minigrid", MG_REPORT, "a run a colleague's private folder (700)",
     (MG, as_user(private=(MG_RUN,))), "ppo/s0"),
    ("train", RESUME, f".lock {SUDO} (a trainer once run with sudo)",
     (as_user(files=("run/.lock",)),), ".lock"),
    # valid: the ways round a read-only folder, and files a user protected
    ("eval", EVAL, f".lock {SUDO} (a trainer once run with sudo), evaluated",
     (as_user(files=("run/.lock",)),), ".lock", True),
    ("eval", [*EVAL, "--out", "o"], "the run read-only, evaluated with --out elsewhere",
     (as_user(trees=("run",)),), "", True),
    ("report", ["{run}"], "the run read-only (the report goes beside it)",
     (as_user(trees=("run",)),), "", True),
    ("report", ["sw", "--out", "o"], "the sweep read-only, reported with --out elsewhere",
     (SW, as_user(trees=("sw",))), "", True),
    ("train", RESUME, "checkpoint.pt and config.json made read-only (chmod a-w), resumed",
     (as_user(protected=("run/checkpoint.pt", "run/config.json")),), "", True),
    ("minigrid", MGT_SELECT, "selection.json a teammate's (theirs, read-only), selected again",
     (mgt_light, teammates_selection), "selection.json", True),
]  # fmt: skip

LIMITED = ("File too large", "too large", "space", "quota")
# writes that fail part-way (a file size limit): (command, argv, what, works, names)
LIMIT_CASES = [
    ("report", ["{run}"], "files limited to 10 kB (ulimit -f): the report's figures fail",
     (file_size_limit,), LIMITED),
    ("report", SW_REPORT, "files limited to 10 kB (ulimit -f): the sweep's figures fail",
     (SW, file_size_limit), LIMITED),
    ("study", STUDY_REPORT, "files limited to 10 kB (ulimit -f): the study's figures fail",
     (ARCH, DMC100K, file_size_limit), LIMITED),
    ("minigrid", MG_REPORT, "files limited to 10 kB (ulimit -f): the MiniGrid figures fail",
     (MG, file_size_limit), LIMITED),
    ("analyze", MASKS, "files limited to 10 kB (ulimit -f): the masks' PNGs fail",
     (file_size_limit,), LIMITED),
]  # fmt: skip

# names as a case-insensitive or Windows file system leaves them
NAME_CASES = [
    ("eval", EVAL, "config.json renamed Config.json (a copy through a Windows share)",
     (renamed("run/config.json", "run/Config.json"),), "config.json"),
    ("train", RESUME, "checkpoint.pt renamed Checkpoint.pt (a copy through a Windows share)",
     (renamed("run/checkpoint.pt", "run/Checkpoint.pt"),), "checkpoint.pt"),
    ("report", ["{run}"], "eval.csv renamed EVAL.CSV (a FAT-formatted USB stick)",
     (renamed("run/eval.csv", "run/EVAL.CSV"),), "eval.csv"),
    ("eval", EVAL, "config.json renamed 'config.json ' (a trailing blank)",
     (renamed("run/config.json", "run/config.json "),), "config.json"),
    ("train", RESUME, "config.json renamed config.json.json (Explorer's hidden extension)",
     (renamed("run/config.json", "run/config.json.json"),), "config.json"),
    ("minigrid", MG_REPORT, "a task's folder in lower case (minigrid-doorkey-6x6-v0)",
     (MG, renamed(f"mg/{TASK}", f"mg/{TASK.lower()}")), (TASK, TASK.lower())),
    ("study", STUDY_REPORT, "the evaluation's recipe folder renamed Simoun",
     (ARCH, DMC100K, renamed("arch/evaluation/simoun", "arch/evaluation/Simoun")),
     ("Simoun", "evaluation/simoun")),
    ("analyze", MASKS, "config.json renamed Config.json (a copy through a Windows share)",
     (renamed("run/config.json", "run/Config.json"),), "config.json"),
    ("sweep", SW_RESUME, "the trial s1 renamed S1",
     (SW, renamed(SW_RUN, SW_RUN[:-2] + "S1")), ("S1", "s1")),
]  # fmt: skip

SW_TRIAL_EVAL = f"{SW_RUN}/eval.csv"
# downloads, compressions, reprs, tabs and links: a kept file not what its name says
CONTENT_CASES = [
    ("report", ["{run}"], "eval.csv a GitHub page's HTML (wget of the blob URL)",
     (run_file("eval.csv", html_page),), "eval.csv"),
    ("eval", EVAL, "config.json a GitHub page's HTML (wget of the blob URL)",
     (run_file("config.json", html_page),), "config.json"),
    ("eval", EVAL, "checkpoint.pt a GitHub page's HTML (wget of the blob URL)",
     (run_file("checkpoint.pt", html_page),), "checkpoint.pt"),
    ("study", STUDY_REPORT, "the spec a GitHub page's HTML (wget of the blob URL)",
     (ARCH, DMC100K, spoil("dmc100k.toml", html_page)), "dmc100k.toml"),
    ("minigrid", [*MG_REPORT, "--spec", "spec.json"], "--spec a GitHub page's HTML",
     (MG, put("spec.json", HTML)), "spec.json"),
    ("report", SW_REPORT, "sweep.json a GitHub page's HTML", (SW, spoil("sw/sweep.json",
     html_page)), "sweep.json"),
    ("minigrid", MGT_SELECT, "a run's eval.csv a GitHub page's HTML",
     (mgt_light, spoil(f"{MGT_RUN}/eval.csv", html_page)), "eval.csv"),
    ("study", STUDY_REPORT, "update_cost.json a GitHub page's HTML",
     (ARCH, DMC100K, add(COSTS, HTML)), "update_cost.json"),
    ("sweep", SW_RESUME, "sweep.json edited in TextEdit (typographic quotes round seeds)",
     (SW, spoil("sw/sweep.json", smart_quotes("seeds"))), "sweep.json"),
    ("eval", EVAL, "config.json edited in TextEdit (typographic quotes round seed)",
     (run_file("config.json", smart_quotes("seed")),), "config.json"),
    ("train", RESUME, "train.csv a GitHub page's HTML (wget of the blob URL)",
     (run_file("train.csv", html_page),), "train.csv"),
    ("minigrid", MGT_RUN_ARGV, "an in-progress run's checkpoint.pt a GitHub page's HTML",
     (MGT, lambda here: html_page(in_progress_checkpoint(here))), "checkpoint.pt"),
    ("sweep", SW_RESUME, "a finished trial's summary.json written as a Python dict",
     (SW, spoil(f"{SW_RUN}/summary.json", python_repr)), "summary.json"),
    ("report", ["{run}"], "eval.csv saved over by a spreadsheet as a workbook (name kept)",
     (run_file("eval.csv", spreadsheet_workbook),), "eval.csv"),
    ("report", ["{run}"], "eval.csv gzip-compressed under its own name",
     (run_file("eval.csv", gzipped_in_place),), "eval.csv"),
    ("train", RESUME, "config.json gzip-compressed under its own name",
     (run_file("config.json", gzipped_in_place),), "config.json"),
    ("report", SW_REPORT, "sweep.json written as a Python dict (single quotes)",
     (SW, spoil("sw/sweep.json", python_repr)), "sweep.json"),
    ("report", ["{run}"], "summary.json written as a Python dict (single quotes)",
     (run_file("summary.json", python_repr),), "summary.json"),
    ("study", STUDY_REPORT, "an evaluation run's config.json written as a Python dict",
     (ARCH, DMC100K, spoil(f"{EV_RUN}/config.json", python_repr)), "config.json"),
    ("minigrid", MG_REPORT, "spec.json written as a Python dict (single quotes)",
     (MG, spoil("mg/spec.json", python_repr)), "spec.json"),
    ("report", ["{run}"], "eval.csv tab-separated (a spreadsheet's text export under .csv)",
     (run_file("eval.csv", TABS),), "eval.csv"),
    ("train", RESUME, "eval.csv tab-separated (a spreadsheet's text export under .csv)",
     (run_file("eval.csv", TABS),), "eval.csv"),
    ("minigrid", MG_REPORT, "a run's eval.csv tab-separated",
     (MG, spoil(f"{MG_RUN}/eval.csv", TABS)), "eval.csv"),
    ("study", STUDY_REPORT, "an evaluation run's eval.csv tab-separated",
     (ARCH, DMC100K, spoil(f"{EV_RUN}/eval.csv", TABS)), "eval.csv"),
    ("sweep", SW_RESUME, "a finished trial's eval.csv tab-separated",
     (SW, spoil(SW_TRIAL_EVAL, TABS)), "eval.csv"),
    ("eval", EVAL, "config.json a symbolic link to itself (a loop)",
     (run_file("config.json", self_link),), "config.json"),
    ("report", SW_REPORT, "sweep.json a symbolic link to itself (a loop)",
     (SW, spoil("sw/sweep.json", self_link)), "sweep.json"),
    ("study", STUDY_REPORT, "study.json a symbolic link to itself (a loop)",
     (ARCH, DMC100K, spoil("arch/study.json", self_link)), "study.json"),
    ("minigrid", MG_REPORT, "a run's summary.json a symbolic link to itself (a loop)",
     (MG, spoil(f"{MG_RUN}/summary.json", self_link)), "summary.json"),
    ("train", RESUME, "train.csv a symbolic link to itself (a loop)",
     (run_file("train.csv", self_link),), "train.csv"),
    ("eval", EVAL, "checkpoint.pt a symbolic link to itself (a loop)",
     (run_file("checkpoint.pt", self_link),), "checkpoint.pt"),
    ("train", RESUME, "checkpoint.pt gzip-compressed under its own name",
     (run_file("checkpoint.pt", gzipped_in_place),), "checkpoint.pt"),
    ("sweep", SW_RESUME, "sweep.json gzip-compressed under its own name",
     (SW, spoil("sw/sweep.json", gzipped_in_place)), "sweep.json"),
    ("minigrid", MG_REPORT, "a run's config.json a GitHub page's HTML",
     (MG, spoil(f"{MG_RUN}/config.json", html_page)), "config.json"),
    ("report", SW_REPORT, "a trial's config.json a GitHub page's HTML",
     (SW, spoil(f"{SW_RUN}/config.json", html_page)), "config.json"),
    ("study", STUDY_REPORT, "an evaluation run's summary.json written as a Python dict",
     (ARCH, DMC100K, spoil(f"{EV_RUN}/summary.json", python_repr)), "summary.json"),
    ("minigrid", MGT_SELECT, "a run's summary.json written as a Python dict",
     (mgt_light, spoil(f"{MGT_RUN}/summary.json", python_repr)), "summary.json"),
    ("study", STUDY_REPORT, "the spec's recipes in typographic quotes (pasted from a document)",
     (ARCH, put("dmc100k.toml", SPEC.replace('"simoun"', "\u201csimoun\u201d", 1))),
     "dmc100k.toml"),
    ("minigrid", [*MG_REPORT, "--spec", "spec.json"],
     "--spec with an arm in typographic quotes (pasted from a document)",
     (MG, lambda here: (here / "spec.json").write_text(
         (here / "mg/spec.json").read_text().replace('"ppo"', "\u201cppo\u201d", 1))),
     "spec.json"),
]  # fmt: skip

MG_SPEC_FLAG = [*MG_REPORT, "--spec"]
# spec files under other names and encodings: (command, argv, what, works, names[, valid])
SPEC_FILE_CASES = [
    ("study", ["report", "dmc100k.toml.txt", "--study-dir", "arch"],
     "the spec saved by Notepad as dmc100k.toml.txt", (ARCH, put("dmc100k.toml.txt", SPEC)),
     "dmc100k.toml.txt", True),
    ("study", ["report", "DMC100K.TOML", "--study-dir", "arch"],
     "the spec named in capitals (DMC100K.TOML, a FAT-formatted stick)",
     (ARCH, put("DMC100K.TOML", SPEC)), ("DMC100K", "dmc100k"), True),
    ("study", STUDY_REPORT, "the spec with a UTF-8 byte-order mark (Notepad)",
     (ARCH, DMC100K, spoil("dmc100k.toml", bom)), "", True),
    ("study", STUDY_REPORT, "the spec with a comment in Latin-1 (an editor set to ISO-8859-1)",
     (ARCH, put("dmc100k.toml", LATIN1_COMMENT)), "dmc100k.toml"),
    ("study", ["report", "spec.toml", "--study-dir", "mg"],
     "the MiniGrid archive's spec as TOML (same keys) given to simoun-study",
     (MG, spec_as_toml("mg/spec.json", "spec.toml")), "", True),
    ("minigrid", [*MG_SPEC_FLAG, "spec.toml"], "--spec the archive's spec as TOML (same keys)",
     (MG, spec_as_toml("mg/spec.json", "spec.toml")), "", True),
    ("minigrid", [*MG_SPEC_FLAG, "spec.json.txt"], "--spec the archive's spec saved as .txt",
     (MG, lambda here: shutil.copyfile(here / "mg/spec.json", here / "spec.json.txt")), "",
     True),
]  # fmt: skip

# valid leftovers of other tools, and re-encodings that keep every value
VALID_CASES = [
    ("study", STUDY_REPORT, "a .git/ in the archive (results versioned with git init)",
     (ARCH, DMC100K, git_init("arch")), ""),
    ("train", RESUME, "an rsync partial file .checkpoint.pt.Xq3v9Z beside checkpoint.pt",
     (rsync_partial,), ""),
    ("train", RESUME, "a report written into the run (simoun-report run --out run), resumed",
     (report_into_run,), ""),
    ("train", RESUME, "the replay moved to a scratch disk and linked back (absolute link)",
     (replay_on_scratch,), ""),
    ("report", ["runs"], "a folder of runs holding a relative link to the run",
     (relative_run_link,), ""),
    ("study", STUDY_REPORT, "study.json reindented with its keys sorted (an editor's format)",
     (ARCH, DMC100K, spoil("arch/study.json", REINDENT)), ""),
    ("report", ["{run}"], "eval.csv's values in exponent notation (-9.3027171751208488e+00)",
     (run_file("eval.csv", EXPONENTS),), ""),
    ("report", ["{run}"], "summary.json saved as UTF-16 (PowerShell)",
     (run_file("summary.json", utf16),), "summary.json"),
]  # fmt: skip

# the Python API's loaders, in a case directory beside the tiny run (../tiny)
RUN = "import shutil; from pathlib import Path; shutil.copytree('../tiny', 'run'); "
HERE = "import reliability_eleventh_files as f; "
LOAD = RUN + HERE + "from simoun_agent.run.load import load_run; "
CSV = RUN + HERE + "from simoun_agent.run.logger import read_csv, read_log; "
CKPT = RUN + HERE + "from simoun_agent.run.checkpoint import load_checkpoint; "
SWEEP = (RUN + HERE + "import reliability_trial as t; t.sweep_dir(Path('.')); "
         "from simoun_lab.sweep.grid import SweepSpec; ")  # fmt: skip
DMC = repr(str(STUDIES / "dmc100k.toml"))
SAC = (
    f"import shutil; from pathlib import Path; shutil.copy({DMC}, 's.toml'); "
    + HERE
    + "import reliability_tenth_files as g; from simoun_lab.study.spec import load_spec; "
)
MGS = repr(str(STUDIES / "minigrid/spec.json"))
MG_SPEC = (f"import shutil; from pathlib import Path; shutil.copy({MGS}, 's.json'); " + HERE
           + "from simoun_lab.minigrid_study.spec import load_spec; ")  # fmt: skip
NOBODY_RUN = "f.as_user({}=({!r},))(Path.cwd()); "
API_CASES = [
    api(SAC + "f.bom(Path('s.toml')); s = load_spec(Path('s.toml')); assert s.recipes", "",
        True),
    api(SAC + "g.utf16(Path('s.toml')); load_spec('s.toml')", "s.toml", True),
    api(SAC + f"load_spec({str(STUDIES / 'dmc100k')!r})", "dmc100k"),
    api(SAC + f"load_spec({str(STUDIES / 'dmc100k/study.json')!r})", "study.json"),
    api(SAC + "g.conflict(Path('s.toml')); load_spec(Path('s.toml'))", "s.toml"),
    api(SAC + f"load_spec({MGS})", "spec.json"),
    api(SAC + "f.html_page(Path('s.toml')); load_spec(Path('s.toml'))", "s.toml"),
    api(MG_SPEC + "Path('s.toml').write_text(f.toml_of_spec(Path('s.json').read_text())); "
        "s = load_spec(Path('s.toml')); assert s.evaluations == 20", "", True),
    api(CSV + "p = Path('run/eval.csv'); f.TABS(p); read_csv(p)", "eval.csv"),
    api(SWEEP + "f.python_repr(Path('sw/sweep.json')); SweepSpec.load(Path('sw'))",
        "sweep.json"),
    api(CKPT + NOBODY_RUN.format("files", "run/checkpoint.pt")
        + "load_checkpoint(Path('run/checkpoint.pt'))", "checkpoint.pt"),
    api(LOAD + NOBODY_RUN.format("files", "run/config.json") + "load_run('run')",
        "config.json"),
    api(LOAD + NOBODY_RUN.format("trees", "run") + "import torch; "
        "r = load_run('run', device=torch.device('cpu')); assert r.env_step == 40", "", True),
    api(LOAD + "f.gzipped_in_place(Path('run/checkpoint.pt')); load_run('run')",
        "checkpoint.pt"),
]  # fmt: skip

CASES: list[dict] = [
    *(fifth("files", command, argv, names, *ok, works=works, what=what)
      for command, argv, what, works, names, *ok in
      PERMISSION_CASES + LIMIT_CASES + NAME_CASES + CONTENT_CASES + SPEC_FILE_CASES),
    *(fifth("files", command, argv, names, True, works=works, what=what)
      for command, argv, what, works, names in VALID_CASES),
    *({**case, "area": "files"} for case in API_CASES),
]  # fmt: skip
