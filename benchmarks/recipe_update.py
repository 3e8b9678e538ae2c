"""Cost of one gradient update of each recipe of the DMC 100k study, against DrQ's, in one run.

A diagnostic of Simoun's equal-wall-time result: the study's runs spread over machines that
ran at different speeds, so their wall times compare only between runs on one machine. This
times the updates themselves, every recipe in the same process on the same replay contents:

- each recipe is built as the study ran it (the ``cpu`` preset, the recipe, its setting selected
  by the study, read from ``docs/studies/dmc100k/selection.json``) on the chosen task, and its
  replay is filled with the same ``--fill`` random-action transitions;
- each repeat times ``--updates`` updates of every recipe (an even count, so the actor and target
  updates that run every second step are averaged in), the recipes in a rotated order; medians
  over ``--repeats`` are reported, so a machine shared with other work slows all alike;
- the table gives milliseconds per update, the ratio to DrQ (the named baseline) and the update
  time of a whole run of the preset's budget (after the warm-up, one update per
  ``update_every_steps`` agent steps: 12,250 updates in 100k env steps at action repeat 8, 24,750
  at 4, half that for drqv2, which updates every 2nd agent step);
- ``--ablations`` adds the ``simoun_no_<part>`` recipes at Simoun's selected setting, so the table
  also says which part of Simoun (curiosity, the interactive module, the auxiliary losses) costs
  the time.

    python benchmarks/recipe_update.py                                   # cheetah-run
    python benchmarks/recipe_update.py --task dm_control/cartpole-swingup-v0 --action-repeat 8
    python benchmarks/recipe_update.py --ablations
    python benchmarks/recipe_update.py --selection runs/studies/NAME/selection.json \
        --json runs/studies/NAME/update_cost.json     # the ratios a study's report draws with

``--json`` also writes the ratios with where they were measured (the command, the commit, the
machine), in the form ``simoun-study report`` reads
(:data:`simoun_lab.study.report.UPDATE_COST_JSON`).
"""

from __future__ import annotations

import argparse
import json
import shlex
import statistics
import sys
import time
from pathlib import Path

import numpy as np
import torch

from simoun_agent import table
from simoun_agent.config import resolve
from simoun_agent.config.recipes import SIMOUN_PARTS
from simoun_agent.run.atomic import atomic_write
from simoun_agent.run.train import build
from simoun_lab.study.probe import machine
from simoun_lab.study.provenance import code_version

SELECTION = Path(__file__).resolve().parent.parent / "docs/studies/dmc100k/selection.json"
BASELINE = "drq"


def selected_settings(path: Path, ablations: bool) -> dict[str, dict]:
    """Each recipe's setting selected by the study, as config overrides; with ``ablations``,
    also each ``simoun_no_<part>`` recipe at Simoun's setting (the study tuned no ablation)."""
    recipes = json.loads(path.read_text())["recipes"]
    settings = {name: dict(entry["setting"]) for name, entry in recipes.items()}
    if ablations:
        settings.update({f"simoun_no_{part}": settings["simoun"] for part in SIMOUN_PARTS})
    return settings


def filled(recipe: str, setting: dict, task: str, action_repeat: int, fill: int):
    """The recipe's agent, a replay holding ``fill`` random-action transitions of the task and
    the number of updates of a whole run of the preset's budget."""
    config = resolve(
        "cpu",
        {"env": task, "action_repeat": action_repeat, "agent.recipe": recipe, **setting},
    )
    env, eval_env, agent, replay = build(config)
    learning_starts = max(config.warmup_agent_steps, config.agent.batch_size)
    updating = config.total_env_steps // action_repeat - learning_starts
    updates = -(-updating // config.agent.update_every_steps) * config.updates_per_step
    try:
        rng = np.random.default_rng(0)
        low, high = env.action_space.low, env.action_space.high
        obs = env.reset(seed=0)
        replay.start_episode(obs["frames"][-1])
        for _ in range(fill):
            action = rng.uniform(low, high).astype(np.float32)
            env.step_async(action)
            obs, reward, terminated, truncated = env.step_wait()
            replay.add(action, reward, obs["frames"][-1], terminated, truncated)
            if terminated or truncated:
                obs = env.reset(seed=1)
                replay.start_episode(obs["frames"][-1])
    finally:
        env.close()
        eval_env.close()
    return agent, replay, updates


def time_updates(agent, replay, updates: int, step: int) -> float:
    """Milliseconds per update over ``updates`` consecutive updates."""
    start = time.perf_counter()
    for _ in range(updates):
        agent.update(replay, step)
    return 1000 * (time.perf_counter() - start) / updates


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--task", default="dm_control/cheetah-run-v0")
    parser.add_argument("--action-repeat", type=int, default=4)
    parser.add_argument("--fill", type=int, default=1000, help="transitions in each replay")
    parser.add_argument("--updates", type=int, default=20, help="updates per timing (even)")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--selection", type=Path, default=SELECTION)
    parser.add_argument(
        "--ablations", action="store_true", help="also time each simoun_no_<part> recipe"
    )
    parser.add_argument("--json", type=Path, help="also write the ratios here, for a study report")
    args = parser.parse_args()
    if args.updates < 2 or args.updates % 2:
        parser.error(f"--updates must be even and at least 2, got {args.updates}")
    torch.set_num_threads(1)
    settings = selected_settings(args.selection, args.ablations)
    if BASELINE not in settings:
        parser.error(f"{args.selection} selects no setting for the baseline {BASELINE!r}")
    built = {
        name: filled(name, setting, args.task, args.action_repeat, args.fill)
        for name, setting in settings.items()
    }
    step = args.fill * args.action_repeat
    for agent, replay, _ in built.values():
        time_updates(agent, replay, 2, step)
    names = list(built)
    times: dict[str, list[float]] = {name: [] for name in names}
    for repeat in range(args.repeats):
        shift = repeat % len(names)
        for name in names[shift:] + names[:shift]:
            agent, replay, _ = built[name]
            times[name].append(time_updates(agent, replay, args.updates, step))
    medians = {name: statistics.median(values) for name, values in times.items()}
    print(
        f"one update of each recipe at the cpu preset (48x48, batch 64, 1 torch thread) on "
        f"{args.task}, action repeat {args.action_repeat}: median of {args.repeats} repeats of "
        f"{args.updates} updates"
    )
    rows = []
    for name in names:
        setting = ", ".join(f"{key}={value}" for key, value in settings[name].items())
        ratio = medians[name] / medians[BASELINE]
        run_s = medians[name] * built[name][2] / 1000
        rows.append([name, setting, f"{medians[name]:.1f}", f"{ratio:.2f}", f"{run_s:.0f}"])
    headers = ["recipe", "setting", "ms / update", f"x {BASELINE}", "update time of a run (s)"]
    print(table.markdown_table(headers, rows, align="llrrr"))
    if args.json is not None:
        code = code_version()
        record = {
            "baseline": BASELINE,
            "ratio": {name: medians[name] / medians[BASELINE] for name in names},
            "ms_per_update": medians,
            "task": args.task,
            "action_repeat": args.action_repeat,
            "command": shlex.join(["python", "benchmarks/recipe_update.py", *sys.argv[1:]]),
            "commit": f"{code['commit'] or code['version']}"
            + (" with uncommitted changes" if code["dirty"] else ""),
            "machine": machine(),
        }
        text = json.dumps(record, indent=2) + "\n"
        atomic_write(args.json, lambda tmp: tmp.write_text(text))


if __name__ == "__main__":
    main()
