"""The MiniGrid study's arms with settings (names, checks) and the tuning phase's selection rule,
by hand on the evaluation records of the committed v1 archive."""

import json
import shutil
from pathlib import Path

import numpy as np
import pytest

from simoun_agent.config import SetupError
from simoun_lab.minigrid_study.arms import arm_name, parse_arm
from simoun_lab.minigrid_study.report import read_rows
from simoun_lab.minigrid_study.select import run_auc, select, write_selection
from simoun_lab.minigrid_study.spec import load_spec, spec_from_dict

V1 = Path(__file__).parent.parent / "docs" / "studies" / "minigrid"
TASK = "MiniGrid-DoorKey-6x6-v0"


def test_arm_names_carry_checked_settings():
    assert parse_arm("ppo") == ("ppo", {})
    assert parse_arm("rnd,normalization=return_std,scale=0.01") == (
        "rnd",
        {"normalization": "return_std", "scale": 0.01},
    )
    assert arm_name("consistency", {"scale": 0.1, "normalization": "paper"}) == (
        "consistency,normalization=paper,scale=0.1"
    )
    for name, problem in (
        ("consistensy", r"unknown arm 'consistensy' \(did you mean 'consistency'\?\)"),
        ("rnd,scael=0.1", r"'scael=0.1' is not KEY=VALUE.*did you mean 'scale'"),
        ("rnd,scale=-1", r"scale='-1' is not valid: scale must be a finite number >= 0"),
        ("consistency,scale=1e400", r"scale='1e400' is not valid.*got inf"),
        ("rnd,progress=2", r"'rnd,progress=2': progress='2' is not valid.*in \(0, 1\]"),
        ("consistency,progress=-0.5", r"progress='-0.5' is not valid"),
        ("rnd,normalization=[1]", r"normalization=\[1\] is not one of"),
        ("rnd,scale=0.1,scale=0.2", r"'scale' is given twice"),
        ("rnd,normalization=std", r"normalization='std' is not one of"),
        ("consistency,lr=0.1", r"'lr=0.1' is not KEY=VALUE"),  # model settings are not arms'
        ("ppo,scale=1", r"its keys: none"),
    ):
        with pytest.raises(SetupError, match=problem):
            parse_arm(name)
    with pytest.raises(SetupError, match="an arm is listed twice"):
        spec_from_dict({"arms": ["ppo", "ppo"]}, "spec")


def test_one_arm_or_task_listed_twice_is_refused():
    same = [
        "consistency,scale=0.01,normalization=paper",
        "consistency,normalization=paper,scale=0.01",
    ]
    for arms in (same, ["rnd", "rnd,scale=0.05"]):
        with pytest.raises(SetupError) as refused:
            spec_from_dict({"arms": ["ppo", *arms]}, "spec")
        assert f"{arms[0]!r} and {arms[1]!r} are one arm spelled two ways" in str(refused.value)
    spec_from_dict({"arms": ["rnd", "rnd,scale=0.01"]}, "spec")
    task = {"env_id": TASK, "steps": 4096, "seeds": [0]}
    with pytest.raises(SetupError, match=f"spec tasks: {TASK} is listed 2 times; list it once"):
        spec_from_dict({"tasks": [task, {**task, "seeds": [1]}]}, "spec")


def test_the_area_is_the_trapezoid_of_success_over_the_budget():
    rows = [
        {"env_step": 0.0, "success_rate": 0.0},
        {"env_step": 100.0, "success_rate": 0.5},
        {"env_step": 200.0, "success_rate": 1.0},
    ]
    # (0 + 0.5) / 2 * 100 + (0.5 + 1) / 2 * 100 = 25 + 75 = 100, over a budget of 200
    assert run_auc(rows, 200) == pytest.approx(0.5)
    with pytest.raises(ValueError, match="2\\+ finite evaluations"):
        run_auc(rows[:1], 200)


def test_the_rule_picks_the_highest_mean_area_once_every_setting_has_finished(tmp_path):
    """v1's ppo, consistency and rnd runs of seeds 0 and 1 stand in for three settings of one
    entry; the rule must pick the one whose mean area over the two seeds is highest."""
    names = {
        "ppo": "rnd,scale=0.001",
        "consistency": "rnd,scale=0.01",
        "rnd": "rnd,scale=0.1",
    }
    spec = spec_from_dict(
        {
            "tasks": [{"env_id": TASK, "steps": 400_000, "seeds": [0, 1]}],
            "arms": ["ppo", *names.values()],
        },
        "spec",
    )
    for v1_arm, arm in names.items():
        for seed in (0, 1):
            run_dir = tmp_path / TASK / arm / f"s{seed}"
            shutil.copytree(V1 / TASK / v1_arm / f"s{seed}", run_dir)
            # recorded as the run of this spec it stands in for, which the selection checks
            config = json.loads((run_dir / "config.json").read_text())
            config.update(run=f"{TASK}/{arm}/s{seed}", spec=spec.to_json())
            (run_dir / "config.json").write_text(json.dumps(config))
            summary = json.loads((run_dir / "summary.json").read_text())
            summary.update(run=f"{TASK}/{arm}/s{seed}")
            (run_dir / "summary.json").write_text(json.dumps(summary))
    hand = {
        arm: np.mean(
            [
                run_auc(read_rows(V1 / TASK / v1_arm / f"s{seed}" / "eval.csv"), 400_000)
                for seed in (0, 1)
            ]
        )
        for v1_arm, arm in names.items()
    }
    result = select(spec, tmp_path)
    assert result["selected"]["ppo"] is None  # plain PPO's runs are not in this archive
    assert result["selected"]["rnd"] == max(hand, key=hand.get)
    for arm, area in hand.items():
        assert result["arms"][arm]["mean_area"] == pytest.approx(area)
    shutil.rmtree(tmp_path / TASK / "rnd,scale=0.1" / "s1")
    assert select(spec, tmp_path)["selected"]["rnd"] is None  # a setting is still running
    markdown = write_selection(spec, tmp_path).read_text()
    assert "rnd: not yet" in markdown and "| rnd,scale=0.1 |" in markdown
    assert json.loads((tmp_path / "selection.json").read_text())["selected"]["rnd"] is None


def test_the_committed_study_specs_load():
    for path in sorted((V1.parent / "minigrid-v2").glob("*/spec.json")):
        spec = load_spec(path)
        assert spec.runs()
    assert load_spec(V1 / "spec.json").arms == ("ppo", "consistency", "rnd")
