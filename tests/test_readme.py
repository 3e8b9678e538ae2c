"""Every code block of README.md and docs/*.md runs, or is checked, as written.

The rule, by the block's fence:

- ```` ```python ```` (or ``py``): run on its own, as written, in a fresh interpreter in a
  temporary directory (files it writes do not land in the repository). No block is skipped.
- ```` ```bash ```` (or ``sh``, ``shell``): shell commands, not run (they train for minutes to
  hours). Each command (``\\`` continuations joined, ``#`` comments dropped, ``&&`` and ``|``
  split) is checked: a ``simoun-*`` command (also as ``.venv/bin/simoun-*``) must be a console
  script of pyproject.toml, and every ``--flag`` it uses must appear in that command's
  ``--help`` (a subcommand's own ``--help`` when it names one); ``bash PATH`` and
  ``python PATH`` must name a file of the repository. Other commands (``pip``, ``ray``,
  ``cp``, ...) are not checked.
- any other fence (``text``, none): output or a file layout, not checked.

Blocks are found by their fence wherever they sit, so a block added later is tested without
editing this file.
"""

from __future__ import annotations

import functools
import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
DOCS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
FENCE = re.compile(r"^```([\w-]*)[ \t]*\n(.*?)^```", re.DOTALL | re.MULTILINE)
PYTHON, SHELL = {"python", "py"}, {"bash", "sh", "shell"}
TIMEOUT_S = 300
ENV = {**os.environ, "OMP_NUM_THREADS": "1", "PYTHONPATH": str(ROOT)}  # two shared cores


def blocks(path: Path, languages: set[str]) -> list[tuple[str, str]]:
    """``(id, code)`` per block of ``languages``; the id is the file, its section's heading and
    the block's rank there."""
    text = path.read_text(encoding="utf-8")
    found: list[tuple[str, str]] = []
    for match in FENCE.finditer(text):
        if match.group(1) not in languages:
            continue
        headings = re.findall(r"^#+ +(.+)$", text[: match.start()], re.MULTILINE)
        section = re.sub(r"\W+", "-", headings[-1]).strip("-").lower() if headings else "top"
        prefix = f"{path.stem}:{section}"
        rank = sum(block_id.rsplit("-", 1)[0] == prefix for block_id, _ in found) + 1
        found.append((f"{prefix}-{rank}", match.group(2)))
    return found


PYTHON_BLOCKS = [block for path in DOCS for block in blocks(path, PYTHON)]
SHELL_BLOCKS = [block for path in DOCS for block in blocks(path, SHELL)]


def test_the_documents_have_blocks():
    assert any(i.startswith("README:") for i, _ in PYTHON_BLOCKS), "no ```python block in README"
    assert len(DOCS) >= 8, f"README.md and docs/*.md: found {[p.name for p in DOCS]}"


@pytest.mark.parametrize("code", [c for _, c in PYTHON_BLOCKS], ids=[i for i, _ in PYTHON_BLOCKS])
def test_python_block_runs_on_its_own(code, tmp_path):
    done = subprocess.run(
        [sys.executable, "-c", code],
        cwd=tmp_path,
        env=ENV,
        capture_output=True,
        text=True,
        timeout=TIMEOUT_S,
    )
    assert done.returncode == 0, f"block failed:\n{code}\n--- stderr ---\n{done.stderr}"


def commands(block: str) -> list[list[str]]:
    """The commands of a shell block, each as its words."""
    joined = re.sub(r"\\\n", " ", block)
    found = []
    for line in joined.splitlines():
        words = shlex.split(line, comments=True)
        current: list[str] = []
        for word in [*words, "&&"]:
            if word in {"&&", "||", "|", ";"}:
                if current:
                    found.append(current)
                current = []
            else:
                current.append(word)
    return found


@functools.cache
def console_scripts() -> dict[str, str]:
    """``{name: "module:function"}`` from pyproject.toml's ``[project.scripts]`` table."""
    text = (ROOT / "pyproject.toml").read_text(encoding="utf-8")
    table = re.search(r"^\[project\.scripts\]\n(.*?)(?=^\[|\Z)", text, re.DOTALL | re.MULTILINE)
    return dict(re.findall(r'^([\w-]+) *= *"([\w.:]+)"', table.group(1), re.MULTILINE))


@functools.cache
def help_text(script: str, subcommand: str | None) -> str:
    """``script [subcommand] --help``, run from pyproject.toml's entry point in this tree."""
    module, function = console_scripts()[script].split(":")
    argv = [subcommand, "--help"] if subcommand else ["--help"]
    code = f"import sys; sys.argv[0] = {script!r}; import {module} as m; m.{function}({argv!r})"
    done = subprocess.run(
        [sys.executable, "-c", code], env=ENV, capture_output=True, text=True, timeout=120
    )
    return done.stdout + done.stderr


def subcommands(script: str) -> set[str]:
    usage = re.search(r"\{([\w,-]+)\}", help_text(script, None))
    return set(usage.group(1).split(",")) if usage else set()


def check_command(words: list[str]) -> list[str]:
    """What is wrong with one documented command (nothing when it is fine)."""
    name = words[0].removeprefix(".venv/bin/")
    if name in {"bash", "python", "python3"} and len(words) > 1 and not words[1].startswith("-"):
        return [] if (ROOT / words[1]).is_file() else [f"{words[1]} is not a file of the tree"]
    if not name.startswith("simoun-"):
        return []
    if name not in console_scripts():
        return [f"{name} is not a console script of pyproject.toml"]
    rest = words[1:]
    subcommand = rest[0] if rest and rest[0] in subcommands(name) else None
    shown = re.findall(r"--[\w.-]+", help_text(name, subcommand))
    shown = {flag.replace("_", "-") for flag in shown}
    flags = [word.split("=", 1)[0] for word in rest if word.startswith("--")]
    missing = [flag for flag in flags if flag.replace("_", "-") not in shown]
    return [f"{name}: {flag} is not in its --help" for flag in missing]


@pytest.mark.parametrize("block", [b for _, b in SHELL_BLOCKS], ids=[i for i, _ in SHELL_BLOCKS])
def test_shell_block_names_real_commands_and_flags(block):
    problems = [problem for words in commands(block) for problem in check_command(words)]
    assert not problems, f"block:\n{block}\n" + "\n".join(problems)


def test_the_readme_commands_stay_exactly_as_ci_and_users_read_them():
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    main_job = (
        "bash scripts/setup.sh && .venv/bin/simoun-train --env dm_control/cartpole-swingup-v0 "
        "--preset cpu"
    )
    assert f"```bash\n{main_job}\n```" in text
    assert "```bash\nbash scripts/test.sh\n```" in text
    assert len(text.splitlines()) <= 200, "README.md is a front page: at most 200 lines"
