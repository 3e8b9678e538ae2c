"""The project's text speaks of the software, never of how it was made.

Every tracked text file (code, comments, docstrings, tests, docs, specs, scripts) is searched for
words that belong to the making of the project rather than to the project: tracker numbers, the
timeline of the work (calendar months, sittings), who provides which machine, and the names of
development tools and assistants. The patterns below are the list; a version or a commit says
when something changed (CHANGELOG.md is organised by version).

Run records are data, not narrative, and are not searched: ``.csv``, ``.json`` and ``.jsonl``
files (their provenance timestamps are dates on purpose), and binary files. This file is not
searched either (it spells the patterns).

``ALLOWED`` lists the exceptions: a (path, word) pair where the word is about the software
itself, each with its reason. It is empty: no legitimate text needs these words. Add an entry
only for such a case, never for an account of the work.
"""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
THIS = Path(__file__).resolve().relative_to(ROOT).as_posix()
DATA_SUFFIXES = {".csv", ".json", ".jsonl"}

FORBIDDEN = {
    "an issue or pull-request number": (
        r"(?<![a-z])(?:issues?|pr|pull[\s_-]requests?|tickets?)[\s_#-]*\d+|\bgh-\d+"
    ),
    "the work's timeline": (
        r"(?<![a-z_])sessions?(?![a-z_])|(?<![a-z])(?:this[\s_]issue|the[\s_]issue(?:'|_)s)(?![a-z])"
        r"|\b20\d\d-\d\d\b"
    ),
    "machine lending": r"\blent\b|\blend(?:s|ing)?\b|\bloan(?:s|ed)?\b",
    "a development tool": (
        r"farm-studio|\bclaude\b|anthropic|openai|chatgpt|\bgpt-?\d|copilot|\bllms?\b"
        r"|duplicates --change|\bissues show\b"
    ),
}
PATTERN = re.compile("|".join(f"(?P<g{i}>{p})" for i, p in enumerate(FORBIDDEN.values())), re.I)
KINDS = list(FORBIDDEN)

# (path, the matched word, lowercased): why it is about the software. Empty on purpose.
ALLOWED: dict[tuple[str, str], str] = {}


def tracked_files() -> list[str]:
    """The repository's tracked files (``git ls-files``), or every file under the root that is
    not in ``.git`` or a virtual environment when git is not available."""
    try:
        listed = subprocess.run(
            ["git", "ls-files", "-z"], cwd=ROOT, capture_output=True, check=True, timeout=60
        ).stdout.decode()
        return [name for name in listed.split("\0") if name]
    except (OSError, subprocess.CalledProcessError):
        skip = {".git", ".venv", ".venv-floors", "__pycache__"}
        return [
            path.relative_to(ROOT).as_posix()
            for path in ROOT.rglob("*")
            if path.is_file() and not skip & set(path.relative_to(ROOT).parts)
        ]


def findings(name: str, text: str) -> list[str]:
    found = []
    for number, line in enumerate(text.splitlines(), 1):
        for match in PATTERN.finditer(line):
            word = match.group(0).lower()
            if (name, word) in ALLOWED:
                continue
            kind = KINDS[int(match.lastgroup[1:])]
            found.append(f"{name}:{number}: {match.group(0)!r} ({kind}): {line.strip()[:120]}")
    return found


def test_the_tracked_text_speaks_of_the_software_only():
    problems = []
    for name in tracked_files():
        path = ROOT / name
        if name == THIS or path.suffix.lower() in DATA_SUFFIXES or not path.is_file():
            continue
        try:
            text = path.read_text(encoding="utf-8")
        except UnicodeDecodeError:  # binary: images, archives, checkpoints
            continue
        problems += findings(name, text)
    assert not problems, (
        "describe the software, not the making of it (tests/test_project_text.py says what is "
        "refused and why):\n" + "\n".join(problems)
    )


def test_the_patterns_catch_what_they_are_for():
    caught = [
        "Issue 20's diagnostic",
        "see issue #38",
        "measured 2026-12-02",
        "in an earlier session",
        "on a lent GPU machine",
        "drawn by farm-studio look",
        "written with Claude",
        "def test_the_spec_of_issue_20_plans_its_runs():",
        "def test_the_default_spec_is_the_issue_s_design():",
        "a pull-request 12 fix",
    ]
    kept = [
        "a silently dropped setting",
        "blend the two views",
        "issues a warning",
        "Ray Tune's trial",
        "2,000 resamples",
        "Eq. 13",
        "PRNG 2 streams",
        "the issues_left counter",
        "obsessions",
        "subprocess.Popen(command, start_new_session=True)",
    ]
    assert all(findings("x", line) for line in caught)
    assert not [line for line in kept if findings("x", line)]
