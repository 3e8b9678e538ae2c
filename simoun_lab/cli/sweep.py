"""``simoun-sweep``: a grid of training runs on Ray Tune, on this machine or a Ray cluster.

    simoun-sweep --preset cpu --grid agent.recipe=simoun,drq,curl --seeds 0-4 --sweep-dir sw
    simoun-sweep --resume --sweep-dir sw              # after Ctrl-C: finish what is unfinished
    simoun-sweep --resume --sweep-dir sw --total-env-steps 200000   # train every trial further
    simoun-sweep --address auto --preset cheetah-run --grid agent.recipe=simoun,drq --seeds 0-4

The base config is given exactly as to ``simoun-train`` (``--preset``, every config flag,
``--set KEY=VALUE``). Each trial is an ordinary run directory ``SWEEP_DIR/<variant>/<env>/s<seed>``;
the report (:mod:`simoun_lab.sweep.report`) is written when the sweep ends. The running is
:mod:`simoun_lab.sweep.launch`'s.
"""

from __future__ import annotations

import json
import sys
from collections.abc import Sequence
from dataclasses import dataclass, field
from datetime import datetime, timezone
from pathlib import Path
from typing import Annotated, Any, Literal

import tyro

from simoun_agent.cli.command_flags import PATH
from simoun_agent.cli.config_flags import (
    ConfigFlags,
    config_default,
    config_switches,
    overrides_from,
)
from simoun_agent.cli.flags import fail, names_full_disk, parse, quiet_pipe
from simoun_agent.cli.other_names import RUN_CONFIG_NAMES, Meant
from simoun_agent.config import RECIPES, SetupError, resolve, to_dict
from simoun_agent.config.device import same_setting
from simoun_agent.config.resolve import flatten
from simoun_agent.config.rules import flag_name
from simoun_agent.run.atomic import space_problem
from simoun_agent.run.kept import present
from simoun_agent.run.layout import CONFIG_NAME
from simoun_agent.run.rundir import check_output_dir, copy_fix
from simoun_lab.engine.ray_start import connect, load_ray
from simoun_lab.engine.trial import check_no_live_runs
from simoun_lab.sweep import report
from simoun_lab.sweep.grid import (
    SWEEP_FILE,
    SweepSpec,
    Trial,
    check_devices,
    check_runnable,
    check_trial_dirs,
    gpus_wanted,
)

PROG = "simoun-sweep"

DESCRIPTION = f"""Run a grid of simoun-train runs (variants x envs x seeds) on Ray Tune, on this
machine or a Ray cluster, then write the report (simoun-report). The base config is given
exactly as to simoun-train (--preset, every config flag, --set KEY=VALUE).

examples:
  simoun-sweep --preset cpu --grid agent.recipe=simoun,drq,curl,sac --seeds 0-4 \\
      --sweep-dir sweeps/baselines
  simoun-sweep --resume --sweep-dir sweeps/baselines
  simoun-sweep --resume --sweep-dir sweeps/baselines --total-env-steps 1000000
  simoun-sweep --address auto --preset walker-walk --grid agent.recipe=simoun,drq \\
      --seeds 0-4 --sweep-dir /shared/sweeps/walker

agent recipes (--grid agent.recipe=A,B): {", ".join(RECIPES)}

Each trial runs in SWEEP_DIR/<variant>/<env>/s<seed>, an ordinary run directory."""


SEED_LIST = "list the seeds in one word, e.g. --seeds 1,2,3 or a range, --seeds 0-4"

OTHER_NAMES = RUN_CONFIG_NAMES | {
    "seed": Meant(note=f"a trial has one seed; for several, {SEED_LIST}"),
    "seeds": Meant(note=SEED_LIST),
    "envs": Meant(note="list the ids in one word, e.g. --envs highway-v0,merge-v0"),
    "log-dir": Meant(("--sweep-dir",), "every trial's run directory goes under it"),
    "logdir": Meant(("--sweep-dir",), "every trial's run directory goes under it"),
    "exp-name": Meant(("--sweep-dir",), "a sweep is named by its directory"),
    "local-dir": Meant(("--sweep-dir",)),
    "storage-path": Meant(("--sweep-dir",)),
    "num-samples": Meant(("--seeds",), "every variant runs once per seed"),
}
"""Other libraries' flags (Ray Tune's too) with what simoun-sweep calls them
(:mod:`simoun_agent.cli.other_names`); ``seed``, ``seeds`` and ``envs`` say how to give
several."""


@dataclass
class SweepCommand:
    """What ``simoun-sweep`` is asked: the grid, where and how to run it, and the base config."""

    sweep_dir: Annotated[str | None, PATH, tyro.conf.arg(metavar="DIR")] = None
    """where the runs and the report go (none: sweeps/<UTC time>; required with --resume); on a
    cluster, a directory every machine sees"""
    grid: Annotated[
        tuple[str, ...], tyro.conf.UseAppendAction, tyro.conf.arg(metavar="KEY=V1,V2")
    ] = ()
    """a config key and the values to try (the variants are the product), e.g. --grid
    agent.recipe=simoun,drq"""
    seeds: Annotated[str | None, tyro.conf.arg(metavar="SEEDS")] = None
    """seeds of each variant, e.g. 0-4 or 0,2,5 (none: --seed)"""
    envs: Annotated[str | None, tyro.conf.arg(metavar="ID,ID")] = None
    """Gymnasium ids to run every variant on (none: --env)"""
    cpus_per_trial: Annotated[int | None, tyro.conf.arg(metavar="N")] = None
    """CPUs per trial; the trial uses as many torch threads (none: 1)"""
    gpus_per_trial: Annotated[str, tyro.conf.arg(metavar="N|auto")] = "auto"
    """GPUs per trial, fractions allowed; auto: 1 when the cluster has GPUs and --device is not
    cpu, else 0"""
    address: Annotated[str | None, tyro.conf.arg(metavar="auto|HOST:PORT|ray://HOST:PORT")] = None
    """run on a Ray cluster (auto: the one `ray start` made on this machine); none: the cluster
    that RAY_ADDRESS names, or a local Ray instance without it"""
    num_cpus: Annotated[int | None, tyro.conf.arg(metavar="N")] = None
    """CPUs of the local Ray instance (none: this machine's); not with a cluster's address"""
    resume: Annotated[bool, tyro.conf.FlagCreatePairsOff] = False
    """continue the sweep in --sweep-dir: finished trials are skipped, the others go on from
    their checkpoints; with a larger --total-env-steps every trial, finished ones too, trains on
    to it"""
    verbose: Literal[0, 1, 2] = 1
    """Tune's output"""
    flags: Annotated[ConfigFlags, tyro.conf.arg(name="")] = field(default_factory=ConfigFlags)
    """the base config of every trial"""


def sweep_spec(args: SweepCommand, base: dict[str, Any], sweep_dir: Path) -> SweepSpec:
    """The sweep to run: from the flags (``base``: the config overrides they give), or the saved
    one on ``--resume`` (which the flags, when given, must match; ``--total-env-steps`` alone may
    differ, and extends every trial to the new budget)."""
    if sweep_dir.exists() and not sweep_dir.is_dir():
        raise SetupError(
            f"--sweep-dir {sweep_dir} is a file, not a directory; pass a new directory, or with "
            "--resume the directory of the sweep"
        )
    preset = args.flags.preset
    if not args.resume:
        if (sweep_dir / SWEEP_FILE).exists():
            raise SetupError(
                f"{sweep_dir} already holds a sweep; continue it with --resume, or pass another "
                "--sweep-dir"
            )
        if sweep_dir.exists() and any(sweep_dir.iterdir()):
            raise SetupError(f"{sweep_dir} is not empty; pass a new --sweep-dir")
        cpus = 1 if args.cpus_per_trial is None else args.cpus_per_trial
        return SweepSpec.create(preset, base, list(args.grid), args.seeds, args.envs, cpus)
    saved = SweepSpec.load(sweep_dir)
    total = base.get("total_env_steps")
    wanted = saved if total is None else saved.extended(total)
    given = bool(args.grid or args.seeds or args.envs or preset or set(base) - {"total_env_steps"})
    if given or args.cpus_per_trial not in (None, saved.cpus_per_trial):
        spec = SweepSpec.create(
            preset,
            base,
            list(args.grid),
            args.seeds,
            args.envs,
            saved.cpus_per_trial if args.cpus_per_trial is None else args.cpus_per_trial,
        )
        differences = resume_differences(args, base, spec, wanted)
        if differences:
            raise SetupError(
                f"the sweep in {sweep_dir} was started with another grid, so --resume cannot "
                f"continue it ({'; '.join(differences)}); give the flags it was started with (or "
                f"only --resume --sweep-dir {sweep_dir}), or start a new sweep in another "
                "--sweep-dir"
            )
    return wanted


def resume_differences(
    args: SweepCommand, base: dict[str, Any], given: SweepSpec, saved: SweepSpec
) -> list[str]:
    """What the flags given with ``--resume`` (read into ``given``, ``base`` the config keys
    they set) change in the ``saved`` sweep, one line per flag and only for the flags given, in
    the order of the command line's help: the preset, the grid, the seeds, the envs, each base
    config flag, the CPUs."""
    lines = []
    seeds_flag = "--seeds" if args.seeds is not None else "--seed" if "seed" in base else None
    envs_flag = "--envs" if args.envs is not None else "--env" if "env" in base else None
    for flag, name in (
        ("--preset" if args.flags.preset is not None else None, "preset"),
        ("--grid" if args.grid else None, "grid"),
        (seeds_flag, "seeds"),
        (envs_flag, "envs"),
    ):
        mine, theirs = getattr(given, name), getattr(saved, name)
        if flag and mine != theirs:
            lines.append(f"{flag}: saved {json.dumps(theirs)}, given {json.dumps(mine)}")
    lines += base_differences(base, saved)
    if args.cpus_per_trial not in (None, saved.cpus_per_trial):
        lines.append(f"--cpus-per-trial: saved {saved.cpus_per_trial}, given {args.cpus_per_trial}")
    return lines


def base_differences(base: dict[str, Any], saved: SweepSpec) -> list[str]:
    """Each base config flag of ``base`` whose value differs from the ``saved`` sweep's (its base
    config's, or its preset's or the default when the base leaves the key out); the seed, env and
    ``--total-env-steps`` are compared elsewhere."""
    effective = flatten(to_dict(resolve(saved.preset, saved.base)))
    lines = []
    for key, value in base.items():
        if key in ("seed", "env", "total_env_steps"):
            continue
        name = key.rpartition(".")[2]
        flag = flag_name(key.removesuffix(name), name)
        mine = plain(value)
        if key in saved.grid:
            theirs = f"{json.dumps(saved.grid[key])} (its --grid)"
        elif not same_setting(key, plain(effective.get(key)), mine):
            theirs = json.dumps(plain(effective.get(key)))
        else:
            continue
        lines.append(f"{flag}: saved {theirs}, given {json.dumps(mine)}")
    return lines


def plain(value: Any) -> Any:
    """A config value in its JSON form (tuples as lists), to compare a flag with a saved one."""
    return json.loads(json.dumps(value))


@names_full_disk(
    PROG,
    "pass --sweep-dir DIR on another disk (a sweep resumed: copy it there and resume the copy)",
)
@quiet_pipe
def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``simoun-sweep``."""
    argv = list(sys.argv[1:] if argv is None else argv)
    try:
        default = SweepCommand(flags=ConfigFlags(config=config_default(argv)))
    except SetupError as err:
        fail(PROG, err)
    args = parse(
        SweepCommand, argv, PROG, DESCRIPTION, default, config_switches(), other_names=OTHER_NAMES
    )
    if args.resume and not args.sweep_dir:
        fail(PROG, "--resume needs the --sweep-dir of the sweep")
    stamp = datetime.now(timezone.utc).strftime("%Y%m%d-%H%M%S")
    # absolute: Tune runs each trial in a working directory of its own
    sweep_dir = Path(args.sweep_dir or Path("sweeps") / stamp).absolute()
    try:
        check_sweep_place(Path(args.sweep_dir) if args.sweep_dir else sweep_dir)
        # the grid is read before Ray is imported (seconds): a typo is answered at once
        spec = sweep_spec(args, overrides_from(args.flags, argv, SweepCommand), sweep_dir)
        check_no_live_runs(sweep_dir, "the sweep", "trial")
        check_trial_dirs(spec, sweep_dir)
        resumed = copy_fix(sweep_dir, "simoun-sweep --resume --sweep-dir")
        check_output_dir(sweep_dir, "--sweep-dir", fix=resumed if args.resume else None)
        check_devices(spec.trials(sweep_dir), gpus_wanted(args.gpus_per_trial), spec.grid)
        ray = load_ray()
    except SetupError as err:
        fail(PROG, err)
    # the trainer (torch) once the flags are read: --help and a bad flag take about a second
    from simoun_lab.sweep.launch import (
        check_fits,
        gpus_per_trial,
        run_sweep,
        stop_trials_on_sigterm,
        summarize,
    )
    from simoun_lab.sweep.trainable import STOP_FILE, finished

    todo = [trial for trial in spec.trials(sweep_dir) if not finished(trial)]
    done = len(spec.trials(sweep_dir)) - len(todo)
    try:
        check_finished_trials([trial for trial in spec.trials(sweep_dir) if trial not in todo])
        check_runnable(todo, "--envs" if args.envs or len(spec.envs) > 1 else "--env", spec.grid)
    except SetupError as err:
        fail(PROG, err)
    print(f"sweep {sweep_dir}: {len(todo)} trials to run, {done} already finished", flush=True)
    terminated: list[bool] = []
    if todo:
        started = False
        try:
            started = connect(ray, args.address, args.num_cpus)
            device = spec.base.get("device", resolve(spec.preset, {}).device)
            gpus = gpus_per_trial(ray, args.gpus_per_trial, device)
            check_fits(ray, spec.cpus_per_trial, gpus)
            sweep_dir.mkdir(parents=True, exist_ok=True)
            if not (sweep_dir / SWEEP_FILE).exists() or SweepSpec.load(sweep_dir) != spec:
                spec.save(sweep_dir)
            (sweep_dir / STOP_FILE).unlink(missing_ok=True)
            with stop_trials_on_sigterm(sweep_dir) as came:
                terminated = came
                outcome = run_sweep(ray, spec, sweep_dir, gpus, args.verbose)
        except SetupError as err:
            fail(PROG, err)
        except KeyboardInterrupt:
            outcome = {"stopped": todo}
        finally:
            if started:
                ray.shutdown()
    else:
        outcome = {}
    written, unwritten = closing_report(spec, sweep_dir)
    return summarize(outcome, sweep_dir, written, bool(terminated), unwritten=unwritten)


def check_sweep_place(sweep_dir: Path) -> None:
    """Refuse a --sweep-dir (as given) inside another sweep's directory or inside a study's
    archive: the trials would mix into that sweep's or study's runs and records. One that is
    such a folder itself is refused as not empty, or, with --resume, as holding no sweep."""
    from simoun_lab.study.owner import check_not_in_sweep, check_not_inside_study

    check_not_inside_study(sweep_dir, "--sweep-dir")
    check_not_in_sweep(sweep_dir, "--sweep-dir", inside_only=True)


def check_finished_trials(trials: list[Trial]) -> None:
    """SetupError naming the first of the finished ``trials`` whose files the report cannot
    read (:func:`~simoun_lab.sweep.report.read_run`: an eval.csv that is a Git LFS pointer, a
    summary.json cut short), before any trial trains: the sweep would count it finished and
    end without its report."""
    for trial in trials:
        run_dir = Path(trial.run_dir)
        try:
            report.read_run(run_dir / CONFIG_NAME)
        except report.DamagedRun as err:
            raise SetupError(
                f"trial {trial.name} is finished, but its run {run_dir} cannot be read: {err}; "
                "restore the file from a copy, or move the run directory aside (mv "
                f"{run_dir} {run_dir}.aside) so that the trial trains anew"
            ) from None


def closing_report(spec: SweepSpec, sweep_dir: Path) -> tuple[list[Path], str | None]:
    """The report the sweep writes at its end (``SWEEP_DIR/report``): its files, and why it
    could not be written, a full disk included (None when it was, or when no trial got as far
    as its config.json: nothing to report, which the trials' own lines say)."""
    if not any(present(Path(trial.run_dir) / CONFIG_NAME) for trial in spec.trials(sweep_dir)):
        return [], None
    try:
        return report.write_report(sweep_dir, flag=None), None
    except SetupError as err:
        return [], f"{err}; then write it with: simoun-report {sweep_dir}"
    except OSError as err:  # a full disk: the trials are done, only their report is to write
        problem = space_problem(err)
        if problem is None:
            raise
        return [], f"{problem} (or write the report with: simoun-report {sweep_dir})"


if __name__ == "__main__":
    sys.exit(main())
