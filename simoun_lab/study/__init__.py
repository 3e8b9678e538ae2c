"""Studies: one protocol for every method, from a spec file (``simoun-study``).

A study compares recipes fairly: each gets the same tuning grid, tuning seeds, budgets and
selection rule; the setting each recipe's tuning selects is then evaluated on held-out seeds,
and the report gives IQM with stratified bootstrap CIs and the probability of improvement
(Agarwal et al. 2021, :mod:`simoun_lab.stats`). Runs are ordinary sweep trials on Ray Tune
(:mod:`simoun_lab.sweep`), so Ray is needed to run a study, not to read or plan one.

Modules, each with one job: :mod:`~simoun_lab.study.spec` (read and check the TOML spec),
:mod:`~simoun_lab.study.toml_lines` (a key's line, for errors), :mod:`~simoun_lab.study.plan`
(the runs of each phase), :mod:`~simoun_lab.study.probe` (the CPU-time estimate),
:mod:`~simoun_lab.study.selection` (the rules) and :mod:`~simoun_lab.study.choice` (the
chosen settings), :mod:`~simoun_lab.study.archive` (what survives the study),
:mod:`~simoun_lab.study.provenance` (the commit it ran), :mod:`~simoun_lab.study.generalization`
(each evaluation run's final agent under distraction), :mod:`~simoun_lab.study.report` and
:mod:`~simoun_lab.study.runner` (the command: :mod:`simoun_lab.cli.study`).

A study directory holds ``study.json`` (the spec and the commits it ran from),
``tuning/<recipe>/<setting>/<task>/s<seed>`` and ``evaluation/<recipe>/<task>/s<seed>`` (run
directories as ``simoun-train`` writes them; diagnostic recipes' runs among the evaluation's),
``selection.json``, ``tune/`` (Ray Tune's records), ``report/`` and, once measured,
``update_cost.json``.
"""

from simoun_wrappers._homes import missing_name


def __getattr__(name: str) -> object:
    raise missing_name(__name__, name)
