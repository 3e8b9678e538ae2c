#!/usr/bin/env bash
# Proves the dependency floors of pyproject.toml: installs the lowest version that each direct
# dependency allows (uv's --resolution lowest-direct) into .venv-floors and runs tests there.
#   1. the package and its dev extra at their floors: a fast subset that uses each floor's
#      feature (fused CPU Adam: torch; np.trapezoid: numpy; AutoresetMode and spec rebuilds:
#      gymnasium; a short training run: matplotlib, opencv, tensorboard, imageio, tqdm,
#      tyro);
#   2. the optional extras added at their floors (stable-baselines3's floor raises torch past
#      its own), with the tests of dm_control, highway-env, PettingZoo and the vector wrappers.
# Needs .venv (scripts/setup.sh) and about 4 GB of disk (PyPI's torch with its CUDA libraries).
# Extra arguments go to both pytest runs.
set -euo pipefail
cd "$(dirname "$0")/.."
# The floors come from PyPI (the local wheel folders hold only current versions): on a machine
# that cannot reach it, say so plainly instead of failing the whole CI on a download.
if ! .venv/bin/python -c "import urllib.request; urllib.request.urlopen('https://pypi.org/simple/uv/', timeout=20)" 2>/dev/null; then
    echo "test_floors.sh: SKIPPED: pypi.org is unreachable, so the lowest allowed versions cannot be installed here" >&2
    exit 0
fi
if [ ! -x .venv/bin/uv ]; then
    .venv/bin/python -m pip install --quiet "uv>=0.5"
fi
uv=.venv/bin/uv
python=.venv-floors/bin/python
rm -rf .venv-floors
"$uv" venv --quiet --python "$(.venv/bin/python -c 'import sys; print(sys.executable)')" \
    .venv-floors
# lowest-direct: every direct dependency at its floor, their own dependencies at the newest
# versions that fit. PyPI's torch wheels for Linux are the CUDA builds; without a GPU
# torch.cuda.is_available() is False and the agent runs on the CPU.
install() {
    "$uv" pip install --quiet --python "$python" --resolution lowest-direct -e ".[$1]"
    # triton (the CUDA build's GPU compiler) segfaults on import once pygame and mujoco are
    # loaded, and fused Adam imports it through torch._dynamo; the CPU build has none
    "$uv" pip uninstall --quiet --python "$python" triton 2>/dev/null || true
    "$uv" pip list --python "$python" 2>/dev/null | grep -iE "^($2) " | tr -s " " | \
        sed "s/^/floor ($1): /"
}
install dev "gymnasium|numpy|torch|opencv-python-headless|tqdm|matplotlib|imageio|imageio-ffmpeg|tensorboard|tyro|pytest"
SIMOUN_FLOORS=core "$python" -m pytest -q -p no:cacheprovider -W ignore::DeprecationWarning \
    tests/test_dependency_floors.py \
    tests/test_losses_by_hand.py \
    tests/test_agent_maths.py \
    tests/test_agent_update.py \
    tests/test_agent_encoder.py \
    tests/test_curiosity_core.py \
    "tests/test_report.py::test_auc_is_the_normalized_trapezoid" \
    "$@"
install dev,dmc,highway,minigrid,multiagent,sb3 "dm-control|shimmy|mujoco|highway-env|pettingzoo|stable-baselines3|minigrid|torch"
SIMOUN_FLOORS=extras "$python" -m pytest -q -p no:cacheprovider -W ignore::DeprecationWarning \
    tests/test_dependency_floors.py \
    tests/test_wrappers_pettingzoo.py \
    tests/test_wrappers_cameras.py \
    tests/test_wrappers_vector.py \
    tests/test_wrappers_spec.py \
    tests/test_train_env.py \
    "$@"
