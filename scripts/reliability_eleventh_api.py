"""The eleventh reliability trial's cases: api (see reliability_trial.py).

The Python API on surfaces no earlier trial touched: the lab's statistics the tenth trial left
alone (``difference_ci`` given a statistic of the wrong kind, by name, returning a profile, or a
confidence where ``reps`` goes, and tasks that differ; ``stratified_bootstrap_band`` of curves
given a final-score statistic or a confidence as two percentiles; ``bootstrap_replicates`` with a
fractional seed; a numpy Generator as the seed; a statistic's value where the statistic goes;
``reps`` given to ``aggregate_iqm``; ``percentile_interval`` given no replicates, a NaN or an
interval; ``normalize`` of a short task name, a dict, a scalar and a return above the task's
maximum; ``max_return`` of a list) and scores in the forms a notebook holds them (a pandas Series
or DataFrame, None runs, a bare number for one run, a column vector, rliable's runs x tasks
matrix, a generator, a dict of seeds, ragged curves, a list where the other method's dict goes);
the information-bias estimator given torch tensors (one requiring grad), a dead unit, one pair,
layers of different widths, observations instead of activations, and ``layer_activations``' dict
of layers; the analysis' layer functions of a loaded run (``layer_activations``,
``structure_masks``, ``make_pairs``, ``play_episode``) given numpy arrays, float frames, one
unbatched observation, two frames, channel-last or smaller frames, the agent instead of its
encoder, a zero batch size, a negative seed, a recoloured half of another length and an unwrapped
env; the sweep report called from a notebook (``compare_runs`` and ``write_report`` of a run
directory, its parent, a list, a file, a missing path, budgets misspelt, as a number, negative,
as text, of one element, NaN or past every run, an output that is a file); configs whose settings
have no effect or cannot work (exploration noise of a Gaussian actor, a curiosity scale with
curiosity off, a schedule going up, a replay smaller than a batch, a warm-up or an evaluation
past the run's end, a human render mode, a Generator seed, env kwargs of numpy or float values, a
highway range as a Python tuple) next to typical valid ones; ``create_run``'s ``overwrite`` and
``check`` of the wrong kinds; callbacks given as one object, a class, a function or a tuple;
Gymnasium's vector RescaleAction and TransformObservation with the vector rewards, ``make_vec``
with the wrapper classes themselves as ``wrappers`` or without a render mode, a normalisation by
its class name; the normalisations called with one argument, float sub-env indices or 0/1
where the counted mask goes; the PettingZoo wrapper with a three-number size, PettingZoo's seed
test, its ``observation_spaces`` dict, its agents' own images, pursuit's float (H, W, C)
observations and actions of the wrong shape; names imported from the analysis package that live
in its submodules, and a name spelt as other libraries spell it.
"""

from reliability_ninth_api import TINY_CONFIG, TRAIN, callback
from reliability_trial import NOV, STEPS3, P, S, api, vec

ST = "from simoun_lab import stats as st; "
XY = "x = {'t': np.array([0.6, 0.7, 0.8])}; y = {'t': np.array([0.5, 0.55, 0.6, 0.65])}; "
CURVES = "c = {'t': np.random.default_rng(0).random((4, 6))}; "
IB = (
    "from simoun_lab.analysis import information_bias; rng = np.random.default_rng(0); "
    "z = rng.normal(size=(50, 4)); "
)
CONF = "from simoun_agent.config import AgentConfig, TrainConfig; "
LOADED = (
    "from simoun_agent.run.load import load_run; r = load_run('../tiny', device='cpu'); "
    "obs = np.stack([r.env.reset(seed=s)[0]['frames'] for s in range(4)]); "
)
LAYERS = LOADED + "import torch; from simoun_lab.analysis.layers import layer_activations; "
MASKS = LOADED + "from simoun_lab.analysis.masks import structure_masks; "
PAIRS = "from simoun_lab.analysis.pairs import make_pairs; "
SWEEP = "from simoun_lab.sweep.report import compare_runs, write_report; "
PEND = vec("NEXT_STEP")
NORM = "from simoun_wrappers.intrinsic_normalization import ReturnStd, RewardStd; "
SPO = "from simoun_wrappers.pettingzoo import SimounParallelObservation as SPO; "
PZ = (
    "import pettingzoo; " + SPO + "pz = pettingzoo.make('parallel', 'butterfly/pistonball-v6', "
    "n_pistons=3, render_mode='rgb_array'); "
)
ACTS = "{a: e.action_space(a).sample() for a in e.agents}"
PZ_STEP = f"e.reset(seed=0); e.step({ACTS})"
QUIET = "    def on_evaluation(self, run, metrics):\n        pass"
HIGHWAY = (
    "from simoun_agent.config import resolve; from simoun_agent.run.train import create_run; "
    f"cfg = resolve('highway-cpu', {{**{TINY_CONFIG}, 'env': 'highway-fast-v0'}}); "
)

# (code, the name the refusal must give, or "" for valid input[, valid: either])
ELEVENTH_CODES = [
    # difference_ci, the bootstrap band, replicates and intervals
    (ST + XY + "p, lo, hi = st.difference_ci(x, y, reps=200); assert lo <= p <= hi", ""),
    (ST + XY + "st.difference_ci(x, y, st.iqm)", ("statistic", "aggregate_iqm")),
    (ST + XY + "st.difference_ci(x, y, st.aggregate_iqm, 0.9)", ("reps", "confidence")),
    (ST + XY + "st.difference_ci(x, y, 'mean')", ("statistic", "aggregate_mean")),
    (ST + XY + "st.difference_ci(x, {'u': y['t']})", ("'u'", "tasks")),
    (ST + XY + "st.difference_ci(x, y, lambda s: st.performance_profile(s, np.array([0.5, 0.7])))",
     ("one number", "stratified_bootstrap_band")),
    (ST + CURVES + "p, lo, hi = st.stratified_bootstrap_band(c, st.iqm_over_steps, reps=100); "
     "assert p.shape == lo.shape == (6,)", ""),
    (ST + CURVES + "st.stratified_bootstrap_band(c, st.aggregate_iqm, reps=100)",
     ("iqm_over_steps", "curves")),
    (ST + "r = st.bootstrap_replicates({'t': [0.2, 0.6, 0.9]}, st.aggregate_iqm, reps=50); "
     "assert r.shape == (50,)", ""),
    (ST + "st.bootstrap_replicates({'t': [0.2, 0.6, 0.9]}, st.aggregate_iqm, 50, 0.5)", "seed"),
    (ST + CURVES + "st.stratified_bootstrap_band(c, st.iqm_over_steps, confidence=(0.05, 0.95))",
     "confidence"),
    (ST + "st.stratified_bootstrap_ci({'t': [0.2, 0.6, 0.9]}, st.aggregate_iqm, "
     "seed=np.random.default_rng(0))", "seed"),
    (ST + "s = {'t': [0.2, 0.6, 0.9]}; st.stratified_bootstrap_ci(s, st.aggregate_iqm(s))",
     "statistic"),
    (ST + "st.aggregate_iqm({'t': [0.5, 0.6]}, reps=100)", ("reps", "stratified_bootstrap_ci")),
    (ST + "st.percentile_interval(np.array([]))", ("replicates", "empty")),
    (ST + "st.percentile_interval(np.array([0.1, np.nan, 0.3]))", ("NaN", "replicates")),
    (ST + "st.percentile_interval(st.stratified_bootstrap_ci({'t': [0.2, 0.6, 0.9]}, "
     "st.aggregate_iqm, reps=50))", ("replicates", "bootstrap_replicates")),
    # normalize and max_return
    (ST + "st.normalize('cheetah-run', [500.0])", ("dm_control/", "env_id")),
    (ST + "st.normalize('dm_control/cheetah-run-v0', {'seed0': 500.0})", "returns"),
    (ST + "assert st.normalize('dm_control/cheetah-run-v0', 500) == 0.5", ""),
    (ST + "st.normalize('dm_control/cheetah-run-v0', [1500.0])", ("1000", "maximum")),
    (ST + "st.max_return(['dm_control/cheetah-run-v0'])", "env_id"),
    # scores in the forms a notebook holds them
    (ST + "st.aggregate_iqm({'t': [0.5, None, 0.7]})", ("None", "NaN")),
    (ST + "st.iqm_over_steps({'t': [[0.1, 0.2, 0.3], [0.1, 0.2]]})", ("steps", "length")),
    (ST + "import pandas as pd; assert st.aggregate_iqm({'t': pd.Series([0.5, 0.6, 0.7])}) == 0.6",
     ""),
    (ST + "import pandas as pd; st.aggregate_iqm(pd.DataFrame({'task': ['a', 'a', 'b'], "
     "'score': [0.5, 0.6, 0.7]}))", ("dict", "DataFrame")),
    (ST + "st.aggregate_mean({'t': [0.5, 0.6], 'u': 0.7})", "'u'"),
    (ST + "st.aggregate_iqm({'t': np.array([[0.5], [0.6], [0.7]])})", "'t'"),
    (ST + "st.aggregate_iqm({'simoun': np.random.default_rng(0).random((5, 3))})",
     ("runs x tasks", "rliable")),
    (ST + "st.probability_of_improvement({'t': [1.0, 2.0]}, [0.5, 0.6])", ("y", "dict")),
    (ST + "st.aggregate_iqm({'t': (r for r in [0.5, 0.6, 0.7])})", "'t'"),
    (ST + "st.aggregate_iqm({'t': {'seed0': 0.5, 'seed1': 0.6}})", ("'t'", "values")),
    (ST + "st.performance_profile({'t': np.random.default_rng(0).random((3, 5))}, "
     "np.linspace(0, 1, 5))", ("curves", "final")),
    # the information-bias estimator
    (IB + "import torch; t = torch.as_tensor(z); information_bias({'dynamic': (t, t + 0.1), "
     "'static': (t, -t)})", ""),
    (IB + "z[:, 0] = 0; b = information_bias({'dynamic': (z, z), 'static': (z, "
     "rng.normal(size=(50, 4)))}); assert all(np.isfinite(s).all() for s in "
     "b.unit_scores.values())", ""),
    (IB + "information_bias({'dynamic': (z[:1], z[:1]), 'static': (z[:1], z[:1])})",
     ("N", "pairs")),
    (IB + "information_bias({'dynamic': (z, z), 'static': (z[:, :3], z[:, :3])})",
     ("units", "D")),
    (IB + "import torch; t = torch.as_tensor(z).requires_grad_(); "
     "information_bias({'dynamic': (t, t * 2), 'static': (t, -t)})", ("detach",), True),
    (IB + PAIRS + "information_bias(make_pairs(np.zeros((8, 3, 3, 32, 32), np.uint8), seed=0))",
     ("(N, D)", "layer_activations")),
    # the analysis' layer functions on a loaded run
    (LAYERS + "a = layer_activations(r.agent.encoder, torch.as_tensor(obs)); "
     "assert all(len(v) == 4 for v in a.values())", ""),
    (LAYERS + "from simoun_lab.analysis import information_bias; "
     "information_bias(layer_activations(r.agent.encoder, torch.as_tensor(obs)))",
     ("dynamic", "factor")),
    (LAYERS + "layer_activations(r.agent.encoder, obs)", ("tensor", "torch.as_tensor"), True),
    (LAYERS + "layer_activations(r.agent.encoder, torch.rand(obs.shape))", "uint8"),
    (LAYERS + "layer_activations(r.agent.encoder, torch.as_tensor(obs[0]))",
     ("batch", "(B, k, C, H, W)")),
    (LAYERS + "layer_activations(r.agent.encoder, torch.as_tensor(obs), batch_size=0)",
     "batch_size"),
    (LAYERS + "layer_activations(r.agent.encoder, torch.as_tensor(obs[:, 1:]))",
     ("frames", "(B, k, C, H, W)")),
    (LAYERS + "layer_activations(r.agent.encoder, torch.as_tensor(obs).permute(0, 1, 3, 4, 2))",
     ("channel", "(B, k, C, H, W)")),
    (MASKS + "m = structure_masks(r.agent.encoder, obs); assert len(m.motion) == 4", ""),
    (MASKS + "structure_masks(r.agent, obs)", ("agent.encoder", "encoder")),
    (MASKS + "structure_masks(r.agent.encoder, obs.astype(np.float32) / 255)", "uint8"),
    (MASKS + "structure_masks(r.agent.encoder, obs[..., :16, :16])", ("32", "size")),
    (LOADED + PAIRS + "p = make_pairs(obs, seed=0); assert p['static'][1].shape == obs.shape", ""),
    (PAIRS + "make_pairs(np.random.default_rng(0).random((4, 3, 3, 32, 32)), seed=0)", "uint8"),
    (PAIRS + "make_pairs(np.zeros((4, 3, 3, 32, 32), np.uint8), seed=-1)", "seed"),
    (LOADED + PAIRS + "make_pairs(obs, seed=0, recoloured=obs[:2])", "recoloured"),
    (LOADED + "from simoun_lab.analysis.runs import play_episode; play_episode(r.agent, "
     f"{P}, 0)", ("SimounObservation", "frames")),
    (PAIRS + "make_pairs(np.zeros((3, 32, 32), np.uint8), seed=0)", ("(N, k, C, H, W)", "batch")),
    # the sweep report from a notebook
    (SWEEP + "c = compare_runs('../tiny'); assert c.groups", ("parent", "run"), True),
    (SWEEP + "files = write_report('..', out='rep'); assert files", ""),
    (SWEEP + "write_report('..', out='rep', budget=('env_steps', 20))", "env_step"),
    (SWEEP + "write_report('..', out='rep', budget=20)", "budget"),
    (SWEEP + "write_report('..', out='rep', budget=('env_step', -5))", ("budget", "-5")),
    (SWEEP + "write_report('..', out='rep', budget=('env_step', '20'))", "budget"),
    (SWEEP + "write_report('..', out='rep', budget=('env_step',))", "budget"),
    (SWEEP + "write_report('..', out='rep', budget=('wall_time_s', float('nan')))", "budget"),
    (SWEEP + "compare_runs('../nowhere')", "nowhere"),
    (SWEEP + "write_report(['../tiny'], out='rep')", ("root", "list")),
    (SWEEP + "compare_runs('../tiny/eval.csv')", ("eval.csv", "directory")),
    (SWEEP + "write_report('..', out='../tiny/config.json')", ("config.json", "out")),
    (SWEEP + "from pathlib import Path; write_report(Path('..'), Path('rep'), "
     "('wall_time_s', 1e9))", ("wall_time_s", "budget")),
    # settings with no effect, or that never happen, and typical valid ones
    (CONF + "AgentConfig(curiosity=False, curiosity_scale=0.5)", ("curiosity_scale", "curiosity")),
    (CONF + "AgentConfig(exploration_std_start=0.5, exploration_std_end=0.05)",
     ("actor", "deterministic")),
    (CONF + "AgentConfig(actor='deterministic', exploration_std_start=0.5, "
     "exploration_std_end=0.05)", ""),
    (CONF + "AgentConfig(actor='deterministic', exploration_std_start=0.1, "
     "exploration_std_end=1.0)", ("exploration_std_start", "exploration_std_end")),
    (CONF + "AgentConfig(lr=3e-4, alpha_lr=3e-4, discount=0.99, batch_size=256, critic_tau=0.005)",
     ""),
    (TRAIN + "cfg.replay_capacity = 4; train(create_run(cfg))", ("replay_capacity", "batch_size")),
    (TRAIN + "cfg.env_kwargs = {'render_mode': 'human'}; create_run(cfg)",
     ("render_mode", "rgb_array")),
    (CONF + "TrainConfig(seed=np.random.default_rng(0))", "seed"),
    (TRAIN + "cfg.env_kwargs = {'max_steps': np.int64(10)}; train(create_run(cfg))",
     ("max_steps",), True),
    (TRAIN + "cfg.env_kwargs = {'max_steps': 10.0}; create_run(cfg)", "max_steps"),
    (HIGHWAY + "cfg.env_kwargs['config']['reward_speed_range'] = (20, 30); create_run(cfg)", ""),
    (TRAIN + "create_run(cfg, overwrite='yes')", "overwrite"),
    (TRAIN + "create_run(cfg, check=True)", "check"),
    (CONF + "TrainConfig(eval_distraction=['color_easy'])", ("eval_distraction",), True),
    (TRAIN + "cfg.warmup_agent_steps = 1000; train(create_run(cfg))",
     ("warmup_agent_steps", "total_env_steps")),
    (TRAIN + "cfg.eval_every = 1000; train(create_run(cfg))", ("eval_every",), True),
    # callbacks in other forms
    (callback(QUIET) + "train(create_run(cfg), C())", ("callbacks", "list")),
    (callback(QUIET) + "train(create_run(cfg), [C])", ("C()", "instance", "class")),
    (TRAIN + "train(create_run(cfg), [lambda run, metrics: None])", "TrainCallback"),
    (callback(QUIET) + "m = train(create_run(cfg), (C(),)); assert m", ""),
    # Gymnasium's own wrappers with the wrappers
    (f"v = gym.wrappers.vector.RescaleAction(w.ConstantBonusVectorReward({PEND}, 0.1), -1.0, "
     "1.0); " + STEPS3, ""),
    (f"v = w.ConstantBonusVectorReward(gym.wrappers.vector.TransformObservation({PEND}, "
     "lambda o: {'frames': o['frames'][:, -1]}), 0.1); " + STEPS3,
     ("frames", "TransformObservation")),
    (NOV + f"w.RNDReward({S}, nov, normalization='ReturnStd')", "return_std"),
    # the normalisations called directly, as their examples call them
    (NORM + "RewardStd()(np.array([1.0, 3.0]))", ("extrinsic", "counted")),
    (NORM + "ReturnStd()(np.array([1.0, 2.0]), np.zeros(2), np.array([0.0, 1.0]), "
     "np.ones(2, bool))", "envs"),
    (NORM + "RewardStd()(np.array([1.0, 3.0]), np.zeros(2), np.zeros(2, int), np.array([1, 1]))",
     "counted"),
    ("gym.make_vec('Pendulum-v1', 2, vectorization_mode='sync', "
     "wrappers=[lambda e: w.SimounObservation(e, size=16)])", "render_mode"),
    ("v = w.ConstantBonusVectorReward(gym.make_vec('Pendulum-v1', 2, vectorization_mode='sync', "
     "render_mode='rgb_array', wrappers=[w.SimounObservation]), 0.1); " + STEPS3, ""),
    ("gym.make_vec('Pendulum-v1', 2, vectorization_mode='sync', render_mode='rgb_array', "
     "wrappers=[w.SimounObservation, w.ConstantBonusReward])", "scale"),
    # the PettingZoo wrapper
    (PZ + "SPO(pz, size=(16, 16, 3))", "size"),
    (PZ + "from pettingzoo.test import parallel_seed_test; parallel_seed_test(lambda: "
     "SPO(pettingzoo.make('parallel', 'butterfly/pistonball-v6', n_pistons=3, "
     "render_mode='rgb_array'), size=16), num_cycles=3)", ""),
    (PZ + "e = SPO(pz, size=16); assert e.observation_spaces['piston_0'] == "
     "e.observation_space('piston_0')", ""),
    (PZ + "e = SPO(pz, size=16, source='observation'); " + PZ_STEP, ""),
    (SPO + "from pettingzoo.sisl import pursuit_v5; e = SPO(pursuit_v5.parallel_env("
     "render_mode='rgb_array', max_cycles=20), size=16); " + PZ_STEP, ""),
    (PZ + "e = SPO(pz, size=16); e.reset(seed=0); e.step({a: np.zeros(3, np.float32) for a in "
     "e.agents})", ("action", "(1,)")),
    # names imported from the package, names as other libraries spell them
    ("from simoun_lab.analysis import layer_activations", "simoun_lab.analysis.layers"),
    ("from simoun_lab.analysis import play_episode", "simoun_lab.analysis.runs"),
    ("from simoun_lab.stats import interquartile_mean", "iqm"),
    ("from simoun_agent import TrainConfig", ("simoun_agent.config",), True),
]  # fmt: skip

CASES: list[dict] = [
    api(code, names, ok=ok[0] if ok else not names) for code, names, *ok in ELEVENTH_CODES
]
