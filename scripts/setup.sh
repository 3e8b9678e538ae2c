#!/usr/bin/env bash
# Creates .venv and installs simoun with every extra. torch is pinned and installed first:
# an unpinned torch pulls a multi-GB CUDA build, while torch==2.13.0 resolves to a CPU wheel.
# pip stays quiet (its per-package lines fill a log); one line per step says what runs now.
set -euo pipefail
cd "$(dirname "$0")/.."

step() {
    echo "setup.sh [$1/4, ${SECONDS} s]: $2" >&2
}

step 1 "creating .venv"
python3 -m venv .venv
step 2 "upgrading pip"
.venv/bin/python -m pip install --quiet --upgrade pip
step 3 "installing torch==2.13.0 (CPU wheel, the largest download)"
.venv/bin/python -m pip install --quiet "torch==2.13.0"
step 4 "installing simoun with every extra and the dev tools (the longest step: minutes)"
.venv/bin/python -m pip install --quiet -e ".[all,dev]"
echo "setup.sh: .venv ready after ${SECONDS} s; try .venv/bin/simoun-train --help" >&2
