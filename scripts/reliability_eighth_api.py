"""The eighth reliability trial's cases: api (see reliability_trial.py).

The Python API on surfaces no earlier trial touched: a run loaded from Python (``load_run`` on the
tiny run the trial trains, its path, device and threads, copies edited or damaged, the loaded env's
observation given to the agent) and evaluated (``evaluate``'s episodes, seeds, envs and recordings,
its callbacks); the distraction suite's functions (``parse_distractions``, ``distractor``,
``make_distracted_env``); ``default_device`` and the agent's ``to``; agents built from other kinds
of shapes, configs and frames, configs changed with ``dataclasses.replace``; ``resolve``,
``from_dict`` and ``to_dict`` given what a user writes in Python instead of on the command line;
Gymnasium's RecordVideo, FrameStackObservation, DtypeObservation, ResizeObservation,
NormalizeReward and vector ClipReward around and under the wrappers, SyncVectorEnv built by hand,
``reset`` with a positional seed, envs with their own time limit; the intrinsic rewards
given lambdas, torch tensors, models of another size and arguments of another normalisation; the
PettingZoo wrapper's render, state, and envs without a render mode; replays of a kept run and files
of another kind given to ``FrameReplay.load``, and PointReach's own arguments and through the
wrappers.
"""

from reliability_trial import (
    AGENT,
    CUR,
    DMC,
    FEAT,
    FILLED,
    FRAMES,
    NOV,
    PZ,
    RND,
    RNDC,
    S64,
    STEP,
    STEPS3,
    A,
    C,
    P,
    S,
    api,
    vec,
)

LOAD = "from simoun_agent.run.load import load_run; "
# the trial's tiny run lies beside each case's own directory
LOADED = LOAD + "r = load_run('../tiny', device='cpu'); "
OBS = "o, _ = r.env.reset(seed=r.first_seed); "
COPY = "import shutil; from pathlib import Path; shutil.copytree('../tiny', 'run'); "
LAST_REPLAY = "import glob; last = sorted(glob.glob('../tiny/replay-*.npz'))[-1]; "
EVAL = "from simoun_agent.run.evaluate import evaluate; "
SUITE = (
    "from simoun_agent.generalization.suite import distractor, make_distracted_env, "
    "parse_distractions; "
)
DEV = "from simoun_agent.device import default_device; "
CONF = (
    "from simoun_agent.config import PRESETS, RECIPES, AgentConfig, TrainConfig, from_dict, "
    "resolve, to_dict; "
)
PEND = vec("NEXT_STEP")
SPO = "from simoun_wrappers.pettingzoo import SimounParallelObservation as SPO; "
SMALL = "batch_size=8, num_filters=4, feature_dim=8, hidden_dim=16, aux_hidden_dim=16"

# (code, the name the refusal must give, or "" for valid input[, valid: either])
EIGHTH_CODES = [
    # a run loaded from Python: paths, devices, threads
    (LOADED + OBS + "r.env.step(r.agent.act(o['frames'], deterministic=True))", ""),
    (LOAD + "load_run('../tiny/checkpoint.pt', device='cpu').agent", ""),
    (LOAD + "load_run('../tiny/config.json')", ("config.json", "checkpoint")),
    (LOAD + LAST_REPLAY + "load_run(last)", ("replay", "checkpoint")),
    (LOAD + "load_run('../tyni')", "tyni"),
    (LOAD + "load_run(None)", "path"),
    (LOAD + "load_run('..')", "checkpoint"),
    (LOAD + "import os; os.mkdir('empty'); load_run('empty')", ("empty", "checkpoint")),
    (LOAD + "load_run('../tiny', device='gpu')", ("gpu", "device")),
    (LOAD + "import torch; assert not torch.cuda.is_available(); load_run('../tiny', 'cuda')",
     "cuda"),
    (LOAD + "load_run('../tiny', device='cpu', torch_threads=0)", "torch_threads"),
    (LOAD + "load_run('../tiny', device='cpu', torch_threads='2')", "torch_threads"),
    (LOAD + "import torch; load_run('../tiny', device=torch.device('cpu'))", ("device",), True),
    # copies of the run edited or damaged, then loaded
    (LOAD + COPY + "import json; p = Path('run/config.json'); d = json.loads(p.read_text()); "
     "d['agent']['lr'] = 0.1; p.write_text(json.dumps(d)); load_run('run', device='cpu')",
     "config.json"),
    (LOAD + COPY + "p = Path('run/checkpoint.pt'); p.write_bytes(p.read_bytes()[:1000]); "
     "load_run('run', device='cpu')", "checkpoint"),
    (LOAD + COPY + "[p.unlink() for p in Path('run').glob('replay-*.npz')]; "
     "load_run('run', device='cpu')", ("replay",), True),
    (LOAD + COPY + "Path('run/config.json').write_text(''); load_run('run', device='cpu')",
     "config.json"),
    (LOAD + COPY + "Path('run/config.json').write_text('[]'); load_run('run', device='cpu')",
     "config.json"),
    (LOAD + COPY + "Path('run/checkpoint.pt').unlink(); Path('run/checkpoint.pt').mkdir(); "
     "load_run('run', device='cpu')", "checkpoint"),
    (AGENT + LOAD + COPY + f"import torch; torch.save({A}.state_dict(), 'run/checkpoint.pt'); "
     "load_run('run', device='cpu')", "checkpoint"),
    # the loaded run used as a user would
    (LOADED + OBS + "r.agent.act(o)", "frames"),
    (LOADED + OBS + "r.env.step(r.agent.act(o['frames'])[0])", ("action", "shape")),
    (LOADED + "r.env.step(r.env.action_space.sample())", "reset"),
    # evaluate()
    (LOADED + EVAL + "m, _ = evaluate(r.agent, r.env, 1, r.first_seed); "
     "assert 'return_mean' in m, m", ""),
    (LOADED + EVAL + "m, frames = evaluate(r.agent, r.env, 1, 0, record=True); assert frames", ""),
    (LOADED + EVAL + "evaluate(r.agent, r.env, 0, 0)", "episodes"),
    (LOADED + EVAL + "evaluate(r.agent, r.env, 1.5, 0)", "episodes"),
    (LOADED + EVAL + "evaluate(r.agent, r.env, '1', 0)", "episodes"),
    (LOADED + EVAL + "evaluate(r.agent, r.env, 1, seed=-1)", "seed"),
    (LOADED + EVAL + "evaluate(r.agent, gym.make('Pendulum-v1'), 1, 0)",
     ("frames", "env", "observation")),
    (LOADED + EVAL + f"evaluate(r.agent, w.SimounObservation({P}, size=32), 1, 0)",
     ("frames", "action", "env")),
    (LOADED + EVAL + "evaluate(r.env, r.agent, 1, 0)", ("agent", "env")),
    (LOADED + EVAL + "evaluate(r.agent, r.env, 1, 0, record='yes')", "record"),
    (LOADED + EVAL + "evaluate(r.agent, r.env, 1, 0, on_episode='print')", "on_episode"),
    (LOADED + EVAL + "evaluate(r.agent, r.env, 1, 0, stop=True)", "stop"),
    # the distraction suite's functions
    (SUITE + "assert parse_distractions('color_easy, video_hard') == ['color_easy', "
     "'video_hard']", ""),
    (SUITE + "parse_distractions('colour_hard')", "color_hard"),
    (SUITE + "parse_distractions(['color_easy', None])", ("None", "distraction")),
    (SUITE + "parse_distractions(3)", ("3", "distraction")),
    (SUITE + "distractor('color_easy,video_easy')", "color_easy,video_easy"),
    (SUITE + LOADED + "make_distracted_env(r.config, 'color_easy')", "dm_control"),
    (SUITE + "parse_distractions('none')", ("none", "train")),
    (SUITE + LOADED + "make_distracted_env(r.config, 'colour_easy')", "color_easy"),
    (SUITE + "make_distracted_env('dm_control/cartpole-swingup-v0', 'color_easy')",
     ("config", "TrainConfig")),
    (SUITE + DMC + "distractor('video_easy', videos=3)(d)", "videos"),
    (SUITE + DMC + "distractor('video_easy', videos='no_such_folder')(d)",
     ("no_such_folder", "videos")),
    (SUITE + DMC + "e = distractor('color_hard')(d); " + STEP, ""),
    # default_device
    (DEV + "assert str(default_device('cpu')) == 'cpu'", ""),
    (DEV + "default_device('CPU')", ("CPU", "cpu"), True),
    (DEV + "default_device(0)", "device"),
    (DEV + "import torch; assert not torch.cuda.is_available(); default_device('cuda:1')", "cuda"),
    (DEV + "default_device('mps')", "mps"),
    (DEV + "default_device('cpu:0,cpu:1')", "cpu:0,cpu:1"),
    (DEV + "default_device('cuda:x')", "cuda:x"),
    (DEV + "default_device('')", "device"),
    # agents built from other kinds of shapes, configs and frames
    (AGENT + f"SimounAgent(np.array([3, 32, 32]), np.int64(2), cfg, device='cpu').act({FRAMES})",
     ""),
    (AGENT + CONF + "SimounAgent((3, 32, 32), 1, resolve('cpu', {}), device='cpu')",
     ("AgentConfig", "TrainConfig")),
    (AGENT + "SimounAgent((3, 32, 32), 1, {'lr': 1e-3}, device='cpu')", ("AgentConfig", "dict")),
    (AGENT + "SimounAgent((3, 32, 32), 1, device='cpu')", "config"),
    (AGENT + "SimounAgent((32, 32, 3), 1, cfg, device='cpu')", ("frame_shape", "(3, 32, 32)")),
    (AGENT + f"{A}.act(np.zeros((3, 3, 32, 32), np.float32))", ("uint8", "float32")),
    (AGENT + f"{A}.act(np.zeros((3, 32, 32, 3), np.uint8))", ("shape", "(3, 3, 32, 32)")),
    (AGENT + f"{A}.act(np.zeros((9, 32, 32), np.uint8))", ("shape", "(3, 3, 32, 32)")),
    (AGENT + f"import torch; {A}.act(torch.zeros((3, 3, 32, 32), dtype=torch.uint8))", ""),
    (AGENT + f"{A}.act({FRAMES}, deterministic=1)", "deterministic"),
    (AGENT + f"{A}.act({FRAMES}, step=-1)", "step"),
    (AGENT + FILLED + f"{A}.update(r, step=-1)", "step"),
    (AGENT + FILLED + f"{A}.update(r, step=2.5)", "step"),
    (AGENT + "import dataclasses; dataclasses.replace(cfg, lr=-1.0)", "lr"),
    (AGENT + "import dataclasses; dataclasses.replace(cfg, recipe='drq')", ("recipe", "resolve"),
     True),
    (AGENT + f"SimounAgent((3, 32, 32), 1, AgentConfig(lr='3e-4', {SMALL}), device='cpu')", "lr"),
    (AGENT + "AgentConfig(batch_size=8.0)", "batch_size"),
    (AGENT + "AgentConfig(lr=None)", "lr"),
    (AGENT + "AgentConfig(discount='0.99')", "discount"),
    (AGENT + f"{A}.to('gpu')", "gpu"),
    (AGENT + "AgentConfig(learning_rate=1e-3)", ("learning_rate", "lr")),
    (AGENT + f"a = {A}; a.load_state_dict(None)", "state"),
    (AGENT + f"a = {A}; a.load_state_dict(a)", ("state", "state_dict")),
    # configs written in Python
    (CONF + "resolve('cpu', {'agent.lr': '1e-3'})", ("agent.lr",), True),
    (CONF + "resolve('cpu', {'--agent.lr': 1e-3})", "agent.lr"),
    (CONF + "resolve('cpu', {'agent_lr': 1e-3})", "agent.lr"),
    (CONF + "resolve('cpu', {'agent.batch-size': 8})", "agent.batch_size"),
    (CONF + "c = resolve('cpu', {'agent.recipe': 'drq', 'agent.lr': 5e-4}); "
     "assert c.agent.lr == 5e-4, c.agent.lr", ""),
    (CONF + "resolve('cpu', {'total_env_steps': 1e5})", ("total_env_steps",), True),
    (CONF + "resolve('cpu', {'seed': True})", "seed"),
    (CONF + "resolve('cpu', {'agent.lr': None})", "agent.lr"),
    (CONF + "resolve('cpu', {'env': 'PendulumV1'})", "PendulumV1"),
    (CONF + "import torch; assert not torch.cuda.is_available(); "
     "resolve('cpu', {'device': 'cuda'})", "cuda"),
    (CONF + "resolve('cpu', {'eval_distraction': 'colour_easy'})", ("colour_easy", "color_easy")),
    (CONF + "resolve('cpu', {'env': 'Pendulum-v1', 'action_repeat': 0})", "action_repeat"),
    (CONF + "resolve('cpu', {'agent.lr': 1e-3}, seed=1)", "seed"),
    (CONF + "resolve('cpu', [('agent.lr', 1e-3)])", "overrides"),
    (CONF + "import json; from_dict(json.loads(json.dumps(to_dict(resolve('cpu', "
     "{'agent.recipe': 'curl'})))))", ""),
    (CONF + "import json; from_dict(json.loads(open('../tiny/config.json').read()))", ""),
    (CONF + "to_dict(AgentConfig())", ("TrainConfig", "AgentConfig")),
    (CONF + "from_dict(resolve('cpu', {}))", ("dict", "TrainConfig")),
    (CONF + "TrainConfig(device='gpu')", "device"),
    (CONF + "TrainConfig(seed=-1)", "seed"),
    (CONF + "TrainConfig(agent={'lr': 1e-3})", ("agent", "AgentConfig")),
    (CONF + "TrainConfig(env_kwargs='{\"size\": 32}')", "env_kwargs"),
    (CONF + "d = to_dict(resolve('cpu', {})); d['agent'] = []; from_dict(d)", "agent"),
    # Gymnasium's own wrappers around and under the wrappers
    (f"e = gym.wrappers.RecordVideo(w.SimounObservation({P}, size=16), 'videos', "
     f"episode_trigger=lambda i: True); {STEP}; e.close()", ("moviepy",), True),
    (NOV + f"e = w.RNDReward(gym.wrappers.NormalizeReward({S}), nov, warmup=0); " + STEP, ""),
    (f"w.ConstantBonusReward(gym.wrappers.DtypeObservation({S}, np.float32), 0.1)",
     ("DtypeObservation", "uint8")),
    (f"e = w.SimounObservation(gym.wrappers.ResizeObservation(gym.wrappers.AddRenderObservation("
     f"{C}), (32, 32)), size=None, source='observation'); {STEP}", ""),
    (f"w.SimounObservation({C}, size=16, source='observation')", ("source", "observation")),
    (f"e = w.SimounObservation({P}, size=(16, 24)); {STEP}; "
     "assert e.observation_space['frames'].shape[-2:] == (16, 24), e.observation_space", ""),
    (f"e = {S}; e.reset(0)", "seed"),
    ("e = w.SimounObservation(gym.make('Pendulum-v1', render_mode='rgb_array', "
     "max_episode_steps=3), size=16); e.reset(seed=0); "
     "assert [e.step(e.action_space.sample())[3] for _ in range(3)] == [False, False, True]; "
     "e.reset(); e.step(e.action_space.sample())", ""),
    (f"w.ActionRepeat(gym.wrappers.FrameStackObservation({P}, 3), 2).reset(seed=0)", ""),
    (f"w.ActionRepeat({PEND}, 2)", ("vector", "ActionRepeat")),
    (f"w.MultiCamera({P}, cameras=['top'], size=16)", ("cameras", "top")),
    # vector envs built by hand and Gymnasium's vector wrappers
    (f"v = w.ConstantBonusVectorReward(gym.vector.SyncVectorEnv([lambda: {S}, lambda: {S}]), "
     f"0.1); {STEPS3}", ""),
    (f"v = gym.wrappers.vector.ClipReward(w.ConstantBonusVectorReward({PEND}, 0.1), -1, 1); "
     + STEPS3, ""),
    (f"v = w.ConstantBonusVectorReward({PEND}, -0.1); " + STEPS3, ("scale",), True),
    (f"v = w.ConstantBonusVectorReward({PEND}, 0.1); v.reset(seed=-1)", "seed"),
    (f"w.ConstantBonusVectorReward(gym.vector.SyncVectorEnv([lambda: {S}, lambda: "
     f"w.SimounObservation({P}, size=24)]), 0.1)", ("shape", "16", "24")),
    # intrinsic rewards given lambdas, tensors, other models, other normalisations' arguments
    (f"e = w.RNDReward({S}, lambda t: np.zeros(len(t)), warmup=0); " + STEP, ""),
    (f"import torch; e = w.RNDReward({S}, lambda t: torch.zeros(len(t)), warmup=0); " + STEP,
     ("novelty", "tensor"), True),
    (f"w.RNDReward({S}, lambda: 0.0, warmup=0).reset(seed=0)", ("novelty", "argument")),
    (FEAT + f"w.ConsistencyCuriosityReward({S}, feat, decay=1.5)", "decay"),
    (FEAT + f"w.ConsistencyCuriosityReward({S}, feat, normalization='return_std', "
     "r_i_max_init=2.0)", ("r_i_max_init", "paper")),
    (NOV + f"w.RNDReward({S}, nov, normalization='paper', decay=-0.5)", "decay"),
    (RND + f"m = RNDModel.for_env({S64}); e = w.RNDReward({S}, m, warmup=0); " + STEP,
     ("64", "16", "shape")),
    (NOV + f"e = w.ConstantBonusReward({S}, 0.1); f = w.RNDReward({S}, nov); "
     "f.load_state_dict(e.state_dict())", "state"),
    (RNDC + f"RNDModel.for_env({S64}, config=RNDConfig(lr=0))", "lr"),
    (RNDC + f"RNDModel.for_env({S64}, config=RNDConfig(batch_size=8.0))", "batch_size"),
    (CUR + f"m = CuriosityModel.for_env({S64}, device='gpu')", ("gpu", "device")),
    # PettingZoo: render, state, no render mode, not a parallel env
    (PZ + "e = SPO(pz, size=16); e.reset(seed=0); assert e.render() is not None", ""),
    (PZ + "e = SPO(pz, size=16); e.reset(seed=0); e.state()", ("state",), True),
    ("import pettingzoo; " + SPO + "e = SPO(pettingzoo.make('parallel', "
     "'butterfly/pistonball-v6', n_pistons=3), size=16); e.reset(seed=0)", ""),
    (SPO + f"SPO({P}, size=16)", ("ParallelEnv", "SimounObservation")),
    (PZ + "e = SPO(pz, size=16); e.reset(seed=0); e.step({})", ("action", "piston_0")),
    (PZ + "e = SPO(pz, size=16); e.observation_space(0)", ("agent", "piston_0")),
    # replays of a kept run, PointReach through the wrappers
    (AGENT + LAST_REPLAY + "FrameReplay.load(last).sample(4)", ""),
    (AGENT + LAST_REPLAY + "FrameReplay(100, (3, 64, 64), 2).load(last)", ("64", "32", "shape")),
    (AGENT + LAST_REPLAY + "FrameReplay.load(last).sample(4, n_step=50)", ("n_step",)),
    (AGENT + FILLED + "r.save('r.npy')", ("npz", "r.npy"), True),
    (AGENT + FILLED + "r.save(3)", "path"),
    (AGENT + "FrameReplay.load('../tiny/checkpoint.pt')", ("checkpoint.pt", "npz", "replay")),
    (AGENT + "FrameReplay.load('../tiny')", ("../tiny", "directory")),
    ("import simoun_agent.envs; e = w.SimounObservation(gym.make('simoun/PointReach-v0', "
     "render_mode='rgb_array'), size=32); " + STEP, ""),
    ("import simoun_agent.envs; gym.make('simoun/PointReach-v0', size=32.0)", "size"),
    ("import simoun_agent.envs; gym.make('simoun/PointReach-v0', render_mode='human')",
     "render_mode"),
    ("import simoun_agent.envs; gym.make('simoun/PointReach-v0', max_steps=True)", "max_steps"),
    ("import simoun_agent.envs; gym.make('simoun/PointReach-v0', step_size=-0.2)", "step_size"),
    ("import simoun_agent.envs; e = gym.make('simoun/PointReach-v0'); e.reset(seed=0); "
     "e.step(np.array([5.0, 5.0]))", ("action",), True),
]  # fmt: skip

CASES: list[dict] = [
    api(code, names, ok=ok[0] if ok else not names) for code, names, *ok in EIGHTH_CODES
]
