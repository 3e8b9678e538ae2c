"""The run layer's public functions check their arguments before anything is built, naming the
function's argument and a call that works: create_run, resume_run, train and the callbacks'
answers (a metric that is no number, a stop_requested that is no signal), and a run directory
held by a live run of this process."""

import signal

import pytest
from test_train_resume import tiny_config

from simoun_agent.config import SetupError, to_dict
from simoun_agent.run import train
from simoun_agent.run.callback import TrainCallback


class Note(TrainCallback):
    """Adds a metric that is no number."""

    def on_evaluation(self, run, metrics):
        metrics["note"] = "best"


class StopNow(TrainCallback):
    """Asks the run to stop, answering ``answer``."""

    def __init__(self, answer):
        self.answer = answer

    def stop_requested(self, run):
        return self.answer


@pytest.mark.parametrize(
    ("call", "error", "said"),
    [
        (
            lambda c: train.create_run(to_dict(c)),
            TypeError,
            "create_run(config=...) must be a TrainConfig, got dict",
        ),
        (
            lambda c: train.create_run(c, overwrite="yes"),
            TypeError,
            "create_run(overwrite=...) must be True or False, got 'yes'",
        ),
        (
            lambda c: train.create_run(c, check=True),
            TypeError,
            "create_run(check=...) must be a callable",
        ),
    ],
)
def test_create_run_names_its_argument_before_building(tmp_path, call, error, said):
    config = tiny_config(tmp_path / "r")
    with pytest.raises(error) as raised:
        call(config)
    assert said in str(raised.value)
    assert not (tmp_path / "r").exists()


def test_a_budget_of_zero_steps_is_named_as_such(tmp_path):
    config = tiny_config(tmp_path / "r")
    config.total_env_steps = 0
    with pytest.raises(SetupError) as raised:
        train.create_run(config)
    said = str(raised.value)
    assert "total-env-steps 0" in said and "TrainConfig.total_env_steps" in said
    assert "action-repeat 0" not in said


@pytest.fixture(scope="module")
def live_run(tmp_path_factory):
    """A run created and not trained; closed at the end."""
    run = train.create_run(tiny_config(tmp_path_factory.mktemp("live") / "r"))
    yield run
    run.close()


@pytest.mark.parametrize(
    ("callbacks", "said"),
    [
        (Note(), "takes a list of callbacks, got the one Note; pass it in a list: [Note()]"),
        ([Note], "item 0 is the class Note, not an instance; pass Note()"),
        ([print], "item 0 is builtin_function_or_method"),
        (None, "must be a list of TrainCallback instances, got NoneType"),
    ],
)
def test_train_names_callbacks_that_are_no_list_of_instances(live_run, callbacks, said):
    with pytest.raises(TypeError) as raised:
        train.train(live_run, callbacks)
    assert said in str(raised.value)


def test_train_names_a_run_that_is_none():
    with pytest.raises(TypeError, match=r"train\(run=\.\.\.\) must be the Run of create_run"):
        train.train(None)


def test_a_second_run_in_a_directory_this_process_holds_is_named_and_close_frees_it(tmp_path):
    config = tiny_config(tmp_path / "r")
    first = train.create_run(config)
    with pytest.raises(SetupError) as raised:
        train.create_run(tiny_config(tmp_path / "r"), overwrite=True)
    said = str(raised.value)
    assert "in use by a run created in this process" in said and "run.close()" in said
    first.close()
    train.create_run(tiny_config(tmp_path / "r"), overwrite=True).close()


def test_a_metric_that_is_no_number_names_the_callback_and_the_metric(tmp_path):
    run = train.create_run(tiny_config(tmp_path / "r"))
    with pytest.raises(TypeError) as raised:
        train.train(run, [Note()])
    assert "Note.on_evaluation set the metric 'note' to str 'best'" in str(raised.value)


@pytest.mark.parametrize("answer", [True, "stop", 1.0])
def test_stop_requested_answering_no_signal_is_named(tmp_path, answer):
    run = train.create_run(tiny_config(tmp_path / "r"))
    with pytest.raises(TypeError) as raised:
        train.train(run, [StopNow(answer)])
    said = str(raised.value)
    assert f"StopNow.stop_requested returned {type(answer).__name__} {answer!r}" in said
    assert "signal.SIGTERM" in said


def test_stop_requested_answering_a_signal_stops_as_that_signal(tmp_path):
    run = train.create_run(tiny_config(tmp_path / "r"))
    with pytest.raises(train.Stopped) as raised:
        train.train(run, [StopNow(signal.SIGTERM)])
    assert raised.value.exit_code == 143


def test_resume_run_takes_a_str_and_names_a_bad_overrides(tmp_path):
    run = train.create_run(tiny_config(tmp_path / "r", total_env_steps=60))
    train.train(run)
    with pytest.raises(TypeError, match=r"resume_run\(overrides=\.\.\.\) must be a dict"):
        train.resume_run(str(tmp_path / "r"), None)
    train.resume_run(str(tmp_path / "r"), {"total_env_steps": 120}).close()


def test_a_run_dir_with_an_unexpanded_home_is_named():
    config = tiny_config("~/simoun-no-such-run")
    with pytest.raises(ValueError, match=r"os.path.expanduser\('~/simoun-no-such-run'\)"):
        train.create_run(config)


class Misspelt(TrainCallback):
    def on_evalution(self, run, metrics):
        raise AssertionError("never called")


class StableBaselinesStyle(TrainCallback):
    def on_step(self, run):
        raise AssertionError("never called")


class OwnHook(TrainCallback):
    def on_best(self, run):
        raise AssertionError("never called")


class Helper(TrainCallback):
    """A helper method of its own is no hook and is allowed."""

    def summarize(self, metrics):
        return dict(metrics)


@pytest.mark.parametrize(
    ("callback", "said"),
    [
        (Misspelt(), "Misspelt defines on_evalution, which the loop never calls; did you mean "),
        (StableBaselinesStyle(), "on_step is a hook of Stable-Baselines3's BaseCallback"),
        (OwnHook(), "OwnHook defines on_best, which the loop never calls"),
    ],
)
def test_a_method_named_like_a_hook_the_loop_never_calls_is_refused(live_run, callback, said):
    with pytest.raises(TypeError) as raised:
        train.train(live_run, [callback])
    message = str(raised.value)
    assert said in message
    assert "on_start, on_evaluation, on_logged, on_end, stop_requested" in message


class ReturnsTrue(TrainCallback):
    def on_evaluation(self, run, metrics):
        return True


def test_a_hook_returning_a_value_is_refused_naming_stop_requested(tmp_path):
    train.check_callbacks([Helper()], "train")
    run = train.create_run(tiny_config(tmp_path / "r"))
    with pytest.raises(TypeError) as raised:
        train.train(run, [ReturnsTrue()])
    said = str(raised.value)
    assert "ReturnsTrue.on_evaluation returned bool True" in said
    assert "stop_requested(run)" in said


def test_a_run_dir_given_as_a_path_is_taken_and_kept_as_a_str(tmp_path):
    config = tiny_config(tmp_path / "r")
    config.run_dir = tmp_path / "p"
    run = train.create_run(config)
    run.close()
    assert run.config.run_dir == str(tmp_path / "p")
    assert (tmp_path / "p" / "config.json").is_file()
