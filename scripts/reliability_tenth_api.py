"""The tenth reliability trial's cases: api (see reliability_trial.py).

The Python API on surfaces no earlier trial touched: the lab's statistics called from a notebook
(``simoun_lab.stats``: scores given as lists, an array instead of a task dict, NaN runs, a
confidence in percent or as text, no resamples or a fraction of one, a negative seed, a statistic
given by name or of the wrong kind, tasks that differ, curves where final scores go and final scores
where curves go, one threshold where a list goes, an env id and returns swapped, curves on different
step grids, no tasks or a task with no runs, a function name misspelt) and the information-bias
estimator (``information_bias``: factors capitalised, a threshold in percent, pairs stacked in one
array, NaN activations, pairs of unequal length, conv maps, a list of pairs, an unknown factor);
``play_episode`` of a loaded run, its seed, its arguments swapped; Gymnasium's DelayObservation,
TransformAction, FilterObservation and a TransformObservation to torch tensors around and under the
wrappers, the vector FlattenObservation, DtypeObservation and TransformReward; Stable-Baselines3's
DummyVecEnv under the vector rewards and over the single ones, ``check_sb3_policy`` given a
PettingZoo env; other PettingZoo envs (cooperative pong, knights-archers-zombies whose agents leave
mid-episode, discrete pistonball with frames of two sizes), unknown agents' spaces, a step with
agents missing and a step after close; highway-env's rendered frames and its stacked grayscale
observation; normalisations at their edges (``ReturnStd`` of gamma 0 and 1, ``Standardize``), a
constant bonus normalised, a warmup written 1e3, a novelty source of a torch model given numpy
triplets, the model classes given where their instances go, a scale as text; vector resets with a
seed per env or a float seed, a vector step after close; agent configs in the forms of other
libraries (a list of hidden sizes, a device, swapped log-std bounds, a pad without its augmentation,
an even kernel, a negative curiosity scale or pad), a recipe's config copied through
``dataclasses.asdict``, ``resolve`` given nested or underscored keys and numpy seeds, env kwargs, a
switch and a distraction mode as one string; the training loop driven from Python with hooks
misspelt or named as other libraries name them, a hook returning a stop answer, the config given
where a run goes, an env changed after ``resolve``, a dict assigned to ``cfg.agent``, unknown env
kwargs, a run dir as a Path, training in a thread; the agent's ``act`` given a non-bool
``deterministic``; names imported from the wrong package; MiniGrid's actions under the constant
bonus.
"""

from reliability_ninth_api import TRAIN, callback
from reliability_trial import (
    AGENT,
    CUR,
    FEAT,
    FRAMES,
    NOV,
    PZ,
    RND,
    S64,
    STEP,
    STEPS3,
    A,
    C,
    M,
    P,
    S,
    api,
    vec,
)

ST = "from simoun_lab import stats as st; "
IB = (
    "from simoun_lab.analysis import information_bias; rng = np.random.default_rng(0); "
    "z = rng.normal(size=(50, 4)); "
)
CONF = "from simoun_agent.config import AgentConfig, TrainConfig, resolve; "
NORM = "from simoun_wrappers.intrinsic_normalization import ReturnStd, Standardize; "
PEND = vec("NEXT_STEP")
FOLDED = vec("NEXT_STEP", wrap="w.SimounObservation(e, size=16, fold_frames=True)")
DUMMY = "from stable_baselines3.common.vec_env import DummyVecEnv; "
SPO = "from simoun_wrappers.pettingzoo import SimounParallelObservation as SPO; "
ACTS = "{a: e.action_space(a).sample() for a in e.agents}"
PZ_STEP = f"e.reset(seed=0); e.step({ACTS})"
HIGHWAY = "import highway_env; gym.register_envs(highway_env); "
PLAY = (
    "from simoun_agent.run.load import load_run; from simoun_lab.analysis.runs import "
    "play_episode; r = load_run('../tiny', device='cpu'); "
)
TEN = "z = np.arange(8.0); "
# observations made torch tensors, as Gymnasium's NumpyToTorch makes them (which needs
# array_api_compat, an optional dependency of Gymnasium that is not installed here)
TORCH = (
    "import torch\ndef to_torch(o):\n    return {k: torch.from_numpy(v) for k, v in o.items()}\n"
)

# (code, the name the refusal must give, or "" for valid input[, valid: either])
TENTH_CODES = [
    # the lab's statistics from a notebook
    (ST + "assert st.iqm([1, 2, 3, 4]) == 2.5", ""),
    (ST + "st.aggregate_iqm(np.array([0.7, 0.65, 0.72]))", ("scores", "task")),
    (ST + "st.iqm([0.7, float('nan'), 0.72, 0.8])", "NaN"),
    (ST + "st.probability_of_improvement({'t': [1.0, float('nan')]}, {'t': [0.5, 0.6]})", "NaN"),
    (ST + TEN + "st.stratified_bootstrap_ci({'t': z}, st.aggregate_iqm, confidence=95)",
     "confidence"),
    (ST + TEN + "st.stratified_bootstrap_ci({'t': z}, st.aggregate_iqm, confidence='95%')",
     "confidence"),
    (ST + TEN + "st.stratified_bootstrap_ci({'t': z}, st.aggregate_iqm, reps=0)", "reps"),
    (ST + TEN + "st.stratified_bootstrap_ci({'t': z}, st.aggregate_iqm, reps=2.5)", "reps"),
    (ST + TEN + "st.stratified_bootstrap_ci({'t': z}, st.aggregate_iqm, seed=-1)", "seed"),
    (ST + TEN + "st.stratified_bootstrap_ci({'t': z}, 'iqm')", "statistic"),
    (ST + TEN + "st.stratified_bootstrap_ci({'t': z}, st.iqm)", ("aggregate_iqm", "statistic")),
    (ST + "st.probability_of_improvement({'cartpole': [1.0, 2.0]}, {'cheetah': [1.0, 2.0]})",
     "cartpole"),
    (ST + "assert st.probability_of_improvement({'t': [2.0, 3.0]}, {'t': [1.0]}) == 1.0", ""),
    (ST + "st.probability_of_improvement({'t': np.array([[1.0, 2.0], [3.0, 4.0]])}, "
     "{'t': np.array([1.0, 2.0])})", ("runs", "steps", "shape")),
    (ST + "st.performance_profile({'t': [0.2, 0.6]}, 0.5)", ("taus", "tau")),
    (ST + "st.normalize(np.array([500.0]), 'dm_control/cheetah-run-v0')", "env_id"),
    (ST + "st.iqm_over_steps({'a': np.zeros((3, 5)), 'b': np.zeros((3, 4))})",
     ("steps", "step grid")),
    (ST + "st.aggregate_iqm({})", ("task", "scores", "run")),
    (ST + "st.iqm_over_steps({'t': [1.0, 2.0, 3.0]})", ("runs", "steps")),
    ("from simoun_lab.stats import bootstrap_ci", "stratified_bootstrap_ci"),
    (ST + "st.aggregate_mean({'t': []})", ("task", "run")),
    (ST + "st.probability_of_improvement_ci({'t': [1.0, 2.0]}, {'t': [0.0, 1.0]}, confidence=1)",
     "confidence"),
    # the information-bias estimator
    (IB + "information_bias({'dynamic': (z, z + 0.1), 'static': (z, rng.normal(size=(50, 4)))})",
     ""),
    (IB + "information_bias({'Dynamic': (z, z), 'Static': (z, z)})", "dynamic"),
    (IB + "information_bias({'dynamic': (z, z), 'static': (z, z)}, threshold=50)", "threshold"),
    (IB + "information_bias({'dynamic': np.stack([z, z]), 'static': np.stack([z, -z])})", ""),
    (IB + "z[0, 0] = np.nan; information_bias({'dynamic': (z, z), 'static': (z, z)})", "NaN"),
    (IB + "information_bias({'dynamic': (z, z[:40]), 'static': (z, z)})", "dynamic"),
    (IB + "information_bias({'dynamic': (z, z), 'static': (z, z), 'motion': (z, z)})", "motion"),
    (IB + "information_bias([(z, z), (z, z)])", ("pairs", "dynamic", "dict")),
    (IB + "t = rng.normal(size=(10, 4, 3, 3)); information_bias({'dynamic': (t, t), "
     "'static': (t, t)})", ("(N, D)", "pooled")),
    # play_episode of a loaded run
    (PLAY + "ep = play_episode(r.agent, r.env, r.first_seed); assert len(ep.rewards) > 0", ""),
    (PLAY + "play_episode(r.agent, r.env, -1)", "seed"),
    (PLAY + "play_episode(r.env, r.agent, r.first_seed)", ("agent", "env")),
    # Gymnasium's own wrappers around and under the wrappers
    (f"e = w.SimounObservation(gym.wrappers.DelayObservation(gym.wrappers.AddRenderObservation("
     f"{C}), 1), size=16); " + STEP, ""),
    (f"s = {S}; e = gym.wrappers.TransformAction(s, lambda a: np.clip(a, -2, 2), "
     "s.action_space); " + STEP, ""),
    (TORCH + f"s = {S}; e = w.ConstantBonusReward(gym.wrappers.TransformObservation(s, to_torch, "
     "s.observation_space), 0.1); " + STEP, ("TransformObservation", "tensor", "torch")),
    (TORCH + f"s = w.ConstantBonusReward({S}, 0.1); e = gym.wrappers.TransformObservation(s, "
     "to_torch, s.observation_space); e.reset(seed=0); o, *_ = e.step(np.zeros(1, np.float32)); "
     "assert isinstance(o['frames'], torch.Tensor)", ""),
    (f"w.ConstantBonusReward(gym.wrappers.FilterObservation({S}, ['motion']), 0.1)", "frames"),
    (NOV + f"w.RNDVectorReward(gym.wrappers.vector.FlattenObservation({PEND}), nov)",
     ("frames", "FlattenObservation")),
    (f"w.ConstantBonusVectorReward(gym.wrappers.vector.DtypeObservation({FOLDED}, np.float32), "
     "0.1)", ("uint8", "DtypeObservation")),
    (f"v = gym.wrappers.vector.TransformReward(w.ConstantBonusVectorReward({PEND}, 0.1), "
     "lambda r: 0.5 * r); " + STEPS3, ""),
    # Stable-Baselines3's vector envs with the rewards
    (DUMMY + f"w.ConstantBonusVectorReward(DummyVecEnv([lambda: {S}]), 0.1)",
     ("VectorEnv", "DummyVecEnv")),
    (NOV + DUMMY + f"w.RNDVectorReward(DummyVecEnv([lambda: {S}]), nov)",
     ("VectorEnv", "DummyVecEnv")),
    (DUMMY + "v = DummyVecEnv([lambda: w.ConstantBonusReward(w.SimounObservation("
     f"{P}, size=36, fold_frames=True), 0.1)]); v.reset(); v.step(np.zeros((1, 1), np.float32))",
     ""),
    (PZ + "w.check_sb3_policy(SPO(pz, size=36, fold_frames=True), 'CnnPolicy')",
     ("ParallelEnv", "PettingZoo", "gymnasium")),
    # other PettingZoo envs, actions and closes
    ("import pettingzoo; " + SPO + "e = SPO(pettingzoo.make('parallel', "
     "'butterfly/cooperative_pong-v6', render_mode='rgb_array'), size=16); " + PZ_STEP, ""),
    ("import pettingzoo; " + SPO + "e = SPO(pettingzoo.make('parallel', "
     "'butterfly/knights_archers_zombies-v11', render_mode='rgb_array', max_cycles=20), "
     f"size=16); e.reset(seed=0)\nwhile e.agents:\n    e.step({ACTS})", ""),
    ("import pettingzoo; " + SPO + "e = SPO(pettingzoo.make('parallel', "
     "'butterfly/pistonball-v6', n_pistons=3, continuous=False, render_mode='rgb_array'), "
     "size=(16, 24), grayscale=True); " + PZ_STEP, ""),
    (PZ + "SPO(pz, size=16).observation_space('piston_7')", "piston_7"),
    (PZ + "e = SPO(pz, size=16); e.reset(seed=0); e.step({'piston_0': np.zeros(1, np.float32)})",
     ("piston_1", "piston_2")),
    (PZ + f"e = SPO(pz, size=16); e.reset(seed=0); e.close(); e.step({ACTS})",
     ("close", "reset")),
    # highway-env's frames
    (HIGHWAY + "e = w.SimounObservation(gym.make('highway-fast-v0', render_mode='rgb_array'), "
     "size=16); " + STEP, ""),
    (HIGHWAY + "w.SimounObservation(gym.make('highway-fast-v0', render_mode='rgb_array', "
     "config={'observation': {'type': 'GrayscaleObservation', 'observation_shape': (128, 64), "
     "'stack_size': 4, 'weights': [0.2989, 0.587, 0.114]}}), source='observation')",
     ("GrayscaleObservation", "(4, 128, 64)", "channel", "stack")),
    # normalisations and novelty sources
    (NORM + "ReturnStd(gamma=1.0)", "gamma"),
    (NORM + NOV + f"e = w.RNDReward({S}, nov, warmup=0, normalization=ReturnStd(0.0)); " + STEP,
     ""),
    (NORM + NOV + f"e = w.RNDReward({S}, nov, warmup=0, normalization=Standardize()); " + STEP,
     ""),
    (f"w.ConstantBonusReward({S}, 0.1, normalization='reward_std')", "normalization"),
    (NOV + f"w.RNDReward({S}, nov, warmup=1e3)", ("warmup",), True),
    (f"import torch; net = torch.nn.Sequential(torch.nn.Flatten(), torch.nn.LazyLinear(1)); "
     f"e = w.RNDReward({S}, lambda t: net(t).squeeze(-1), warmup=0); " + STEP,
     ("novelty", "numpy")),
    (FEAT + f"e = w.ConsistencyCuriosityReward({S}, feat, scale='0.2')", "scale"),
    (RND + f"w.RNDReward({S64}, RNDModel)", ("RNDModel.for_env", "novelty")),
    (CUR + f"w.ConsistencyCuriosityReward({S64}, CuriosityModel)",
     ("CuriosityModel.for_env", "features")),
    # vector resets
    (f"v = w.ConstantBonusVectorReward({PEND}, 0.1); v.reset(seed=[3, 4]); "
     "v.step(v.action_space.sample())", ""),
    (f"v = w.ConstantBonusVectorReward({PEND}, 0.1); v.reset(seed=[3, 3.5])", "seed"),
    (f"v = w.ConstantBonusVectorReward({PEND}, 0.1); v.reset(seed=0); v.close(); "
     "v.step(v.action_space.sample())", ("close", "reset")),
    # agent configs in other libraries' forms, copies of recipes
    (CONF + "AgentConfig(hidden_dim=[256, 256])", "hidden_dim"),
    (CONF + "AgentConfig(device='cuda')", ("device", "TrainConfig")),
    (CONF + "AgentConfig(critic_tau=1.5)", "critic_tau"),
    (CONF + "AgentConfig(init_temperature=0)", "init_temperature"),
    (CONF + "AgentConfig(log_std_min=2.0, log_std_max=-10.0)", ("log_std_min", "log_std_max")),
    (CONF + "AgentConfig(shift_pad=4)", ("shift_pad", "augmentation")),
    (CONF + "AgentConfig(augmentation='shift', shift_pad=-4)", "shift_pad"),
    (CONF + "AgentConfig(random_conv_kernel=4)", "random_conv_kernel"),
    (CONF + "AgentConfig(curiosity_scale=-0.2)", "curiosity_scale"),
    (CONF + "import dataclasses; c = AgentConfig(**dataclasses.asdict(AgentConfig("
     "recipe='drqv2'))); assert c.actor == 'deterministic', c.actor", ""),
    (CONF + "resolve(None, {'agent': {'lr': 1e-3}})", ("agent.lr", "agent."), True),
    (CONF + "resolve(None, {'agent_lr': 1e-3})", "agent.lr"),
    (CONF + "c = resolve(None, {'seed': np.int64(3)}); assert c.seed == 3", ""),
    (CONF + "TrainConfig(env_kwargs='max_episode_steps=50')", "env_kwargs"),
    (CONF + "TrainConfig(grayscale='False')", "grayscale"),
    (CONF + "TrainConfig(eval_distraction='color_easy')", ("eval_distraction", "color_easy")),
    # the training loop from Python
    (callback("    def on_evalution(self, run, metrics):\n        raise SystemExit('never')")
     + "train(create_run(cfg), [C()])", "on_evalution"),
    (callback("    def on_step(self, run):\n        raise SystemExit('never')")
     + "train(create_run(cfg), [C()])", "on_step"),
    (callback("    def on_evaluation(self, run, metrics):\n        return True")
     + "train(create_run(cfg), [C()])", ("stop_requested", "on_evaluation")),
    (TRAIN + "train(cfg)", ("create_run", "Run")),
    (TRAIN + "cfg.env = 'simoun/PointReach-v1'; create_run(cfg)", "PointReach"),
    (TRAIN + "cfg.agent = {'lr': 1e-3}; create_run(cfg)", ("agent", "AgentConfig")),
    (TRAIN + "cfg.env_kwargs = {'nope': 1}; create_run(cfg)", "nope"),
    (TRAIN + "from pathlib import Path; cfg.run_dir = Path('r'); train(create_run(cfg))", ""),
    (TRAIN + "import threading; t = threading.Thread(target=lambda: train(create_run(cfg))); "
     "t.start(); t.join(); import os; assert os.path.exists('r/eval.csv')", ""),
    # the agent's act
    (AGENT + f"{A}.act({FRAMES}, deterministic='yes')", "deterministic"),
    (AGENT + f"{A}.act({FRAMES}, deterministic=None)", "deterministic"),
    # names imported from the wrong package
    ("from simoun_wrappers import SimounParallelObservation", "simoun_wrappers.pettingzoo"),
    ("from simoun_wrappers import ReturnStd", "intrinsic_normalization"),
    ("from simoun_lab import iqm", "simoun_lab.stats"),
    ("from simoun_agent import load_run", "simoun_agent.run.load"),
    ("from simoun_wrappers import RNDModel", "simoun_agent.rnd_model"),
    # MiniGrid's frames under the wrappers
    (f"e = w.ConstantBonusReward(w.SimounObservation({M}, size=16), 0.1); e.reset(seed=0); "
     "e.step(6)", ""),
    (f"e = w.ConstantBonusReward(w.SimounObservation({M}, size=16), 0.1); e.reset(seed=0); "
     "e.step(7)", "action"),
]  # fmt: skip

CASES: list[dict] = [
    api(code, names, ok=ok[0] if ok else not names) for code, names, *ok in TENTH_CODES
]
