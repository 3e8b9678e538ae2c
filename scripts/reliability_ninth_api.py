"""The ninth reliability trial's cases: api (see reliability_trial.py).

The Python API on surfaces no earlier trial touched: the training loop driven from Python
(``create_run`` and ``train`` with a config from ``resolve``, callbacks of the user's own given in
other forms, with other signatures, metrics or stop answers, a run trained twice or set up twice,
a config changed after ``resolve``); ``RandomPolicy`` played by ``evaluate``; ``evaluate_runs``,
``write_report``, ``DistractionEvaluation`` and ``distraction_callbacks`` of the distraction suite;
recipes in Python (``AgentConfig(recipe=...)`` with fields given, positionally, a recipe that
contradicts a field; ``Recipe.values_for``) and presets that fit or not the env given;
the agent's ``update_window`` given numpy arrays, floats and targets of the wrong shape, ``cpu()``
and ``cuda()``, states edited or given as a path, copies of an agent, updates from replays of
another frame count or with no transition; replays loaded from a glob pattern and added to after
an episode ended; the RND and curiosity models' ``update`` with nothing watched, pickling, an
unbatched triplet, another model's state and ``FeatureSource``; ``make_encoder``; Gymnasium's
TimeAwareObservation, FlattenObservation, RescaleAction and the vector DictInfoToList with the
wrappers, actions given as torch tensors, lists, arrays or NaN, an env rendering
``rgb_array_list``, ResidualMotion over SimounObservation; the PettingZoo wrapper given an
unknown agent, an array for the actions, a negative seed, a size of three numbers, or stepped
after its episode ended; ``load_run`` of a literal ``~`` and a loaded run trained on from Python;
names misspelled or moved.
"""

from reliability_trial import (
    AGENT,
    CUR,
    DMC,
    FILLED,
    FRAME,
    FRAMES,
    NOV,
    RND,
    RNDC,
    S64,
    STEP,
    STEPS3,
    A,
    M,
    P,
    S,
    api,
    vec,
)

TINY_CONFIG = (
    "{'env': 'simoun/PointReach-v0', 'image_size': 32, 'warmup_agent_steps': 10, "
    "'eval_every': 20, 'eval_episodes': 1, 'checkpoint_every': 20, 'device': 'cpu', "
    "'torch_threads': 1, 'agent.batch_size': 8, 'agent.num_filters': 4, "
    "'agent.feature_dim': 8, 'agent.hidden_dim': 16, 'agent.aux_hidden_dim': 16, "
    "'progress': False, 'video': False, 'total_env_steps': 40, 'run_dir': 'r'}"
)
# the tiny run's settings as a user writes them in Python, and the loop's functions
TRAIN = (
    "from simoun_agent.config import resolve, to_dict; "
    "from simoun_agent.run.train import create_run, train; "
    "from simoun_agent.run.callback import TrainCallback\n"
    f"cfg = resolve(None, {TINY_CONFIG})\n"
)


def callback(body: str) -> str:
    """TRAIN and a TrainCallback subclass ``C`` whose methods are ``body`` (indented once)."""
    return TRAIN + "class C(TrainCallback):\n" + body + "\n"


METRIC = callback("    def on_evaluation(self, run, metrics):\n        metrics['mine'] = 1.0")
LOAD = "from simoun_agent.run.load import load_run; "
LOADED = LOAD + "r = load_run('../tiny', device='cpu'); "
LAST_REPLAY = "import glob; last = sorted(glob.glob('../tiny/replay-*.npz'))[-1]; "
EVAL = "from simoun_agent.run.evaluate import RandomPolicy, evaluate; "
RUNS = (
    "from pathlib import Path; from simoun_agent.generalization.evaluation import evaluate_runs; "
    "from simoun_agent.generalization.report import write_report; "
)
CALLBACKS = (
    "from simoun_agent.config import resolve; from simoun_agent.generalization.callback import "
    "DistractionEvaluation, distraction_callbacks; "
)
CONF = "from simoun_agent.config import AgentConfig, TrainConfig, resolve; "
RECIPE = "from simoun_agent.config.recipes import RECIPES; "
TORCH = "import torch; a = " + A + "; "
WINDOW = "torch.zeros((8, 4, 3, 32, 32), dtype=torch.uint8)"
ACTION, REWARD, DISCOUNT = "torch.zeros(8, 1)", "torch.zeros(8)", "torch.ones(8)"
ENCODER = "from simoun_agent import make_encoder; "
PEND = vec("NEXT_STEP")
SPO = "from simoun_wrappers.pettingzoo import SimounParallelObservation as SPO; "
PZ_SHORT = (
    "import pettingzoo; " + SPO + "e = SPO(pettingzoo.make('parallel', 'butterfly/pistonball-v6', "
    "n_pistons=3, max_cycles=2, render_mode='rgb_array'), size=16); e.reset(seed=0); "
)
ACTIONS = "{a: e.action_space(a).sample() for a in e.agents}"
M64V = (
    "gym.make_vec('MiniGrid-Empty-5x5-v0', 2, vectorization_mode='sync', render_mode='rgb_array',"
    " wrappers=[lambda e: w.SimounObservation(e, size=64)])"
)

# (code, the name the refusal must give, or "" for valid input[, valid: either])
NINTH_CODES = [
    # the training loop driven from Python, with callbacks of one's own
    (TRAIN + "train(create_run(cfg))", ""),
    (METRIC + "train(create_run(cfg), [C()])", ""),
    (METRIC + "train(create_run(cfg), C())", "callbacks"),
    (METRIC + "train(create_run(cfg), [C])", ("C()", "callbacks")),
    (TRAIN + "train(create_run(cfg), [print])", ("TrainCallback", "callbacks")),
    (TRAIN + "train(create_run(cfg), callbacks=None)", "callbacks"),
    (callback("    def on_evaluation(self, run):\n        pass")
     + "train(create_run(cfg), [C()])", "on_evaluation"),
    (callback("    def on_evaluation(self, run, metrics):\n        metrics['note'] = 'best'")
     + "train(create_run(cfg), [C()])", "note"),
    (callback("    def stop_requested(self, run):\n        return True")
     + "train(create_run(cfg), [C()])", "stop_requested"),
    (TRAIN + "run = create_run(cfg); create_run(cfg)", ("'r'", "r/", "run directory")),
    (TRAIN + "create_run(to_dict(cfg))", "TrainConfig"),
    (TRAIN + "create_run(cfg, overwrite='yes')", "overwrite"),
    (TRAIN + "cfg.run_dir = '/proc/simoun-run'; create_run(cfg)", "/proc/simoun-run"),
    (TRAIN + "run = create_run(cfg); train(run); train(run)", ("resume", "finished")),
    (TRAIN + "cfg.total_env_steps = 0; create_run(cfg)", "total_env_steps"),
    (TRAIN + "cfg.eval_distraction = ('color_easy',); train(create_run(cfg))",
     ("dm_control", "eval_distraction")),
    (TRAIN + "cfg.agent.lr = float('nan'); create_run(cfg)", "lr"),
    (TRAIN + "import torch; assert not torch.cuda.is_available(); cfg.device = 'cuda'; "
     "create_run(cfg)", "cuda"),
    (TRAIN + "create_run(cfg, check=True)", "check"),
    # RandomPolicy played by evaluate()
    (LOADED + EVAL + "m, _ = evaluate(RandomPolicy(r.env.action_space.shape[0], 0), r.env, 1, "
     "r.first_seed); assert 'return_mean' in m, m", ""),
    (LOADED + EVAL + "evaluate(RandomPolicy(5, 0), r.env, 1, 0)", ("action", "5")),
    (LOADED + EVAL + "evaluate(RandomPolicy(r.env.action_space, 0), r.env, 1, 0)",
     ("action_dim", "Box")),
    (LOADED + EVAL + "evaluate(RandomPolicy(2, -1), r.env, 1, 0)", "seed"),
    (LOADED + EVAL + "evaluate(RandomPolicy(2.5, 0), r.env, 1, 0)", "action_dim"),
    (LOADED + EVAL + "evaluate(r.agent, r.env, 1, r.first_seed, on_episode=lambda: None)",
     "on_episode"),
    (LOADED + EVAL + "evaluate(r.agent, r.env, 1, r.first_seed, stop=lambda: 'no')", "stop"),
    # evaluate_runs and write_report from Python
    (RUNS + "res = evaluate_runs(['../tiny'], ['train'], 1); assert len(res) == 1, res", ""),
    (RUNS + "evaluate_runs(['../tiny'], 'train', 1)", "modes"),
    (RUNS + "evaluate_runs(['../tiny'], ['color_easy'], 1)", "dm_control"),
    (RUNS + "evaluate_runs([], ['train'], 1)", ("run_dirs",), True),
    (RUNS + "import torch; assert not torch.cuda.is_available(); "
     "evaluate_runs(['../tiny'], ['train'], 1, device='cuda')", "cuda"),
    (RUNS + "evaluate_runs(['../tiny'], ['train'], 1, progress=True)", "progress"),
    (RUNS + "evaluate_runs(['../tiny'], ['train'], 0)", "episodes"),
    (RUNS + "evaluate_runs(['../tiny'], ['train'], 1, seed=-1)", "seed"),
    (RUNS + "evaluate_runs(['../tiny/checkpoint.pt'], ['train'], 1)",
     ("checkpoint.pt", "run director")),
    (RUNS + "write_report(evaluate_runs(['../tiny'], ['train'], 1), Path('out'), 'PointReach')",
     ("out",), True),
    (RUNS + "import os; os.mkdir('out'); "
     "write_report(evaluate_runs(['../tiny'], ['train'], 1), 'out', 'PointReach')", ("out",),
     True),
    # the distraction callbacks
    (CALLBACKS + "DistractionEvaluation('color_easy')", ("modes", "list")),
    (CALLBACKS + "distraction_callbacks(resolve('cpu', {'eval_distraction': ['colour_easy']}))",
     "colour_easy"),
    (CALLBACKS + "c = distraction_callbacks(resolve(None, {'eval_distraction': ['color_easy']})); "
     "assert len(c) == 1, c", ""),
    (CALLBACKS + "from simoun_agent.generalization.suite import parse_distractions; "
     "parse_distractions('color_easy;video_easy')", ("color_easy;video_easy", ",")),
    # recipes and presets in Python
    (CONF + "c = AgentConfig(recipe='drqv2', lr=3e-4); "
     "assert (c.actor, c.lr) == ('deterministic', 3e-4), c", ""),
    (CONF + "c = AgentConfig('drqv2'); assert c.actor == 'deterministic', c.actor", ""),
    (CONF + "AgentConfig(recipe='drq ')", ("'drq '", "recipe")),
    (CONF + "AgentConfig(recipe='simoun_no_curiosity', curiosity=True)", ("curiosity",), True),
    (RECIPE + "RECIPES['drqv2'].values_for('dm_control/cartpole-swingup-v0')",
     ("cartpole-swingup", "task")),
    (CONF + "resolve('cartpole-swingup', {'env': 'dm_control/cheetah-run-v0'})", "cheetah-run"),
    (CONF + "c = resolve('highway', {'env': 'highway-fast-v0'}); "
     "assert c.env == 'highway-fast-v0', c.env", ""),
    (CONF + "resolve('cpu', {'agent.recipe': ['drq']})", "agent.recipe"),
    (CONF + "resolve('cpu', {'eval_distraction': ('color_easy',)})", ("eval_distraction",), True),
    (CONF + "AgentConfig(n_step=3, discount=99)", "discount"),
    (CONF + "TrainConfig(image_size=(64, 64))", "image_size"),
    (CONF + "TrainConfig(image_size='32')", "image_size"),
    (CONF + "TrainConfig(eval_distraction=('color_easy', 'color_easy'))", "color_easy"),
    (CONF + "AgentConfig(recipe='drqv2', actor='Gaussian')", "actor"),
    (CONF + "resolve('cartpole_swingup', {})", "cartpole-swingup"),
    # the agent's own methods: update_window, cpu/cuda, states, copies
    (AGENT + TORCH + f"a.update_window({WINDOW}, {ACTION}, {REWARD}, {DISCOUNT}, 0)", ""),
    (AGENT + TORCH + f"a.update_window(np.zeros((8, 4, 3, 32, 32), np.uint8), {ACTION}, "
     f"{REWARD}, {DISCOUNT}, 0)", ("window", "tensor")),
    (AGENT + TORCH + "a.update_window(torch.zeros((8, 4, 3, 32, 32)), "
     f"{ACTION}, {REWARD}, {DISCOUNT}, 0)", ("uint8", "window")),
    (AGENT + TORCH + f"a.update_window({WINDOW}, torch.zeros(8, 2), {REWARD}, {DISCOUNT}, 0)",
     "action"),
    (AGENT + TORCH + f"a.update_window({WINDOW}, {ACTION}, torch.zeros(8, 1), {DISCOUNT}, 0)",
     "reward"),
    (AGENT + TORCH + "a.update_window(torch.zeros((4, 4, 3, 32, 32), dtype=torch.uint8), "
     f"{ACTION}, {REWARD}, {DISCOUNT}, 0)", ("batch", "window")),
    (AGENT + TORCH + "a.update_window(torch.zeros((8, 6, 3, 32, 32), dtype=torch.uint8), "
     f"{ACTION}, {REWARD}, {DISCOUNT}, 0)", ("return_mask", "window")),
    (AGENT + "import torch; assert not torch.cuda.is_available(); " + A + ".cuda()", "cuda"),
    (AGENT + A + ".cpu().act(" + FRAMES + ")", ("cpu", "to"), True),
    (AGENT + A + f".act({FRAMES}, step=True)", "step"),
    (AGENT + "r = FrameReplay(100, (3, 32, 32), 1); r.start_episode(" + FRAME + "); "
     + A + ".update(r, 0)", ("replay", "transition")),
    (AGENT + "r = FrameReplay(100, (3, 32, 32), 1, num_frames=2); r.start_episode(" + FRAME
     + "); [r.add(np.zeros(1), 0.0, " + FRAME + ", False, False) for _ in range(9)]; "
     + A + ".update(r, 0)", "num_frames"),
    (AGENT + "import torch; torch.save(" + A + ".state_dict(), 'a.pt'); "
     + A + ".load_state_dict('a.pt')", ("state", "torch.load")),
    (AGENT + "s = " + A + ".state_dict(); del s['critic_optimizer']; " + A
     + ".load_state_dict(s)", "critic_optimizer"),
    (AGENT + "s = " + A + ".state_dict(); s['num_updates'] = -1; " + A + ".load_state_dict(s)",
     "num_updates"),
    (AGENT + "import copy; copy.deepcopy(" + A + f").act({FRAMES})", ""),
    (AGENT + "pickle.loads(pickle.dumps(" + A + f")).act({FRAMES})", ("pickle", "state_dict"),
     True),
    # replays
    (AGENT + "FrameReplay.load('../tiny/replay-*.npz')", "replay-*.npz"),
    (AGENT + FILLED + "r.add(np.zeros(1), 0.0, " + FRAME + ", True, False); "
     "r.add(np.zeros(1), 0.0, " + FRAME + ", False, False)", "start_episode"),
    (AGENT + "FrameReplay(100, (3, 32, 32), 1.0)", "action_dim"),
    (LOADED + LAST_REPLAY + "from simoun_agent import FrameReplay; "
     "r.agent.update(FrameReplay.load(last), step=40)", ""),
    # the RND and curiosity models
    (RND + f"RNDModel.for_env({S64}).update()", ("watch", "buffer", "transition")),
    (RND + f"m = pickle.loads(pickle.dumps(RNDModel.for_env({S64}))); "
     "m(np.zeros((2, 3, 3, 64, 64), np.uint8))", ""),
    (CUR + f"CuriosityModel.for_env({M64V})", ""),
    (RND + f"RNDModel.for_env({S64})(np.zeros((3, 3, 64, 64), np.uint8))",
     ("shape", "(B, 3")),
    (RND + CUR + f"RNDModel.for_env({S64}).load_state_dict(CuriosityModel.for_env({S64})"
     ".state_dict())", ("RNDModel", "CuriosityModel")),
    (CUR + f"CuriosityModel.for_env({S64})(np.zeros((2, 3, 3, 32, 32), np.uint8))",
     ("64", "32", "shape")),
    (CUR + f"assert isinstance(CuriosityModel.for_env({S64}), w.FeatureSource)", ""),
    (RNDC + f"RNDModel.for_env({S64}, config=RNDConfig(seed=1.5))", "seed"),
    # encoders
    (AGENT + ENCODER + "make_encoder(cfg, (32, 32, 3))", ("frame_shape", "(3, 32, 32)")),
    (AGENT + ENCODER + "make_encoder(cfg, (3, 8, 8))", ("8", "size")),
    (ENCODER + "make_encoder({'encoder': 'dual'}, (3, 32, 32))", ("config", "AgentConfig")),
    # Gymnasium's own wrappers with the wrappers
    (f"e = w.ConstantBonusReward(gym.wrappers.TimeAwareObservation({S}), 0.1); " + STEP, ""),
    (NOV + f"w.RNDReward(gym.wrappers.FlattenObservation({S}), nov, warmup=0)",
     ("frames", "FlattenObservation")),
    (f"e = w.SimounObservation(gym.wrappers.RescaleAction({P}, -1.0, 1.0), size=16); "
     "e.reset(seed=0); e.step(np.array([0.5], np.float32))", ""),
    (f"v = gym.wrappers.vector.DictInfoToList(w.ConstantBonusVectorReward({PEND}, 0.1)); "
     + STEPS3, ""),
    (f"v = w.ConstantBonusVectorReward(gym.wrappers.vector.DictInfoToList({PEND}), 0.1); "
     + STEPS3, ("DictInfoToList", "info")),
    (f"e = {S}; e.reset(seed=0); import torch; e.step(torch.tensor([0.5]))",
     ("action", "tensor")),
    (f"e = {S}; e.reset(seed=0); e.step(np.array([float('nan')], np.float32))", "action"),
    (f"e = w.SimounObservation({M}, size=16); e.reset(seed=0); e.step(np.array([2]))",
     ("action",), True),
    (f"e = {S}; e.reset(seed=0); e.step([0.5])", ("action",), True),
    ("w.SimounObservation(gym.make('Pendulum-v1', render_mode='rgb_array_list'), size=16)",
     ("rgb_array_list", "render_mode")),
    (f"w.ResidualMotion({S})", ("SimounObservation", "motion")),
    (NOV + "from simoun_wrappers.intrinsic_normalization import RewardStd; "
     f"w.RNDReward({S}, nov, normalization=RewardStd)", ("normalization", "RewardStd()")),
    (DMC + "w.ColorShift(d, level='Hard')", ("level", "hard")),
    # PettingZoo
    (PZ_SHORT + f"e.step({{**{ACTIONS}, 'piston_9': np.zeros(1, np.float32)}})", "piston_9"),
    (PZ_SHORT + "e.step(np.zeros((3, 1), np.float32))", ("dict", "actions")),
    (SPO + "import pettingzoo; SPO(pettingzoo.make('parallel', 'butterfly/pistonball-v6', "
     "n_pistons=3, render_mode='rgb_array'), size=16).reset(seed=-1)", "seed"),
    (SPO + "import pettingzoo; SPO(pettingzoo.make('parallel', 'butterfly/pistonball-v6', "
     "n_pistons=3, render_mode='rgb_array'), size=(16, 16, 3))", "size"),
    (PZ_SHORT + f"e.step({ACTIONS}); e.step({ACTIONS}); e.step({ACTIONS})", "reset"),
    # load_run of other paths, trained on from Python
    (LOAD + "load_run('~/tiny', device='cpu')", "~"),
    (LOADED + "r.agent.act(r.env.reset(seed=0)[0]['frames'][None])",
     ("shape", "(3, 3, 32, 32)")),
    # names misspelled or moved
    ("from simoun_agent import Agent", ("Agent", "SimounAgent")),
    ("import simoun_agent; simoun_agent.FrameBuffer", ("FrameBuffer", "FrameReplay")),
    ("from simoun_wrappers import ConsistencyReward", ("ConsistencyReward",
     "ConsistencyCuriosityReward")),
    ("import warnings; warnings.simplefilter('ignore'); import simoun_agent.cli.sweep",
     ("simoun_lab",), True),
]  # fmt: skip

CASES: list[dict] = [
    api(code, names, ok=ok[0] if ok else not names) for code, names, *ok in NINTH_CODES
]
