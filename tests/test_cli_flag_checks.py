"""Every command line, subcommands included, checks its flags the same way before anything
runs: an unknown flag is named with the flags it most likely meant (by meaning as well as
spelling), an option given twice with different values is refused, a word after a switch is
named with the switch, an empty value, a switch given a value, a stray argument and a path
too long for the file system are named; the driving references check every value before an
episode."""

import os
from pathlib import Path

import pytest
import torch
from other_users import restored, run_as_user, unwritable

from simoun_agent.cli import eval as eval_cli
from simoun_agent.cli import train as train_cli
from simoun_agent.cli.command_flags import command_flags
from simoun_agent.cli.other_names import RUN_CONFIG_NAMES
from simoun_agent.run import driving_reference
from simoun_lab.cli import analyze as analyze_cli
from simoun_lab.cli import report as report_cli
from simoun_lab.cli import study as study_cli
from simoun_lab.cli import sweep as sweep_cli
from simoun_lab.minigrid_study import __main__ as minigrid_cli
from simoun_lab.sweep.grid import SweepSpec

MINIGRID = "python -m simoun_lab.minigrid_study"
DRIVING = "python -m simoun_agent.run.driving_reference"


def refused(capsys, main, argv) -> str:
    """The error ``main`` prints for ``argv``, refused with status 2 and no traceback."""
    with pytest.raises(SystemExit) as stop:
        main(argv)
    assert stop.value.code == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err
    return err


@pytest.mark.parametrize(
    ("main", "argv", "said"),
    [
        (sweep_cli.main, ["--learning-rat", "3e-4"], "unknown flag --learning-rat (did you "
         "mean --agent.lr?); `simoun-sweep --help` lists every flag"),
        (sweep_cli.main, ["--sweepdir", "x"], "(did you mean --sweep-dir?)"),
        (eval_cli.main, ["RUN", "--num-episodes", "3"], "unknown flag --num-episodes (did you "
         "mean --episodes?); `simoun-eval --help`"),
        (report_cli.main, ["DIR", "--at-stpe", "5"], "(did you mean --at-step"),
        (study_cli.main, ["plan", "spec.toml", "--probe-update", "1"], "unknown flag "
         "--probe-update (did you mean --probe-updates?); `simoun-study plan --help`"),
        (analyze_cli.main, ["masks", "RUN", "--step", "2"], "(did you mean --steps?); "
         "`simoun-analyze masks --help`"),
        (minigrid_cli.main, ["report", "--archiv", "x"], "unknown flag --archiv (did you mean "
         f"--archive?); `{MINIGRID} report --help`"),
        (minigrid_cli.main, ["probe", "--settings.stesp", "3"], "--settings.steps"),
        (driving_reference.main, ["--episdoes", "2"], "(did you mean --episodes?)"),
        (train_cli.main, ["--xyzzy"], "unknown flag --xyzzy; `simoun-train --help`"),
        (train_cli.main, ["--frame-size", "64"], "unknown flag --frame-size (did you mean "
         "--image-size?)"),
        (train_cli.main, ["--resolution", "64"], "unknown flag --resolution (did you mean "
         "--image-size?)"),
        (train_cli.main, ["--frame-skip", "4"], "calls it --action-repeat"),
        (eval_cli.main, ["RUN", "--action-repeat", "2"], "--action-repeat is not a flag of "
         "simoun-eval: action_repeat is a setting of the run, saved in its config.json, and "
         "simoun-eval uses the run's own; it is chosen when the run is trained (simoun-train "
         "--action-repeat ...)"),
        (eval_cli.main, ["RUN", "--env", "Pendulum-v1"], "--env is not a flag of simoun-eval"),
        (eval_cli.main, ["RUN", "--agent.no-curiosity"], "agent.curiosity is a setting of the "
         "run"),
        (eval_cli.main, ["RUN", "--eval-episodes", "5"], "--eval-episodes is simoun-train's "
         "flag (episodes per evaluation (deterministic actions)), not simoun-eval's; "
         "simoun-eval has --episodes (episodes to play)"),
    ],
)  # fmt: skip
def test_every_command_names_the_flag_an_unknown_one_meant(main, argv, said, capsys):
    assert said in refused(capsys, main, argv)


@pytest.mark.parametrize(
    ("main", "argv", "said"),
    [
        (study_cli.main, ["run", "s.toml", "--study-dir", "a", "--study-dir", "b"],
         "--study-dir is given twice with different values (--study-dir a and --study-dir b)"),
        (study_cli.main, ["plan", "s.toml", "--probe-updates=1", "--probe-updates", "2"],
         "--probe-updates is given twice"),
        (minigrid_cli.main, ["run", "--work-dir", "a", "--work-dir", "b"],
         "--work-dir is given twice"),
        (analyze_cli.main, ["masks", "RUN", "--out", "a", "--out", "b"], "--out is given twice"),
        (analyze_cli.main, ["bias", "RUN", "--overwrite", "--pairs", "1", "--pairs", "2"],
         "--pairs is given twice"),
        (sweep_cli.main, ["--seeds", "1", "--seeds", "2"], "--seeds is given twice"),
        (driving_reference.main, ["--episodes", "1", "--episodes", "2"],
         "--episodes is given twice"),
    ],
)  # fmt: skip
def test_a_subcommand_option_given_twice_is_refused(main, argv, said, capsys):
    err = refused(capsys, main, argv)
    assert said in err and "give it once" in err


@pytest.mark.parametrize(
    ("main", "argv", "said"),
    [
        (minigrid_cli.main, ["Run", "--archive", "mg"],
         f"unknown subcommand 'Run' (did you mean run?); {MINIGRID} takes one of run, report, "
         f"select, probe first, e.g. `{MINIGRID} run --help`"),
        (study_cli.main, ["Plan", "s.toml"], "unknown subcommand 'Plan' (did you mean plan?)"),
        (analyze_cli.main, ["mask", "RUN"], "unknown subcommand 'mask' (did you mean masks?)"),
        (study_cli.main, ["--study-dir", "a", "run", "s.toml"],
         "--study-dir comes before the subcommand; simoun-study takes its subcommand first (put "
         "run before --study-dir)"),
        (minigrid_cli.main, ["--archive", "mg"], "(name one of run, report, select, probe)"),
    ],
)  # fmt: skip
def test_a_word_that_is_no_subcommand_is_named_with_the_close_ones(main, argv, said, capsys):
    assert said in refused(capsys, main, argv)


def test_the_same_subcommand_option_twice_with_one_value_is_kept(capsys):
    # refused for the missing spec, not for the option given twice alike
    err = refused(capsys, study_cli.main, ["plan", "s.toml", "--probe-updates", "1",
                                           "--probe-updates", "1"])  # fmt: skip
    assert "cannot read the study spec s.toml" in err


def test_a_word_after_a_switch_names_the_switch(capsys):
    err = refused(capsys, train_cli.main, ["--progress", "maybe"])
    assert "--progress is a switch: it takes true or false" in err and "'maybe'" in err


def test_set_without_a_key_shows_the_form(capsys):
    err = refused(capsys, train_cli.main, ["--set", "=3"])
    assert "--set takes KEY=VALUE, got '=3'; e.g. --set agent.lr=3e-4" in err


@pytest.mark.parametrize(
    ("argv", "said"),
    [
        (["--episodes", "0"], "--episodes must be 1 or more, got 0"),
        (["--seed", "-1"], "--seed must be 0 or more, got -1"),
        (["--preset", "cpu"], "--preset cpu trains on dm_control/cartpole-swingup-v0, not "
         "highway-env: the reference drivers steer a highway-env car; choose one of highway, "
         "highway-cpu"),
        (["--preset", "cpux"], "--preset 'cpux': unknown preset; choose one of highway, "
         "highway-cpu\n"),
        (["--preset", "HIGHWAY-CPU"], "--preset 'HIGHWAY-CPU': unknown preset (did you mean "
         "'highway-cpu'?); choose one of highway, highway-cpu\n"),
        (["--video", "lane.txt"], "--video lane.txt: a video is written as .gif or .mp4"),
        (["--video", "nowhere/lane.gif"], "the folder nowhere does not exist"),
        (["--json", "refs.csv"], "--json refs.csv: the metrics file is written as .json"),
        (["--json", "nowhere/references.json"], "the folder nowhere does not exist"),
        (["--video", "/proc/lane.gif"], "cannot write to the output directory /proc"),
    ],
)  # fmt: skip
def test_the_driving_references_check_every_value_before_playing(argv, said, capsys, tmp_path,
                                                                 monkeypatch):  # fmt: skip
    monkeypatch.chdir(tmp_path)
    assert said in refused(capsys, driving_reference.main, argv)
    assert list(tmp_path.iterdir()) == []


def test_driving_references_write_over_no_file_but_their_own(capsys, tmp_path):
    run_config = tmp_path / "config.json"
    run_config.write_text('{"env": "highway-fast-v0"}\n')
    (tmp_path / "dir.json").mkdir()
    said = {
        run_config: "it is a file this command did not write, so writing the metrics there",
        tmp_path / "dir.json": "it is a directory, not a regular file",
    }
    for path, text in said.items():
        err = refused(capsys, driving_reference.main, ["--episodes", "1", "--json", str(path)])
        assert f"--json {path}: {text}" in err and "pass a new path" in err, err
    assert run_config.read_text() == '{"env": "highway-fast-v0"}\n'
    ours = tmp_path / "references.json"
    args = driving_reference.DrivingReferenceCommand(episodes=1, json=ours)
    metrics = {"zero": {"return_mean": 1.0}}
    ours.write_text(driving_reference.references_json(args, driving_reference.PROG, metrics))
    driving_reference.check_replaceable(ours)  # a file it wrote is measured anew


@pytest.mark.parametrize(
    ("main", "argv", "flag"),
    [
        (eval_cli.main, ["RUN", "--episodes", "9" * 30], "--episodes"),
        (eval_cli.main, ["RUN", "--torch-threads=" + "9" * 30], "--torch-threads"),
        (report_cli.main, ["DIR", "--at-step", str(2**63)], "--at-step"),
        (analyze_cli.main, ["masks", "RUN", "--episodes", "-" + "9" * 30], "--episodes"),
        (study_cli.main, ["run", "s.toml", "--study-dir", "s", "--num-cpus", "9" * 30],
         "--num-cpus"),
        (minigrid_cli.main, ["run", "--concurrent", "9" * 30], "--concurrent"),
        (driving_reference.main, ["--seed", "9" * 30], "--seed"),
    ],
)  # fmt: skip
def test_a_number_past_int64_is_refused_naming_its_flag(main, argv, flag, capsys):
    err = refused(capsys, main, argv)
    assert f"{flag} " in err and "below 2**63); give a smaller number" in err, err


def test_an_output_directory_flag_given_a_file_is_refused_before_work(tmp_path, capsys):
    spec, taken = tmp_path / "spec.toml", tmp_path / "taken"
    spec.write_text(Path("docs/studies/dmc100k.toml").read_text())
    taken.write_text("")
    err = refused(capsys, study_cli.main, ["run", str(spec), "--study-dir", str(taken)])
    assert f"the output directory {taken} is a file" in err and "--study-dir" in err
    err = refused(capsys, sweep_cli.main, ["--preset", "cpu", "--sweep-dir", str(taken)])
    assert f"--sweep-dir {taken} is a file, not a directory" in err


def test_the_probe_takes_only_a_minigrid_task(tmp_path, capsys):
    argv = ["probe", "--settings.env-id", "Pendulum-v1", "--out", str(tmp_path / "p")]
    err = refused(capsys, minigrid_cli.main, argv)
    assert "--settings.env-id Pendulum-v1: must be a registered MiniGrid id" in err


@pytest.mark.parametrize(("value", "said"), [("", "--gpus-per-trial is given an empty value"),
                                             ("nan", "must be a finite number"),
                                             ("inf", "must be a finite number")])  # fmt: skip
def test_gpus_per_trial_is_read_before_ray_starts(value, said, tmp_path, capsys):
    argv = ["--preset", "cpu", "--sweep-dir", str(tmp_path / "s"), "--gpus-per-trial", value]
    assert said in refused(capsys, sweep_cli.main, argv)
    assert not (tmp_path / "s").exists()


LONG_NAME = "a" * 300
LONG_PATH = "/".join(["b" * 200] * 25)


@pytest.mark.parametrize("blank", ["", "  "])
@pytest.mark.parametrize(
    ("main", "argv", "flag"),
    [
        (train_cli.main, ["--run-dir"], "--run-dir"),
        (train_cli.main, ["--resume"], "--resume"),
        (train_cli.main, ["--env"], "--env"),
        (train_cli.main, ["--preset"], "--preset"),
        (train_cli.main, ["--eval-distraction"], "--eval-distraction"),
        (eval_cli.main, ["RUN", "--out"], "--out"),
        (eval_cli.main, ["RUN", "--device"], "--device"),
        (sweep_cli.main, ["--sweep-dir"], "--sweep-dir"),
        (sweep_cli.main, ["--seeds"], "--seeds"),
        (report_cli.main, ["DIR", "--out"], "--out"),
        (study_cli.main, ["run", "s.toml", "--study-dir"], "--study-dir"),
        (study_cli.main, ["run", "s.toml", "--study-dir", "s", "--archive"], "--archive"),
        (analyze_cli.main, ["masks", "RUN", "--out"], "--out"),
        (analyze_cli.main, ["bias", "RUN", "--out"], "--out"),
        (minigrid_cli.main, ["run", "--archive"], "--archive"),
        (minigrid_cli.main, ["probe", "--out"], "--out"),
        (minigrid_cli.main, ["probe", "--settings.env-id"], "--settings.env-id"),
    ],
)  # fmt: skip
def test_an_empty_or_blank_value_is_refused_naming_its_flag(main, argv, flag, blank, capsys,
                                                            tmp_path, monkeypatch):  # fmt: skip
    monkeypatch.chdir(tmp_path)
    for given in ([*argv, blank], [*argv[:-1], f"{argv[-1]}={blank}"]):
        err = refused(capsys, main, given)
        assert f"{flag} is given an empty value ({blank!r}); give {flag} a value" in err, err
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    ("main", "argv", "name"),
    [
        (eval_cli.main, [""], "RUN"),
        (report_cli.main, ["  "], "DIR"),
        (study_cli.main, ["plan", ""], "SPEC"),
        (analyze_cli.main, ["bias", "RUN", " "], "RUN"),
    ],
)
def test_an_empty_positional_argument_is_refused_naming_it(main, argv, name, capsys):
    assert f"{name} is given an empty value" in refused(capsys, main, argv)


@pytest.mark.parametrize(
    ("main", "argv", "said"),
    [
        (eval_cli.main, ["RUN", "--no-progress=false"], "--no-progress takes no value; give "
         "--no-progress alone, or --progress=true / --progress=false"),
        (train_cli.main, ["--agent.no-curiosity=true"], "--agent.no-curiosity takes no value"),
        (sweep_cli.main, ["--no-video=1"], "--no-video takes no value"),
        (train_cli.main, ["--overwrite=true"], "--overwrite is a switch and takes no value; "
         "give --overwrite alone, or leave it out"),
        (eval_cli.main, ["RUN", "--random-policy=1"], "--random-policy is a switch"),
        (sweep_cli.main, ["--resume=false"], "--resume is a switch and takes no value"),
        (study_cli.main, ["run", "s.toml", "--study-dir", "s", "--allow-other-commit=no"],
         "--allow-other-commit is a switch and takes no value"),
        (analyze_cli.main, ["masks", "RUN", "--overwrite=1"], "--overwrite is a switch"),
        (train_cli.main, ["--overwrite", "true"], "--overwrite is a switch and takes no value"),
        (sweep_cli.main, ["--resume", "yes"], "--resume is a switch and takes no value"),
    ],
)  # fmt: skip
def test_a_switch_given_a_value_says_it_takes_none(main, argv, said, capsys):
    assert said in refused(capsys, main, argv)


@pytest.mark.parametrize(
    ("main", "argv", "said"),
    [
        (train_cli.main, ["foo"], "unexpected argument 'foo': simoun-train takes no positional "
         "argument"),
        (sweep_cli.main, ["--seed", "1", "foo"], "unexpected argument 'foo': simoun-sweep"),
        (report_cli.main, ["DIR", "extra"], "unexpected argument 'extra': simoun-report takes "
         "only DIR"),
        (eval_cli.main, ["A", "--episodes", "1", "B"], "unexpected argument 'B': simoun-eval "
         "takes only RUN [RUN ...], all together before or after the flags"),
        (study_cli.main, ["plan", "a.toml", "b.toml"], "unexpected argument 'b.toml': "
         "simoun-study plan takes only SPEC"),
        (analyze_cli.main, ["masks", "RUN", "extra"], "unexpected argument 'extra'"),
        (minigrid_cli.main, ["report", "extra"], "unexpected argument 'extra'"),
    ],
)  # fmt: skip
def test_a_stray_argument_is_refused_naming_it(main, argv, said, capsys):
    assert said in refused(capsys, main, argv)


@pytest.mark.parametrize(
    ("main", "argv", "said"),
    [
        (train_cli.main, ["--buffer-size", "100000"], "unknown flag --buffer-size: simoun-train "
         "calls it --replay-capacity (transitions kept in the replay buffer)"),
        (train_cli.main, ["--Buffer_Size", "100000"], "calls it --replay-capacity"),
        (train_cli.main, ["--log-dir", "logs"], "simoun-train calls it --run-dir"),
        (train_cli.main, ["--exp-name", "mine"], "simoun-train calls it --run-dir"),
        (train_cli.main, ["--save-freq", "20"], "simoun-train calls it --checkpoint-every"),
        (train_cli.main, ["--train-freq", "2"], "simoun-train calls it "
         "--agent.update-every-steps (the agent's gradient step(s) come at every this-many-th "
         "agent step once learning has started) or --updates-per-step (gradient updates per "
         "agent decision once learning has started)"),
        (train_cli.main, ["--num-envs", "4"], "unknown flag --num-envs: not supported here: a "
         "run steps one environment (there are no vectorised envs); to train several runs at "
         "once, simoun-sweep runs them as parallel trials"),
        (train_cli.main, ["--seeds", "1"], "simoun-train calls it --seed (seed of every random "
         "stream); a run has one seed; for several, simoun-sweep --seeds 1,2,3"),
        (eval_cli.main, ["--run-dir", "runs/a", "--episodes", "1", "--no-video"], "unknown flag "
         "--run-dir: RUN is a positional argument of simoun-eval, given without a flag: "
         "simoun-eval runs/a --episodes 1 --no-video"),
        (eval_cli.main, ["--checkpoint=runs/a/checkpoint.pt"], "given without a flag: "
         "simoun-eval runs/a/checkpoint.pt"),
        (eval_cli.main, ["RUN", "--buffer-size", "3"], "--buffer-size is not a flag of "
         "simoun-eval: replay_capacity is a setting of the run"),
        (eval_cli.main, ["RUN", "--deterministic"], "not supported here: simoun-eval always "
         "plays the agent's deterministic action"),
        (sweep_cli.main, ["--log-dir", "x"], "simoun-sweep calls it --sweep-dir"),
        (study_cli.main, ["run", "--config", "s.toml", "--study-dir", "d"], "SPEC is a "
         "positional argument of simoun-study run, given without a flag: simoun-study run "
         "s.toml --study-dir d"),
        (report_cli.main, ["--log-dir", "runs"], "DIR is a positional argument of "
         "simoun-report, given without a flag: simoun-report runs"),
        (analyze_cli.main, ["masks", "--run-dir", "r"], "given without a flag: simoun-analyze "
         "masks r"),
        (minigrid_cli.main, ["run", "--log-dir", "x"], f"{MINIGRID} run calls it --work-dir"),
    ],
)  # fmt: skip
def test_another_librarys_flag_is_named_with_this_commands_own(main, argv, said, capsys):
    assert said in refused(capsys, main, argv)


@pytest.mark.parametrize(
    ("main", "argv", "said"),
    [
        (train_cli.main, ["--no-curiosity"], "unknown flag --no-curiosity (did you mean "
         "--agent.no-curiosity?)"),
        (sweep_cli.main, ["--disable-video"], "(did you mean --no-video?)"),
        (train_cli.main, ["--no-eval"], "unknown flag --no-eval; "),
    ],
)  # fmt: skip
def test_a_negated_flag_is_offered_only_negations(main, argv, said, capsys):
    assert said in refused(capsys, main, argv)


def test_every_other_names_table_names_flags_of_its_command():
    commands = [
        (train_cli.TrainCommand, train_cli.OTHER_NAMES, [[]]),
        (eval_cli.EvalCommand, eval_cli.OTHER_NAMES, [[]]),
        (sweep_cli.SweepCommand, sweep_cli.OTHER_NAMES, [[]]),
        (study_cli.Command, study_cli.OTHER_NAMES, [["plan"], ["run"], ["report"]]),
        (minigrid_cli.Command, minigrid_cli.OTHER_NAMES, [["run"], ["report"], ["probe"]]),
    ]
    for command, table, argvs in commands:
        known = {name for argv in argvs for name in command_flags(command, argv)}
        for name, meant in table.items():
            run_config = command is eval_cli.EvalCommand and name in RUN_CONFIG_NAMES
            assert run_config or set(meant.flags) <= known, (name, meant.flags)


@pytest.mark.parametrize(
    ("main", "argv", "said"),
    [
        (train_cli.main, ["--env-kwargs", '{"size": 32}', '{"max_steps": 5}'], "--env-kwargs "
         """takes one value, so '{"max_steps": 5}' after '{"size": 32}' is left over: put every """
         """key in one JSON object, e.g. --env-kwargs '{"size": 32, "max_steps": 5}'"""),
        (train_cli.main, ["--seed", "1", "2", "3"], "--seed takes one value, so '2' after '1' "
         "is left over: a run has one seed; for several, simoun-sweep --seeds 1,2,3 trains one "
         "run per seed"),
        (train_cli.main, ["--set", "agent.lr=1e-3", "agent.n_step=3"], "give --set once per "
         "value, e.g. --set agent.lr=1e-3 --set agent.n_step=3"),
        (train_cli.main, ["--env", "a", "b"], "--env takes one value, so 'b' after 'a' is left "
         "over"),
        (sweep_cli.main, ["--seeds", "1", "2", "3"], "--seeds takes one value, so '2' after '1' "
         "is left over: list the seeds in one word, e.g. --seeds 1,2,3 or a range, --seeds 0-4"),
        (sweep_cli.main, ["--seed", "1", "2"], "for several, list the seeds in one word"),
        (eval_cli.main, ["RUN", "--distraction", "train", "video_hard"], "--distraction takes "
         "one value, so 'video_hard' after 'train' is left over: comma-separate the modes"),
        (eval_cli.main, ["RUN", "--episodes", "1", "2"], "--episodes takes one value"),
        (report_cli.main, ["DIR", "--at-step", "1", "2"], "--at-step takes one value"),
        (report_cli.main, ["DIR", "100"], "unexpected argument '100': simoun-report takes only "
         "DIR; a number goes with the flag it is for, e.g. --at-step 100"),
    ],
)  # fmt: skip
def test_a_second_value_is_named_with_the_flag_that_takes_one(main, argv, said, capsys):
    assert said in refused(capsys, main, argv)


def test_a_number_where_a_run_goes_is_named_as_a_flags_value(tmp_path, capsys):
    said = refused(capsys, eval_cli.main, [str(tmp_path), "1", "--no-video"])
    assert (
        "'1' is not a RUN (no such file or directory) but a number, which simoun-eval does "
        "not take bare: a number goes with the flag it is for, e.g. --episodes 1 (episodes to "
        "play)" in said
    )


@pytest.mark.parametrize(
    ("main", "argv", "said"),
    [
        (train_cli.main, ["--no-video", "agent.lr=1e-3"], "--no-video is a switch and takes no "
         "value, and a KEY=VALUE setting is not given bare: write --set agent.lr=1e-3 or "
         "--agent.lr 1e-3; got 'agent.lr=1e-3'"),
        (train_cli.main, ["agent.lr=1e-3"], "unexpected argument 'agent.lr=1e-3': simoun-train "
         "takes no positional argument (every value goes with its --flag); a KEY=VALUE setting "
         "is not given bare: write --set agent.lr=1e-3 or --agent.lr 1e-3"),
        (train_cli.main, ["--overwrite", "+agent.batch_size=8"], "write --set "
         "agent.batch_size=8 or --agent.batch-size 8"),
        (sweep_cli.main, ["--resume", "seed=3"], "write --set seed=3 or --seed 3"),
        (eval_cli.main, ["RUN", "--no-video", "episodes=3"], "a KEY=VALUE setting is not given "
         "bare: write --episodes 3"),
        (train_cli.main, ["--", "agent.lr=1e-3"], "unexpected argument 'agent.lr=1e-3': "
         "simoun-train takes no positional argument (every value goes with its --flag); a "
         "KEY=VALUE setting is not given bare: write --set agent.lr=1e-3 or --agent.lr 1e-3"),
        (train_cli.main, ["--no-video", "--", "foo"], "unexpected argument 'foo': simoun-train "
         "takes no positional argument (every value goes with its --flag); `simoun-train "
         "--help` lists its flags"),
        (eval_cli.main, ["RUN", "episodes=1", "--no-video"], "'episodes=1' is not a RUN (no such "
         "file or directory) but a KEY=VALUE setting, which simoun-eval does not take bare: it "
         "takes options as flags; write --episodes 1"),
        (eval_cli.main, ["episodes=1", "RUN", "--distraction", "train"], "'episodes=1' is not a "
         "RUN"),
        (report_cli.main, ["format=md"], "'format=md' is not a DIR (no such file or directory) "
         "but a KEY=VALUE setting"),
    ],
)  # fmt: skip
def test_a_bare_key_value_setting_is_answered_with_the_forms_that_take_it(main, argv, said, capsys):
    assert said in refused(capsys, main, argv)


@pytest.mark.parametrize(
    ("argv", "said"),
    [
        (["--no-video", "preset=cpu"], "write --preset cpu; got 'preset=cpu'"),
        (["preset=cpu"], "write --preset cpu"),
        (["--no-video", "resume=runs/a"], "write --resume runs/a; got"),
        (["--no-video", "overwrite=true"], "write --overwrite; got"),
        (["--no-video", "overwrite=false"], "write nothing: leave --overwrite out; got"),
        (["version=1"], "write --version"),
        (["--no-video", "help=1"], "write --help; got"),
    ],
)  # fmt: skip
def test_a_bare_setting_of_a_command_flag_is_answered_with_the_flag_alone(argv, said, capsys):
    message = refused(capsys, train_cli.main, argv)
    assert said in message
    assert "--set" not in message  # --set refuses these keys


def test_a_run_directory_named_like_a_setting_is_still_a_run(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "episodes=1").mkdir()
    message = refused(capsys, eval_cli.main, ["episodes=1", "--no-video"])
    assert "KEY=VALUE" not in message and "episodes=1" in message


@pytest.mark.parametrize(
    "argv",
    [["masks", "RUN", "--video", "--steps", "2"], ["masks", "RUN", "--video", "mp4", "--steps",
     "2"], ["masks", "--video", "RUN"], ["bias", "--out", "o", "RUN", "RUN2"]],
)  # fmt: skip
def test_an_option_whose_value_may_be_left_out_is_read_as_before(argv, capsys):
    # refused for the missing run, so the arguments were read as meant
    assert "RUN does not exist" in refused(capsys, analyze_cli.main, argv)


@pytest.mark.parametrize("path", [LONG_NAME, LONG_PATH])
@pytest.mark.parametrize(
    ("main", "argv", "flag"),
    [
        (train_cli.main, ["--run-dir"], "--run-dir"),
        (train_cli.main, ["--resume"], "--resume"),
        (eval_cli.main, [], "RUN"),
        (eval_cli.main, ["RUN", "--out"], "--out"),
        (sweep_cli.main, ["--sweep-dir"], "--sweep-dir"),
        (report_cli.main, [], "DIR"),
        (report_cli.main, [".", "--out"], "--out"),
        (study_cli.main, ["plan"], "SPEC"),
        (study_cli.main, ["report", "s.toml", "--study-dir"], "--study-dir"),
        (analyze_cli.main, ["bias"], "RUN"),
        (minigrid_cli.main, ["report", "--archive"], "--archive"),
        (minigrid_cli.main, ["probe", "--out"], "--out"),
    ],
)
def test_a_path_too_long_for_the_file_system_is_refused_naming_its_flag(main, argv, flag, path,
                                                                        capsys):  # fmt: skip
    err = refused(capsys, main, [*argv, path])
    limit = "4095; give a shorter path" if path == LONG_PATH else "255; give a shorter name"
    assert f"{flag} {path[:40]}...: " in err and f"past the file system's limit of {limit}" in err


@pytest.mark.parametrize("seeds", ["0-100000", "0-99999999999999999999", "0-9999,20000-20001"])
def test_a_seed_range_past_the_cap_is_refused_before_ray_starts(seeds, tmp_path, capsys):
    argv = ["--preset", "cpu", "--sweep-dir", str(tmp_path / "s"), "--seeds", seeds]
    err = refused(capsys, sweep_cli.main, argv)
    assert f"--seeds {seeds!r} names" in err and "past the cap of 10,000; give fewer" in err
    assert not (tmp_path / "s").exists()


def test_a_study_spec_seed_range_past_the_cap_is_refused(tmp_path, capsys):
    spec = tmp_path / "spec.toml"
    spec.write_text(
        Path("docs/studies/dmc100k.toml").read_text().replace('"101-102"', '"0-100000"')
    )
    err = refused(capsys, study_cli.main, ["plan", str(spec)])
    assert "seeds '0-100000' names" in err and "past the cap of 10,000" in err


@pytest.mark.parametrize("spec", ["docs/studies/dmc100k.toml",
                                  "docs/studies/minigrid-v2/tuning/spec.json"])  # fmt: skip
@pytest.mark.parametrize("archive", ["study", "study/", "other/../study"])
def test_a_study_archive_that_is_the_study_dir_is_refused_before_ray(
    spec, archive, tmp_path, capsys, monkeypatch
):
    spec = Path(spec).absolute()
    monkeypatch.chdir(tmp_path)
    (tmp_path / "other").mkdir()
    err = refused(capsys, study_cli.main, ["run", str(spec), "--study-dir", "study",
                                           "--archive", archive])  # fmt: skip
    assert f"--archive {tmp_path / archive} is the --study-dir itself" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["other"]


@pytest.mark.parametrize(
    ("archive", "work", "said"),
    [
        ("mgt", "mgt", "--archive mgt is the --work-dir itself"),
        ("mgt", "mgt/wd", "--work-dir mgt/wd is inside --archive mgt"),
        ("wd/mgt", "wd", "--archive wd/mgt is inside --work-dir wd"),
    ],
)
def test_a_minigrid_archive_that_is_or_nests_the_work_dir_is_refused_before_ray(
    archive, work, said, tmp_path, capsys, monkeypatch
):
    monkeypatch.chdir(tmp_path)
    Path(archive).mkdir(parents=True)
    err = refused(capsys, minigrid_cli.main, ["run", "--archive", archive, "--work-dir", work])
    assert said in err and "pass directories apart from each other" in err
    assert not Path(work, "tune").exists() and not Path(archive, "spec.json").exists()


@pytest.mark.parametrize(
    ("archive", "said"),
    [("study/kept", "--archive {}/study/kept is inside"), (".", "/study is inside --archive {};")],
)
def test_a_study_archive_nested_with_the_study_dir_is_refused_before_ray(
    archive, said, tmp_path, capsys, monkeypatch
):
    monkeypatch.chdir(tmp_path)
    spec = Path(__file__).parents[1] / "docs/studies/dmc100k.toml"
    err = refused(capsys, study_cli.main, ["run", str(spec), "--study-dir", "study",
                                           "--archive", archive])  # fmt: skip
    assert said.format(tmp_path) in err
    assert not (tmp_path / "study").exists()


@pytest.mark.parametrize(
    ("argv", "said"),
    [
        (["--env-kwargs", '{"a": 1, "a": 2}'], "--env-kwargs: the key 'a' is given twice"),
        (['--env-kwargs={"x": {"b": 1, "b": 1}}'], "--env-kwargs: the key 'b' is given twice"),
        (["--set", 'env_kwargs={"a": 1, "a": 2}'], "env_kwargs='{\"a\": 1, \"a\": 2}': the key "
         "'a' is given twice"),
        (["--env-kwargs", "nope"], "--env-kwargs: 'nope' is not JSON (Expecting value at line 1 "
         "column 1)"),
        (["--env-kwargs", "[1]"], "--env-kwargs: expected a JSON object, e.g. '{\"a\": 1}', got "
         "'[1]' (a JSON list)"),
    ],
)  # fmt: skip
def test_a_json_object_that_gives_a_key_twice_is_refused_naming_the_key(argv, said, capsys):
    err = refused(capsys, train_cli.main, argv)
    assert said in err, err


@pytest.mark.parametrize(
    ("argv", "said"),
    [
        (["--env-kwargs", "{\u201csize\u201d: 32}"], "--env-kwargs: '{\u201csize\u201d: 32}' is "
         "not JSON (Expecting property name enclosed in double quotes at line 1 column 2: it has "
         "typographic quotes (\u201c \u201d), as a word processor or web page writes them; JSON "
         "takes straight double quotes (\")); give --env-kwargs '{\"size\": 32}'"),
        (["--env-kwargs", '{"visualize_reward": True}'], "(Expecting value at line 1 column 22: "
         "True is Python's spelling; JSON writes true, false and null in lower case); give "
         "--env-kwargs '{\"visualize_reward\": true}'"),
        (["--env-kwargs", "{'size': 32}"], "JSON strings take double quotes, not single ones; in "
         "a shell, put the whole object in single quotes and its strings in double quotes); "
         "give --env-kwargs '{\"size\": 32}'"),
        (["--env-kwargs", '{"size": 32,}'], "a comma after the last item, which JSON does not "
         "allow; remove it); give --env-kwargs '{\"size\": 32}'"),
        (["--env-kwargs", '{"size": 32'], "is not JSON (Expecting ',' delimiter at line 1 column "
         "12); a JSON object is written e.g."),
        (["--set", "env_kwargs={'a': None}"], "cannot read env_kwargs=\"{'a': None}\": expected "
         "JSON for a dict: Expecting property name enclosed in double quotes at line 1 column 2: "
         "JSON strings take double quotes, not single ones; in a shell, put the whole object in "
         "single quotes and its strings in double quotes; in JSON: {\"a\": null}"),
    ],
)  # fmt: skip
def test_a_value_that_is_not_json_is_refused_with_what_is_wrong_and_where(argv, said, capsys):
    err = refused(capsys, train_cli.main, ["--preset", "cpu", *argv])
    assert said in err, err


def test_every_flag_that_takes_json_says_what_is_wrong_with_its_text(capsys):
    commands = [
        (train_cli.main, train_cli.TrainCommand, []),
        (sweep_cli.main, sweep_cli.SweepCommand, ["--sweep-dir", "s"]),
    ]
    for main, command, argv in commands:
        json_flags = [name for name, flag in command_flags(command, argv).items() if flag.json]
        assert json_flags, command
        for name in json_flags:
            err = refused(capsys, main, [*argv, name, '{"a": False}'])
            assert "False is Python's spelling; JSON writes true, false and null" in err, err
            assert f"give {name} '{{\"a\": false}}'" in err, err


def test_an_output_directory_that_cannot_be_made_is_refused_before_ray(tmp_path, capsys):
    blocker = tmp_path / "file"
    blocker.write_text("")
    spec = Path("docs/studies/dmc100k.toml").absolute()
    for main, argv, flag in [
        (sweep_cli.main, ["--preset", "cpu", "--sweep-dir"], "--sweep-dir"),
        (study_cli.main, ["run", str(spec), "--study-dir"], "--study-dir"),
        (study_cli.main, ["run", str(spec), "--study-dir", str(tmp_path / "s"), "--archive"],
         "--archive"),
    ]:  # fmt: skip
        err = refused(capsys, main, [*argv, str(blocker / "out")])
        assert (
            f"cannot write to the output directory {blocker / 'out'} ({blocker} is a file); "
            f"pass a writable {flag}"
        ) in err
    assert sorted(tmp_path.iterdir()) == [blocker]


def test_a_sweep_dir_without_write_permission_is_refused_before_ray(tmp_path, capsys):
    locked = tmp_path / "locked"
    locked.mkdir(mode=0o555)
    if os.access(locked, os.W_OK):
        pytest.skip("this user writes into a read-only directory (root)")
    argv = ["--preset", "cpu", "--sweep-dir", str(locked / "sweep")]
    err = refused(capsys, sweep_cli.main, argv)
    assert f"({locked} is not writable); pass a writable --sweep-dir" in err


@pytest.mark.parametrize(
    ("argv", "said"),
    [
        (["--settings.n-steps", "0"], "--settings.n-steps 0: must be 1 or more"),
        (["--settings.n-envs", "-2"], "--settings.n-envs -2: must be 1 or more"),
        (["--settings.steps", "0"], "--settings.steps 0: must be 1 or more"),
        (["--settings.steps", "1000"], "--settings.steps 1000: fewer than two blocks of "
         "--settings.n-envs x --settings.n-steps = 1024 transitions"),
        (["--settings.seed", "-1"], "--settings.seed -1: must be 0 or more"),
    ],
)  # fmt: skip
def test_a_probe_count_below_one_is_refused_naming_the_setting(argv, said, tmp_path, capsys):
    err = refused(capsys, minigrid_cli.main, ["probe", "--out", str(tmp_path / "p"), *argv])
    assert said in err
    assert list(tmp_path.iterdir()) == []


def loop(tmp_path: Path) -> Path:
    """A symbolic link to itself."""
    link = tmp_path / "loop"
    link.symlink_to(link)
    return link


@pytest.mark.parametrize(
    ("where", "said"),
    [
        (lambda tmp_path: Path("/proc/x"), "(/proc takes no new folder: "),
        (loop, "is a symbolic link to {tmp_path}/loop: Too many levels of symbolic links"),
        (lambda tmp_path: loop(tmp_path) / "deeper", "is a symbolic link to {tmp_path}/loop"),
    ],
)
def test_an_output_directory_that_cannot_be_made_is_named_by_every_command(
    where, said, tmp_path, capsys
):
    spec = Path("docs/studies/dmc100k.toml").absolute()
    archive = tmp_path / "archive"
    archive.mkdir()
    out = where(tmp_path)
    for main, argv, flag in [
        (sweep_cli.main, ["--preset", "cpu", "--sweep-dir"], "--sweep-dir"),
        (study_cli.main, ["run", str(spec), "--study-dir"], "--study-dir"),
        (study_cli.main, ["run", str(spec), "--study-dir", str(tmp_path / "s"), "--archive"],
         "--archive"),
        (train_cli.main, ["--env", "simoun/PointReach-v0", "--run-dir"], "--run-dir"),
        (minigrid_cli.main, ["probe", "--out"], "--out"),
        (minigrid_cli.main, ["run", "--archive", str(archive), "--work-dir"], "--work-dir"),
    ]:  # fmt: skip
        err = refused(capsys, main, [*argv, str(out)])
        assert f"cannot write to the output directory {out} (" in err
        assert said.format(tmp_path=tmp_path) in err and f"pass a writable {flag}" in err
    made = {archive, tmp_path / "loop"} if out != Path("/proc/x") else {archive}
    assert set(tmp_path.iterdir()) == made and not any(archive.iterdir())


def test_the_probe_refuses_an_empty_probe_list(tmp_path, capsys):
    out = tmp_path / "probe"
    err = refused(capsys, minigrid_cli.main, ["probe", "--probes", "--out", str(out)])
    assert "--probes is given no probe" in err and "leave --probes out" in err
    assert not out.exists()


@pytest.mark.parametrize(
    "word",
    [
        "\u2013-seed",
        "\u2014seed",
        "\uff0d\uff0d\uff53\uff45\uff45\uff44",
        "--\uff53\uff45\uff45\uff44",
        "\u2212\u2212seed=3",
    ],
)
@pytest.mark.parametrize(
    ("main", "argv"),
    [
        (train_cli.main, ["--env", "simoun/PointReach-v0", "--no-video"]),
        (train_cli.main, ["--env", "simoun/PointReach-v0", "--run-dir"]),
        (eval_cli.main, ["run", "--no-video"]),
        (sweep_cli.main, ["--preset", "cpu", "--resume"]),
        (minigrid_cli.main, ["probe", "--out", "p"]),
    ],
)  # fmt: skip
def test_a_flag_typed_with_a_unicode_dash_is_shown_in_ascii(main, argv, word, capsys):
    err = refused(capsys, main, [*argv, word, "3"])
    assert f"{word!r} looks like a flag typed with a non-ASCII dash or letters" in err
    assert err.rstrip().endswith("type it in ASCII: --seed" + "=3" * word.endswith("=3"))


@pytest.mark.parametrize(
    ("envs", "said"),
    [
        ("Pendulum-v1,Pendulum-v1", "--envs 'Pendulum-v1,Pendulum-v1' names Pendulum-v1 twice; "
         "list each env once"),
        ("simoun/PointReach-v0,simoun_agent.envs:simoun/PointReach-v0",
         "--envs gives simoun/PointReach-v0 and simoun_agent.envs:simoun/PointReach-v0, one task "
         "by its name (simoun-PointReach-v0); keep one of them"),
    ],
)  # fmt: skip
def test_an_env_given_twice_in_envs_is_named_as_such(envs, said, tmp_path, capsys):
    argv = ["--preset", "cpu", "--envs", envs, "--sweep-dir", str(tmp_path / "s")]
    err = refused(capsys, sweep_cli.main, argv)
    assert said in err and "--grid" not in err
    assert not (tmp_path / "s").exists()


def test_simoun_eval_names_its_device_flag_for_a_device_the_machine_lacks(capsys, tmp_path):
    said = refused(capsys, eval_cli.main, [str(tmp_path), "--device", "gpu"])
    assert "simoun-eval: error: --device gpu: device type 'gpu' is not supported" in said
    if not torch.cuda.is_available():
        said = refused(capsys, eval_cli.main, [str(tmp_path), "--device", "cuda"])
        assert said.startswith("simoun-eval: error: --device cuda: this torch")
        assert "saved config" not in said


EVERY_MAIN = [
    train_cli.main,
    eval_cli.main,
    sweep_cli.main,
    study_cli.main,
    report_cli.main,
    analyze_cli.main,
    minigrid_cli.main,
    driving_reference.main,
]


@pytest.mark.parametrize("main", EVERY_MAIN)
def test_every_commands_help_lists_version(main, capsys):
    with pytest.raises(SystemExit) as stop:
        main(["--help"])
    assert stop.value.code == 0
    assert "--version: print the installed version and exit." in capsys.readouterr().out


@pytest.mark.parametrize("main", EVERY_MAIN)
@pytest.mark.parametrize("option", ["-V", "-v"])
def test_an_unknown_short_option_names_version_and_help(main, option, capsys):
    err = refused(capsys, main, [option])
    assert f"unknown option {option}:" in err
    assert "--version prints its version" in err and "--help` lists every flag" in err


def test_a_short_option_names_the_long_flags_it_starts_and_negative_numbers_are_values(capsys):
    assert "(did you mean --env or --env-module or --env-kwargs?)" in refused(
        capsys, train_cli.main, ["-env", "Pendulum-v1"]
    )
    err = refused(capsys, train_cli.main, ["--agent.log-std-min", "-30", "--agent.lr", "-1"])
    assert "unknown option" not in err and "--agent.lr -1" in err


@pytest.mark.parametrize(
    ("main", "argv", "where"),
    [
        (train_cli.main, ["--resume", "~/simoun-absent/run"], "--resume"),
        (train_cli.main, ["--resume=~/simoun-absent/run"], "--resume"),
        (train_cli.main, ["--run-dir=~/simoun-absent/run"], "--run-dir"),
        (eval_cli.main, ["~/simoun-absent/run"], "RUN"),
        (report_cli.main, ["~/simoun-absent"], "DIR"),
    ],
)
def test_a_tilde_the_shell_did_not_expand_is_named_with_the_expanded_path(
    main, argv, where, capsys
):
    err = refused(capsys, main, argv)
    expanded = os.path.expanduser("~/simoun-absent")
    assert f"{where} ~/simoun-absent" in err
    assert "the shell did not expand ~" in err and f"give {expanded}" in err


@pytest.mark.parametrize(
    ("main", "argv", "said"),
    [
        # the command's own flag in other letter case or with _ for -, before anything else
        (train_cli.main, ["--Seed", "3"], "unknown flag --Seed: flags are written in lower case "
         "with dashes; give --seed (seed of every random stream)"),
        (train_cli.main, ["--agent.batch_size", "8"], "give --agent.batch-size"),
        (eval_cli.main, ["RUN", "--Episodes", "2"], "give --episodes (episodes to play)"),
        (sweep_cli.main, ["--Seeds", "1"], "give --seeds"),
        # another simoun command's flag is named as that command's, with its counterpart here
        (train_cli.main, ["--videos", "v"], "--videos is simoun-eval's flag (with --distraction: "
         "a folder of video files"),
        (train_cli.main, ["--videos", "v"], "simoun-train takes no background videos (its --video "
         "records an evaluation video"),
        (train_cli.main, ["--random-policy"], "--random-policy is simoun-eval's flag (play "
         "uniformly random actions"),
        (train_cli.main, ["--random-policy"], "a run's first --warmup-agent-steps agent steps take "
         "uniformly random actions; the random baseline of a trained run is simoun-eval RUN "
         "--random-policy"),
        (train_cli.main, ["--episodes", "3"], "--episodes is simoun-eval's flag (episodes to "
         "play), not simoun-train's; simoun-train calls it --eval-episodes"),
        (eval_cli.main, ["RUN", "--warmup-agent-steps", "5"], "--warmup-agent-steps is "
         "simoun-train's flag (agent decisions taken uniformly at random before learning "
         "starts), not simoun-eval's; simoun-eval has no such flag"),
        # other libraries' flags with their counterparts
        (train_cli.main, ["--config", "cfg.yaml"], "there is no config file flag: --preset picks "
         "a preset, and --set KEY=VALUE"),
        (eval_cli.main, ["RUN", "--config", "cfg.yaml"], "simoun-eval reads the run's own "
         "config.json"),
        (train_cli.main, ["--checkpoint", "run/checkpoint.pt"], "simoun-train calls it --resume "
         "(continue a run); give the run directory or its checkpoint.pt: --resume "
         "run/checkpoint.pt"),
        (train_cli.main, ["--render"], "simoun-train calls it --video (record one evaluation "
         "episode"),
        (train_cli.main, ["--max-episode-steps", "100"], "simoun-train calls it --env-kwargs "
         "(extra keyword arguments for gymnasium.make); an episode's step limit is the env's "
         "keyword, e.g. --env-kwargs '{\"max_episode_steps\": 100}'"),
        (sweep_cli.main, ["--max-episode-steps", "100"], "--env-kwargs '{\"max_episode_steps\": "
         "100}'"),
        (eval_cli.main, ["RUN", "--render-mode", "human"], "simoun-eval calls it --video (record "
         "the first episode to video.mp4); frames are rendered off screen (rgb_array) for the "
         "agent and the video: no window opens"),
    ],
)  # fmt: skip
def test_an_unknown_flag_is_offered_only_a_flag_of_its_meaning(main, argv, said, capsys):
    assert said in refused(capsys, main, argv)


@pytest.mark.parametrize(
    ("argv", "never"),
    [
        (["--checkpoint-evry", "runs/a"], "--checkpoint-every"),  # a path for a number flag
        (["--image-siz", "--no-video"], "--image-size"),  # a switch for a flag with a value
        (["--vide", "mp4"], "--video"),  # a value for a switch
    ],
)
def test_a_close_spelling_that_takes_another_kind_of_value_is_not_offered(argv, never, capsys):
    assert never not in refused(capsys, train_cli.main, argv)


def test_a_read_only_sweep_resumed_is_told_to_resume_a_copy(tmp_path):
    """Another --sweep-dir holds no sweep to resume: the fix for another user's sweep is a
    copy of it, resumed."""
    sweep_dir = tmp_path / "sw"
    sweep_dir.mkdir()
    SweepSpec(None, {"device": "cpu"}, {}, [0], ["simoun/PointReach-v0"]).save(sweep_dir)
    unwritable(sweep_dir)
    try:
        result = run_as_user("simoun_lab.cli.sweep", "--resume", "--sweep-dir", str(sweep_dir))
    finally:
        restored(sweep_dir)
    assert result.returncode == 2, result.stderr[-3000:]
    assert f"cannot write to the output directory {sweep_dir}" in result.stderr
    copy = f"cp -r {sweep_dir} ~/sw && simoun-sweep --resume --sweep-dir ~/sw"
    assert copy in result.stderr
    assert "pass a writable --sweep-dir" not in result.stderr


def test_a_read_only_study_resumed_is_told_to_resume_a_copy(tmp_path):
    study_dir = tmp_path / "s"
    study_dir.mkdir()
    unwritable(study_dir)
    spec = Path(__file__).parents[1] / "docs" / "studies" / "dmc100k.toml"
    try:
        argv = ["run", str(spec), "--study-dir", str(study_dir), "--resume"]
        result = run_as_user("simoun_lab.cli.study", *argv)
    finally:
        restored(study_dir)
    assert result.returncode == 2, result.stderr[-3000:]
    assert f"cannot write to the output directory {study_dir}" in result.stderr
    copy = f"cp -r {study_dir} ~/s && simoun-study run {spec} --resume --study-dir ~/s"
    assert copy in result.stderr


def test_a_list_flag_given_twice_is_refused_with_every_value_after_one_flag(tmp_path, capsys):
    probe = ["probe", "--out", str(tmp_path / "no" / "p")]
    err = refused(capsys, minigrid_cli.main, [*probe, "--probes", "rnd", "--probes", "consistency"])
    assert (
        "--probes is given twice with different values (--probes rnd and --probes consistency), "
        "and only the last would count; give every value after one --probes: --probes rnd "
        "consistency"
    ) in err
    err = refused(capsys, minigrid_cli.main, [*probe, "--probes=rnd", "--probes", "rnd", "count"])
    assert "--probes rnd count" in err
    # the same list twice changes nothing: refused for the missing folder, not the repetition
    err = refused(capsys, minigrid_cli.main, [*probe, "--probes", "rnd", "--probes", "rnd"])
    assert "given twice" not in err and "its folder" in err


@pytest.mark.parametrize(
    ("main", "argv", "said"),
    [
        (sweep_cli.main, ["--grid", "--agent.lr=1e-3,3e-4"],
         "--grid takes a KEY=VALUE word, and '--agent.lr=1e-3,3e-4' after it starts with dashes, "
         "so it was read as a flag of its own and --grid was left without a value; write the key "
         "without dashes: --grid agent.lr=1e-3,3e-4"),
        (sweep_cli.main, ["--grid", "--agent.curiosity=on,off"],
         "write the key without dashes: --grid agent.curiosity=on,off"),
        (sweep_cli.main, ["--set", "--agent.batch-size=8"], "--set agent.batch_size=8"),
        (train_cli.main, ["--set", "-image_size=32"], "--set image_size=32"),
    ],
)  # fmt: skip
def test_a_setting_written_with_dashes_after_its_flag_is_named_with_the_fix(
    main, argv, said, capsys
):
    err = refused(capsys, main, argv)
    assert said in err and "Missing value" not in err, err
