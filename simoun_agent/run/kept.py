"""Reading a run's kept files, with the damage a disk, a copy or an editor leaves named.

``simoun-train --resume``, ``simoun-eval``, ``simoun-analyze`` and ``simoun-report`` read the
files a run keeps (``config.json``, ``eval.csv``, ``train.csv``, ``summary.json``,
``checkpoint.pt``), and the lab's commands the files studies and sweeps keep (``study.json``,
``spec.json``, ``trial.json``, ``references.json``, ``generalization.csv`` ...); each names a
damaged one by its path, what is wrong and the fix, rather than failing inside a parser or taking
the damage for data. :class:`Damaged` carries what is wrong; each caller adds the fix that fits
its command. A file or folder the user may not read (another user's, a colleague's private run)
is no damage: :class:`Unreadable` names it with its owner, mode and the fix for permissions.
"""

from __future__ import annotations

import csv
import errno
import io
import json
import math
import os
import pwd
import stat
import zipfile
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from simoun_agent.config.errors import SetupError

STEP_LIMIT = 2**63
"""Steps at or past it are damage: counters, TensorBoard and numpy hold steps as int64."""

_UTF16_MARKS = (b"\xff\xfe", b"\xfe\xff")

LFS_POINTER = b"version https://git-lfs.github.com/spec/v1"
"""The first line of a Git LFS pointer: what a clone made without git-lfs holds in place of each
file the repository keeps in LFS."""


def lfs_problem(path: Path, data: bytes) -> str | None:
    """What is wrong with ``path`` when its bytes ``data`` (its start suffices) are a Git LFS
    pointer, else None: the file itself was never fetched, and ``git lfs pull`` fetches it."""
    if not data.startswith(LFS_POINTER):
        return None
    return (
        "it is a Git LFS pointer, not the file itself (a clone made without git-lfs); fetch the "
        f"file with `git lfs install && git lfs pull` in the clone that holds {path.name}"
    )


def encoding_problem(path: Path) -> str:
    """What is wrong with ``path``, a UTF-16 text file (PowerShell's ``>`` and Notepad write
    them), and the fix that keeps its content: every kept text file is read as UTF-8."""
    return (
        f"it is saved as UTF-16 text, not UTF-8; convert it (iconv -f UTF-16 -t UTF-8 {path} > "
        f"{path}.utf8 && mv {path}.utf8 {path})"
    )


def json_problem(text: str, err: json.JSONDecodeError) -> str:
    """Where and why ``text`` is not JSON (``err``, json's error on it), in the words of a
    person who edited the file: the two slips of hand-edited JSON are named, since json's own
    message hides them (a comma after the last item, which it reports on the line after, and a
    comment), else json's message with its line and column."""
    before, rest = text[: err.pos].rstrip(), text[err.pos :]
    if before.endswith(",") and rest.lstrip()[:1] in ("}", "]"):
        return (
            f"a comma after the last item, line {before.count(chr(10)) + 1}: JSON allows none "
            "there; remove it"
        )
    if rest.startswith(("//", "/*", "#")):
        return f"a comment, line {err.lineno}: JSON has no comments; remove it"
    return f"{err.msg}, line {err.lineno} column {err.colno}"


class Damaged(ValueError):
    """A kept file that cannot be what the run wrote; ``str()`` says what is wrong with it."""


class Unreadable(SetupError):
    """A kept file or folder the user may not read (permission denied): whole, as far as anyone
    knows, so that the fix is to make it readable, never to restore, delete or train it anew;
    ``str()`` names it, its owner and mode, and the command that makes it readable."""


DENIED = (errno.EACCES, errno.EPERM)
"""The errors of a file or folder the user may not read (its mode, its owner)."""


def blocking(path: Path) -> Path:
    """What stops a read of ``path``: the outermost of its folders that the user may not enter
    (a colleague's private run folder, mode 700), else ``path`` itself."""
    for folder in reversed(Path(path).parents):
        if str(folder) not in ("", ".") and not os.access(folder, os.X_OK):
            return folder
    return Path(path)


def owner_and_mode(path: Path) -> tuple[str, str]:
    """The user name (or number) that owns ``path`` and its permission bits, as ``ls -l`` and
    ``chmod`` show them (``600``); ``?`` for what cannot be looked at."""
    try:
        info = os.lstat(path)
    except OSError:
        return "?", "?"
    try:
        owner = pwd.getpwuid(info.st_uid).pw_name
    except KeyError:
        owner = str(info.st_uid)
    return owner, f"{stat.S_IMODE(info.st_mode):o}"


def permission_problem(path: Path) -> str:
    """``path`` (a file or folder the user may not read) named with what blocks it, its owner and
    mode, and the fix that works: ``chmod`` for the user's own, the owner's or ``sudo chown``
    for another user's. Nothing in it is damaged."""
    where = blocking(path)
    owner, mode = owner_and_mode(where)
    folder = os.path.isdir(where)
    bits = "u+rx" if folder else "u+r"
    what = f"{path} cannot be read" + ("" if where == Path(path) else f" (its folder {where})")
    try:
        mine = os.lstat(where).st_uid == os.geteuid()
    except OSError:
        mine = False
    fix = (
        f"make it readable (chmod {bits} {where})"
        if mine
        else (
            f"ask its owner ({owner}) to make it readable (chmod a{bits[1:]} {where}), or take it "
            f"as an administrator (sudo chown {'-R ' if folder else ''}$USER {where})"
        )
    )
    return f"{what}: permission denied (owner {owner}, mode {mode}); {fix}"


@contextmanager
def reading(path: Path) -> Iterator[None]:
    """Reads of ``path`` (a kept file or folder) inside it that are refused for permission
    raise :class:`Unreadable` naming it (:func:`permission_problem`); other OSErrors pass."""
    try:
        yield
    except OSError as err:
        if err.errno in DENIED:
            raise Unreadable(permission_problem(Path(path))) from None
        raise


def broken_link(path: Path) -> str | None:
    """What is wrong with ``path`` when it is a symbolic link to nothing or a chain of links
    that loops, else None (an existing file's ``exists()`` is True, a missing one's is False:
    such a link looks missing)."""
    if not path.is_symlink():
        return None
    try:
        os.stat(path)
    except OSError as err:
        if err.errno == errno.ELOOP:
            return f"it is a symbolic link to {os.readlink(path)}, which leads back to itself"
        return f"it is a symbolic link to {os.readlink(path)}, which does not exist"
    return None


def folder_problem(path: Path) -> str | None:
    """What is wrong with the run folder at ``path`` when something else than a run's directory
    stands there, else None (nothing there is not a problem: a run not started): a symbolic
    link to nothing or that loops (:func:`broken_link`), a link to a folder it is in (a reader
    walking the runs would go round in it, and a run trained there would write into the
    folder above), or a file. A link to a copy of the run elsewhere is a run."""
    problem = broken_link(path)
    if problem:
        return problem
    if path.is_symlink() and path.resolve() in (here := path.parent.resolve(), *here.parents):
        return (
            f"it is a symbolic link to {os.readlink(path)}, a folder it is in (a loop), not the "
            "run's directory"
        )
    if present(path) and not path.is_dir():
        return "it is a file, not the run's directory"
    return None


_KINDS = (
    (stat.S_ISDIR, "a directory"),
    (stat.S_ISFIFO, "a named pipe (FIFO)"),
    (stat.S_ISSOCK, "a socket"),
    (stat.S_ISCHR, "a character device"),
    (stat.S_ISBLK, "a block device"),
)


def not_a_file(path: Path) -> str | None:
    """What is wrong with ``path`` when it is there but is not a regular file, else None: a
    read of a named pipe waits for a writer forever, and a device can give bytes without end."""
    try:
        mode = os.stat(path).st_mode
    except OSError:
        return None  # missing or unreadable: the read that follows names it
    if stat.S_ISREG(mode):
        return None
    kind = next((name for test, name in _KINDS if test(mode)), "something else")
    return f"it is {kind}, not a regular file"


def read_text(path: Path) -> str:
    """The UTF-8 text of ``path`` (a leading byte order mark dropped, as a spreadsheet writes
    it); :class:`Damaged` for a link to nothing, something that is not a regular file (checked
    before it is opened), a Git LFS pointer (:func:`lfs_problem`), text in another encoding
    (UTF-16 named with the command that converts it) or NUL bytes, which no run writes. Every
    kept text file, JSON or CSV, is read here, so that each is refused or taken alike. OSError
    for a file that cannot be read, :class:`Unreadable` for one the user may not read."""
    with reading(path):
        problem = broken_link(path) or not_a_file(path)
        if problem:
            raise Damaged(problem)
        data = path.read_bytes()
    problem = lfs_problem(path, data)
    if problem:
        raise Damaged(problem)
    if data.startswith(_UTF16_MARKS):
        raise Damaged(encoding_problem(path))
    if b"\0" in data:
        line = data[: data.index(b"\0")].count(b"\n") + 1
        raise Damaged(f"line {line} holds a NUL byte (zero bytes from a disk or copy failure)")
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as err:
        line = data[: err.start].count(b"\n") + 1
        raise Damaged(f"line {line} is not UTF-8 text (byte {data[err.start]:#04x})") from None


def present(path: Path) -> bool:
    """Whether anything is at ``path``: a file, a directory, a named pipe or a symbolic link,
    even one to nothing. A kept file is read when present, so that what stands in its place is
    named rather than taken for a file not written yet. :class:`Unreadable` where a folder on
    the way may not be entered (a colleague's private run folder)."""
    with reading(path):
        return path.is_symlink() or path.exists()


def json_kind(value: Any) -> str:
    """What JSON calls ``value``'s kind (an array, null, a number...), for messages."""
    kinds = {list: "an array", dict: "an object", type(None): "null", bool: "true/false"}
    return kinds.get(type(value), "a string" if isinstance(value, str) else "a number")


def read_json_object(path: Path) -> dict[str, Any]:
    """The JSON object in ``path``; :class:`Damaged` for what :func:`read_text` refuses, an
    empty file, text that is not JSON (cut short, say), JSON that is not an object, or a file
    that cannot be read (its callers name every such file the same way); :class:`Unreadable`
    for one the user may not read."""
    try:
        text = read_text(path)
    except OSError as err:
        raise Damaged(f"it cannot be read ({err.strerror})") from None
    if not text.strip():
        raise Damaged("it is empty")
    try:
        value = json.loads(text)
    except json.JSONDecodeError as err:
        raise Damaged(f"it is not JSON ({json_problem(text, err)})") from None
    if not isinstance(value, dict):
        raise Damaged(f"it holds {json_kind(value)}, not a JSON object")
    return value


def csv_lines(path: Path) -> list[list[str]]:
    """The fields of each line of the CSV file ``path``, blanks after a comma dropped (``1, 2``
    as a person or a spreadsheet writes it reads as ``1,2``: every reader of a run's logs, and
    a resumed run's writer, takes one header whichever way it is spaced); :class:`Damaged` for
    what :func:`read_text` refuses, text that is not CSV, a JSON file (``{...}``, a run's other
    kind of kept file), or a comment line (``# ...``), which CSV does not have and which would
    be read as the header or a row. OSError for a file that cannot be read."""
    text = read_text(path)
    if text.lstrip()[:1] in ("{", "["):
        raise Damaged(f"it looks like JSON (it begins with {text.lstrip()[0]!r}), not a CSV log")
    try:
        lines = list(csv.reader(io.StringIO(text, newline=""), skipinitialspace=True))
    except csv.Error as err:
        raise Damaged(f"it is not a CSV file ({err})") from None
    for number, values in enumerate(lines, start=1):
        if values and values[0].lstrip().startswith("#"):
            raise Damaged(
                f"line {number} is a comment ({values[0][:40]!r}): CSV has no comments; remove "
                "that line"
            )
    return lines


def read_csv_rows(
    path: Path, columns: Sequence[str] = (), empty_ok: bool = False
) -> list[dict[str, str]]:
    """The rows of the CSV file ``path`` under its header line, values as text (blank lines
    skipped); :class:`Damaged` for what :func:`csv_lines` refuses, an empty file (no rows where
    ``empty_ok``: a reader that says what an empty log means for its run), a first line of
    numbers (:func:`header_problem`), a header without one of ``columns``, or a row whose
    fields do not fit the header (a line cut short or two run together). OSError for a file
    that cannot be read."""
    lines = csv_lines(path)
    if not any(lines):
        if empty_ok:
            return []
        raise Damaged("it is empty")
    header = lines[0]
    problem = header_problem(header)
    if problem:
        raise Damaged(problem)
    missing = [column for column in columns if column not in header]
    if missing:
        raise Damaged(f"its first line has no {', '.join(missing)} column")
    for number, values in enumerate(lines[1:], start=2):
        if values and len(values) != len(header):
            fields = f"{len(values)} fields where the header has {len(header)}"
            raise Damaged(f"line {number} has {fields}")
    return [dict(zip(header, values, strict=True)) for values in lines[1:] if values]


def is_number(text: str) -> bool:
    """Whether ``text`` reads as a number (``nan`` and ``inf`` included)."""
    try:
        float(text)
    except ValueError:
        return False
    return True


def header_problem(header: Sequence[str]) -> str | None:
    """What is wrong with the first line ``header`` of a CSV file when it holds numbers where
    the column names go (the header line deleted: the first row would name the columns and be
    lost), else None. No file the project writes names a column with a number."""
    numbers = [name for name in header if is_number(name)]
    if not numbers:
        return None
    shown = ",".join(header[:4]) + (",..." if len(header) > 4 else "")
    return (
        f"its first line ({shown}) holds numbers where the header of column names goes: the "
        "header line is missing (deleted, or the file cut at its start)"
    )


def csv_number(text: str, column: str, line: int) -> float:
    """The value ``text`` of ``column`` on ``line`` of a CSV file as a float, NaN where empty (a
    value the run did not measure); :class:`Damaged` naming the line when it is not a number."""
    if text == "":
        return math.nan
    try:
        return float(text)
    except ValueError:
        raise Damaged(f"line {line}: {column} is {text!r}, not a number") from None


def step_count(text: str) -> int:
    """The env step written as ``text`` in a kept log: digits, or a float of a whole number
    (``20.0``, as pandas and spreadsheets write integer columns that had an empty cell), so that
    every reader of a run's logs takes the same file; :class:`Damaged` saying what is wrong
    with any other value (a fraction, a sign, a word, a step past :data:`STEP_LIMIT`)."""
    try:
        value = float(text) if text.strip() == text and text else math.nan
    except ValueError:
        value = math.nan
    if not math.isfinite(value) or value < 0 or value != int(value):
        raise Damaged(f"env_step {text!r} is not a step count (a whole number of steps)")
    if value >= STEP_LIMIT:
        raise Damaged(f"env_step {text} is past 2**63, more steps than a run can count")
    return int(text) if text.isdigit() else int(value)


def binary_problem(path: Path) -> str:
    """What is visibly wrong with a binary file that its reader refused: empty, a Git LFS
    pointer (:func:`lfs_problem`), or all zero bytes (a disk that lost the data, a copy cut
    off); else that it cannot be read. :class:`Unreadable` for a file the user may not read:
    its reader's refusal was not damage."""
    try:
        size = path.stat().st_size
        if size == 0:
            return "it is empty"
        with path.open("rb") as f:
            if problem := lfs_problem(path, f.read(len(LFS_POINTER))):
                return problem
            f.seek(0)
            while chunk := f.read(1 << 20):
                if chunk.count(0) != len(chunk):
                    return f"it cannot be read ({size} bytes, cut short or overwritten)"
    except OSError as err:
        if err.errno in DENIED:
            raise Unreadable(permission_problem(path)) from None
        return f"it cannot be read ({err.strerror})"
    return f"all its {size} bytes are zero (a disk or copy failure)"


def checkpoint_problem(path: Path) -> str | None:
    """What is wrong with the checkpoint at ``path`` (a ``torch.save`` file, which is a zip
    archive), checked without torch by reading every member against its checksum; None when it
    is whole. A link to nothing or something that is not a file is named too;
    :class:`Unreadable` for a file the user may not read."""
    with reading(path):
        problem = broken_link(path) or not_a_file(path)
    if problem:
        return problem
    try:
        with zipfile.ZipFile(path) as archive:
            bad = archive.testzip()
    except (zipfile.BadZipFile, EOFError, ValueError):
        return binary_problem(path)
    except OSError as err:
        if err.errno in DENIED:
            raise Unreadable(permission_problem(path)) from None
        return f"it cannot be read ({err.strerror})"
    return None if bad is None else f"its part {bad} does not match its checksum (overwritten)"


RUN_LOG_COLUMNS = {
    "eval.csv": ("env_step", "return_mean", "return_std", "return_min", "return_max",
                 "length_mean"),
    "train.csv": ("env_step", "episode", "return", "length", "env_steps_per_s"),
}  # fmt: skip
"""The columns a simoun run writes to each of its logs, by file name: an evaluation's
statistics, a training episode's own numbers (callbacks and test modes may add others)."""
RUN_JSON_KEYS = {
    "config.json": ("env", "seed", "agent"),
    "summary.json": ("env_step", "final_eval"),
}
"""The keys a simoun run writes to each of its JSON records, by file name."""
REQUIRED = {"eval.csv": ("return_mean",), "train.csv": ("return",)}
"""The columns every reader of a log reads besides env_step (the other columns of
:data:`RUN_LOG_COLUMNS` are left out of an older or a trimmed copy)."""


def kind_problem(name: str, found: Sequence[str]) -> str | None:
    """What is wrong when ``found``, the header of the run's log ``name`` (eval.csv, train.csv)
    or the keys of its record (config.json, summary.json), holds another of the run's files'
    own columns or keys (those the file ``name`` never holds): that file copied over it (the
    ones it lacks of its own named too), or the two logs mixed into one; or, for a log, when a
    column every reader of it reads is missing. None when they are its own, and for a file of
    another name."""
    kinds = RUN_LOG_COLUMNS if name in RUN_LOG_COLUMNS else RUN_JSON_KEYS
    if name not in kinds:
        return None
    what = "columns" if kinds is RUN_LOG_COLUMNS else "keys"
    own, present_ = kinds[name], set(found)
    missing = [key for key in own if key not in present_]
    for other, keys in kinds.items():
        strays = [key for key in keys if key not in own and key in present_]
        if other == name or not strays:
            continue
        if missing:
            return (
                f"it holds {other}'s {what} ({', '.join(strays)}), not {name}'s (it has no "
                f"{', '.join(missing)}): {other} was copied over it"
            )
        return (
            f"it holds {other}'s {what} ({', '.join(strays)}) beside its own: the run's two "
            "files were mixed into one"
        )
    lacking = [key for key in REQUIRED.get(name, ()) if key not in present_]
    if lacking:
        return f"it has no {', '.join(lacking)} column, which every {name} of a run holds"
    return None


def finite_number(value: Any) -> bool:
    """Whether ``value`` is a finite JSON number (true/false are not numbers)."""
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def summary_problem(path: Path) -> str | None:
    """What is wrong with a run's ``summary.json``, the mark that the run finished, when a
    resume cannot rely on it: it cannot be read (:func:`read_json_object`), holds another file's
    keys (:func:`kind_problem`), or has no env_step >= 0 or no finite final_eval.return_mean,
    which every reader of a finished run reads. None when there is no summary.json (the run is
    not finished) or it is sound. :class:`Unreadable` for one the user may not read."""
    with reading(path):
        written = path.is_file()
    if not written:
        return None
    try:
        summary = read_json_object(path)
    except Damaged as err:
        return str(err)
    problem = kind_problem(path.name, list(summary))
    if problem:
        return problem
    step = summary.get("env_step")
    if not (finite_number(step) and step >= 0):
        return f"its env_step is {json.dumps(step)}, not a number >= 0"
    final = summary.get("final_eval")
    value = final.get("return_mean") if isinstance(final, dict) else None
    if not finite_number(value):
        return f"it has no finite final_eval.return_mean ({json.dumps(value)})"
    return None


UNPACK = {".gz": "gunzip", ".bz2": "bunzip2", ".xz": "unxz", ".zst": "unzstd"}
"""A compressed file's suffix -> the command that restores the file beside it."""


def packed_problem(path: Path, what: str = "") -> str | None:
    """What to say of the kept file ``path`` when it is missing but a compressed copy of it lies
    beside it (``checkpoint.pt.gz``: packed by hand to save space), with the command that unpacks
    it; None when ``path`` is there or no such copy is. A reader says this rather than that the
    file was never written. ``what``: what the file is, said after its path."""
    if present(path):
        return None
    for suffix, command in UNPACK.items():
        packed = path.with_name(path.name + suffix)
        if present(packed):
            return (
                f"{path}{what} is missing, but {packed.name} lies beside it (packed to save "
                f"space): unpack it ({command} -k {packed})"
            )
    return None


def packed_folder_advice(path: Path) -> str:
    """The advice for a file given where a folder is read (a run, a sweep, a study's archive):
    the folder packed for sending (``mg.tar.gz``, ``runs.zip``), with the command that unpacks
    it beside itself."""
    if path.suffix.lower() == ".zip":
        command = f"unzip {path} -d {path.parent}"
    else:
        command = f"tar -xf {path} -C {path.parent}"
    return f"if it is the folder packed, unpack it first ({command}) and pass the folder it gives"
