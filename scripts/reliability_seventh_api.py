"""The seventh reliability trial's cases: api (see reliability_trial.py).

The Python API as a researcher uses it, on surfaces the earlier trials left alone: numpy scalars
given to the wrappers the sixth trial did not try, the normalisations by other names and as
instances a user shares or writes, specs of the other wrappers written to JSON and re-made,
Gymnasium's own wrappers (TimeLimit, ClipAction, RescaleAction, StickyAction, MaxAndSkip,
GrayscaleObservation, the env checker) around and under the wrappers, steps after an episode
ended without a reset, steps and renders after close, the vector wrappers' seeds, actions and
Gymnasium's vector wrappers, PettingZoo's AEC test over the parallel wrapper and AEC envs
converted, and the agent's Python API: state dicts through torch.save/torch.load, devices,
recipes by other spellings, configs made from dicts, the replay's values and files, and the
online models' configs, copies and closed threads.
"""

from reliability_trial import (
    AGENT,
    CUR,
    DMC,
    FEAT,
    FILLED,
    FRAME,
    FRAMES,
    NOV,
    PZ,
    RESOLVE,
    RND,
    RNDC,
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

NORM = "from simoun_wrappers.intrinsic_normalization import ReturnStd, Standardize, Raw; "
OWN_NORM = (
    "from simoun_wrappers.intrinsic_normalization import Normalization\n"
    "class Half(Normalization):\n"
    "    name = 'half'\n"
    "    def __call__(self, raw, extrinsic, envs, counted):\n"
    "        return {}\n"
    "    def state_dict(self):\n"
    "        return {{}}\n"
    "    def restore(self, state):\n"
    "        pass\n"
)
CAM = "lambda e: e.render()"
CART = vec("NEXT_STEP", "CartPole-v1")
CART_SAME = vec("SAME_STEP", "CartPole-v1")
PEND = vec("NEXT_STEP")
PEND_SAME = vec("SAME_STEP")
DISABLED = vec("DISABLED", "CartPole-v1")
# the vector envs inside a template that .format fills
PEND_T, CART_T = (v.replace("{", "{{").replace("}", "}}") for v in (PEND, CART))
SC = f"w.SimounObservation({C}, size=16)"
SPEC_JSON = "from gymnasium.envs.registration import EnvSpec; "
REMADE = "e = gym.make(EnvSpec.from_json({}.spec.to_json())); " + STEP
IMAGES = f"gym.wrappers.AddRenderObservation({C})"
# CartPole pushed right until it falls, then stepped again without a reset
ENDED = (
    "e.reset(seed=0); done = False\nwhile not done:\n    *_, t, u, _ = e.step(1); done = t or u\n"
    "e.step(1)"
)
CONFIG_DICT = (
    "from simoun_agent.config import from_dict, to_dict; d = to_dict(resolve('cpu', {})); "
)
AEC_PZ = (
    "import pettingzoo; from pettingzoo.utils.conversions import aec_to_parallel, parallel_to_aec; "
    "from simoun_wrappers.pettingzoo import SimounParallelObservation as SPO; "
)
MODEL = RND + f"m = RNDModel.for_env({S64}); "
TRIPLETS = "np.zeros((2, 3, 3, 64, 64), np.uint8)"
WATCH = (
    f"m.watch({TRIPLETS}, np.zeros((2, 1), np.float32), {TRIPLETS}, np.zeros(2, bool), "
    "np.zeros(2, bool))"
)

# (code with one {}, the name the refusal must give, the values)
SEVENTH_REFUSED = [
    (f"w.RandomConvolution({P}, kernel_size={{}})", "kernel_size", "3.0", "True"),
    (f"w.RandomConvolution({P}, source={{}})", "source", "'obs'", "None"),
    (f"w.ActionRepeat({P}, repeat={{}})", "repeat", "0", "'2'", "None"),
    (f"w.MultiCamera({P}, cameras={{}}, size=16)", "cameras", "[]", CAM, "'render'"),
    (PZ + "SPO(pz, size=16, grayscale={})", "grayscale", "1"),
    (PZ + "SPO(pz, size={})", "size", "0", "'16'", "16.0"),
    (PZ + "SPO(pz, size=16, num_frames={})", "num_frames", "2", "True", "np.int64(-3)"),
    (f"w.ConstantBonusVectorReward({PEND_T}, scale={{}})", "scale",
     "'0.1'", "None", "np.array([0.1, 0.2])"),
    (NOV + f"w.RNDVectorReward({CART_T}, nov, decay={{}})", "decay", "-1", "'1e-3'"),
    (FEAT + f"w.ConsistencyCuriosityVectorReward({CART_T}, feat, warmup={{}})", "warmup",
     "1.5", "-5"),
    (FEAT + f"w.ConsistencyCuriosityVectorReward({CART_T}, feat, progress={{}})", "progress",
     "2", "'0.5'"),
    (DMC + "w.MovingBackground(d, seed={})", "seed", "-1", "1.5", "'0'"),
    (DMC + "w.ColorShift(d, seed={})", "seed", "1.5", "True"),
    (AGENT + "FrameReplay({})", ("capacity", "frame_shape", "action_dim"),
     "-5, (3, 32, 32), 1", "1.5, (3, 32, 32), 1", "100, (32, 32), 1", "100, (3, 32, 32, 1), 1",
     "100, (3, 32, 32), 1.5"),
    (AGENT + FILLED + "r.sample({})", "batch_size", "4.0", "'4'"),
    (AGENT + f"{A}.act({FRAMES}, step={{}})", "step", "'3'", "1.5"),
    (RESOLVE + "resolve({}, {{}})", "preset", "'cartpole'", "'GPU'"),
    ("w.residual_motion({})", "frames",
     "np.zeros((3, 3, 8, 8), np.float32)", "[[1]]"),
    (PZ + "SPO(pz, size=16).reset(seed={})", "seed", "-1", "1.5"),
    (NOV + f"w.RNDReward({S}, nov, normalization={{}})", "normalization",
     "'standardise'", "'Return_Std'", "None"),
    (FEAT + NORM + f"w.ConsistencyCuriosityReward({S}, feat, normalization={{}})", "normalization",
     "'max'", "Raw"),
    (AGENT + "AgentConfig(recipe={})", "recipe", "'DrQ'", "'drq-v2'", "['drq']"),
    (AGENT + FILLED + "r.sample(4, {})", ("n_step", "discount"), "n_step=0", "discount=1.5",
     "n_step=2.5"),
    (AGENT + "SimounAgent({}, cfg, device='cpu')", ("frame_shape", "action"),
     "(32, 32, 3), 1", "(3, 32, 32), 0", "(3, 32), 1"),
]  # fmt: skip

# (code, the name the refusal must give, or "" for valid input[, valid: either])
SEVENTH_CODES = [
    # numpy scalars where Python numbers are expected, on the wrappers the sixth trial left
    (f"e = w.RandomConvolution({P}, kernel_size=np.int64(5)); " + STEP, ""),
    (f"e = w.FrameTriplet({P}, num_frames=np.int32(4)); " + STEP, ""),
    (f"e = w.MultiCamera({P}, cameras=[{CAM}], size=np.int32(16)); " + STEP, ""),
    (DMC + "e = w.MovingBackground(d, seed=np.uint16(2)); " + STEP, ""),
    (NOV + f"e = w.RNDReward({S}, nov, warmup=np.int64(0), scale=np.float32(0.5)); " + STEP, ""),
    (FEAT + f"e = w.ConsistencyCuriosityReward({S}, feat, progress=np.float64(0.5)); " + STEP, ""),
    (f"v = w.ConstantBonusVectorReward({PEND_SAME}, np.float64(0.1)); v.reset(seed=np.int64(3)); "
     "v.step(v.action_space.sample())", ""),
    (AGENT + FILLED + "r.sample(np.int64(4), n_step=np.int32(2), discount=np.float32(0.9))", ""),
    (AGENT + "r = FrameReplay(100, (3, 32, 32), 1); r.start_episode(" + FRAME + "); "
     f"r.add(np.zeros(1), np.float32(0.5), {FRAME}, np.bool_(False), np.bool_(True))", ""),
    (AGENT + f"{A}.act({FRAMES}, step=np.int64(3), deterministic=np.bool_(True))", ""),
    (RESOLVE + "resolve('cpu', {'agent.lr': np.float32(1e-3), 'agent.n_step': np.int64(3)})", ""),
    # the normalisations by other names, as instances shared, and a user's own
    (FEAT + f"e = w.ConsistencyCuriosityReward({S}, feat, normalization='raw'); " + STEP, ""),
    (NORM + NOV + f"e = w.RNDReward({S}, nov, warmup=0, normalization=Standardize()); " + STEP,
     ""),
    (NORM + NOV + f"n = ReturnStd(); e = w.RNDReward({S}, nov, warmup=0, normalization=n); "
     f"f = w.RNDReward({S}, nov, warmup=0, normalization=n); {STEP}",
     ("normalization", "shared", "instance"), True),
    ("from simoun_wrappers.intrinsic_normalization import Normalization\n"
     "class Mine(Normalization):\n    name = 'mine'\n" + NOV
     + f"w.RNDReward({S}, nov, normalization=Mine())", ("Mine", "__call__")),
    (OWN_NORM.format("list(raw)") + NOV
     + f"e = w.RNDReward({S}, nov, warmup=0, normalization=Half()); " + STEP, ("Half",), True),
    (OWN_NORM.format("raw.astype(np.float16)") + FEAT
     + f"e = w.ConsistencyCuriosityReward({S}, feat, normalization=Half()); " + STEP, ""),
    (FEAT + f"v = w.ConsistencyCuriosityVectorReward({CART}, feat, normalization='return_std'); "
     f"{STEPS3}; u = w.ConsistencyCuriosityVectorReward({CART}, feat); "
     "u.load_state_dict(v.state_dict())", ("return_std", "reward_std", "normalization")),
    (FEAT + "import json; " + f"e = w.ConsistencyCuriosityReward({S}, feat); {STEP}; "
     "e.load_state_dict(json.loads(json.dumps(e.state_dict())))", ""),
    (f"e = w.ConstantBonusReward({S}, 0.1); e.load_state_dict({{}})", "state"),
    (NOV + f"e = w.RNDReward({S}, nov, warmup=0); e.load_state_dict([1, 2])", "state"),
    # intrinsic wrappers stacked on each other
    (FEAT + NOV + f"e = w.RNDReward(w.ConsistencyCuriosityReward({S}, feat), nov, warmup=0); "
     + STEP, ("RNDReward", "ConsistencyCuriosityReward"), True),
    # the vector wrappers: both autoreset modes, seeds, actions, Gymnasium's vector wrappers
    (NOV + f"v = w.RNDVectorReward({CART_SAME}, nov, warmup=0, normalization='return_std'); "
     + STEPS3, ""),
    (FEAT + f"v = w.ConsistencyCuriosityVectorReward({CART}, feat, normalization='standardize'); "
     "v.reset(seed=0); [v.step(np.ones(2, np.int64)) for _ in range(30)]", ""),
    (NOV + f"w.RNDVectorReward({DISABLED}, nov)", ("autoreset", "DISABLED")),
    (f"v = w.ConstantBonusVectorReward({PEND}, 0.1); v.reset(seed=0); "
     "v.step([[0.1], [0.2]])", ("action",), True),
    (f"v = w.ConstantBonusVectorReward({PEND_SAME}, 0.1); v.step(v.action_space.sample())",
     "reset"),
    (f"v = w.ConstantBonusVectorReward({PEND}, 0.1); v.reset(seed=[np.int64(0), np.int64(1)]); "
     "v.step(v.action_space.sample())", ""),
    (f"v = w.ConstantBonusVectorReward(gym.wrappers.vector.NormalizeObservation({PEND}), 0.1)",
     ("NormalizeObservation", "uint8", "triplet")),
    (NOV + f"v = gym.wrappers.vector.RecordEpisodeStatistics(w.RNDVectorReward({CART}, nov, "
     "warmup=0)); " + STEPS3, ""),
    (NOV + f"v = w.RNDVectorReward({CART}, nov, warmup=0); v.reset(seed=0); v.close(); v.close(); "
     "v.step(v.action_space.sample())", "close"),
    (f"v = w.ConstantBonusVectorReward({CART}, 0.1); v.reset(seed=0); v.step(np.ones(2))",
     ("action", "int"), True),
    # Gymnasium's own wrappers around and under the wrappers
    (f"e = gym.wrappers.TimeLimit(w.ActionRepeat({P}, 2), 3); e.reset(seed=0); "
     "r = [e.step(e.action_space.sample())[3] for _ in range(3)]; "
     "assert r == [False, False, True], r", ""),
    (f"e = w.ActionRepeat(gym.wrappers.TimeLimit({P}, 3), 2); e.reset(seed=0); "
     "e.step(e.action_space.sample()); *_, t, u, _ = e.step(e.action_space.sample()); "
     "assert u", ""),
    (f"e = gym.wrappers.ClipAction(w.ActionRepeat({P}, 2)); e.reset(seed=0); "
     "e.step(np.array([5.0], np.float32))", ""),
    (f"e = w.SimounObservation(gym.wrappers.MaxAndSkipObservation({IMAGES}, skip=2), size=16); "
     + STEP, ""),
    (f"e = w.RandomConvolution(gym.wrappers.GrayscaleObservation({IMAGES}, keep_dim=False)); "
     + STEP, ("shape", "channel", "GrayscaleObservation"), True),
    (f"w.SimounObservation(w.FrameTriplet({IMAGES}), size=16)", ("FrameTriplet", "stack")),
    ("from gymnasium.utils.env_checker import check_env; "
     f"check_env(w.SimounObservation({P}, size=16), skip_render_check=True)", ""),
    # wrappers in the wrong order
    (f"e = w.ActionRepeat({S}, 2); " + STEP, ""),
    (DMC + "w.MovingBackground(w.SimounObservation(d, size=16))", ("SimounObservation", "order")),
    (DMC + "e = w.ColorShift(gym.wrappers.TimeLimit(d, 10), seed=0); " + STEP, ""),
    (f"w.ResidualMotion(w.FrameTriplet({P}))", ("ResidualMotion", "uint8")),
    ("w.residual_motion(np.zeros((3, 3, 8, 8), np.uint8))", ""),
    ("w.residual_motion(np.zeros((3, 8, 8), np.uint8))", ("frames", "shape")),
    # specs of the other wrappers written to JSON and re-made
    (SPEC_JSON + REMADE.format(f"w.RandomConvolution({P}, kernel_size=np.int64(5))"), ""),
    (SPEC_JSON + DMC + REMADE.format("w.ColorShift(d, seed=np.int64(1))"), ""),
    (SPEC_JSON + f"w.MultiCamera({P}, cameras=[{CAM}], size=16).spec.to_json()",
     ("cameras", "MultiCamera")),
    (SPEC_JSON + NOV + f"w.RNDReward({S}, nov).spec.to_json()", ("novelty", "RNDReward")),
    (f"e = gym.make(w.FrameTriplet({P}, num_frames=4).spec); {STEP}; "
     "assert e.observation_space.shape[0] == 4, e.observation_space", ""),
    # copies: pickled vector wrappers, agents, replays, models
    (f"v = pickle.loads(pickle.dumps(w.ConstantBonusVectorReward({PEND}, 0.1))); " + STEPS3,
     ("pickle",), True),
    (AGENT + f"pickle.loads(pickle.dumps({A})).act({FRAMES})", ""),
    (MODEL + "pickle.dumps(m)", ("pickle", "RNDModel"), True),
    # render, close, and steps after close or after an episode ended
    (f"e = w.MultiCamera({P}, cameras=[{CAM}], size=16); e.step(e.action_space.sample())",
     "reset"),
    (DMC + "e = w.MultiCamera(d, cameras=[0, 1], size=16); e.reset(seed=0); e.render()", ""),
    (DMC + "e = w.MovingBackground(d, seed=0); e.reset(seed=0); e.close(); e.render()", "close"),
    (f"e = w.ResidualMotion(w.FrameTriplet(gym.wrappers.TransformObservation({IMAGES}, "
     "lambda o: o.transpose(2, 0, 1)[:, :8, :8], gym.spaces.Box(0, 255, (3, 8, 8), np.uint8)))); "
     "e.reset(seed=0); e.close(); e.close()", ""),
    (MODEL + f"m.close(); {WATCH}", "close"),
    (f"e = w.ConstantBonusReward({SC}, 0.1); " + ENDED, "reset"),
    (f"e = w.ActionRepeat({C}, 2); " + ENDED, "reset"),
    (f"e = w.FrameTriplet({C}); " + ENDED, "reset"),
    (NOV + f"e = w.RNDReward({SC}, nov, warmup=0); " + ENDED, "reset"),
    # PettingZoo: AEC envs converted, the AEC test over the parallel wrapper, agents, actions
    (AEC_PZ + "e = SPO(aec_to_parallel(pettingzoo.make('aec', 'butterfly/pistonball-v6', "
     "n_pistons=3, render_mode='rgb_array')), size=16); e.reset(seed=0)", ""),
    (AEC_PZ + "import pettingzoo.test; pz = pettingzoo.make('parallel', 'butterfly/pistonball-v6', "
     "n_pistons=3, render_mode='rgb_array'); pettingzoo.test.api_test(parallel_to_aec("
     "SPO(pz, size=16)), num_cycles=3)", ""),
    (AEC_PZ + "pz = pettingzoo.make('parallel', 'butterfly/pistonball-v6', n_pistons=3, "
     "render_mode='rgb_array'); SPO(parallel_to_aec(pz), size=16)", ("AEC", "parallel")),
    (PZ + "e = SPO(pz, size=16); e.reset(seed=0); a = {x: e.action_space(x).sample() "
     "for x in e.agents}; a['piston_9'] = a['piston_0']; e.step(a)", "piston_9"),
    (PZ + "e = SPO(pz, size=16); e.reset(seed=0); e.step({x: np.float32(0.5) for x in e.agents})",
     ("action",), True),
    (PZ + "e = SPO(pz, size=16); e.reset(seed=0); e.step({x: 0.5 for x in e.agents})",
     ("action",), True),
    # the agent: state dicts, devices, configs from dicts, recipes
    (AGENT + f"import torch; a = {A}; torch.save(a.state_dict(), 'a.pt'); "
     "a.load_state_dict(torch.load('a.pt'))", ("weights_only",), True),
    (AGENT + "s = SimounAgent((3, 32, 32), 2, cfg, device='cpu').state_dict(); "
     f"{A}.load_state_dict(s)", ("action", "2")),
    (AGENT + f"a = {A}; s = a.state_dict(); s.pop(next(iter(s))); a.load_state_dict(s)", "state"),
    (AGENT + "import torch; assert not torch.cuda.is_available(); "
     f"{A}.to('cuda')", ("cuda", "device")),
    (AGENT + f"{A}.act(np.zeros((1, 3, 3, 32, 32), np.uint8))", ("shape", "obs", "(3, 3, 32, 32)"),
     True),
    (AGENT + FILLED + f"{A}.update(r, step=0)", ""),
    (AGENT + "r = FrameReplay(100, (3, 32, 32), 1); r.start_episode(" + FRAME + "); "
     f"[r.add(np.zeros(1), 0.0, {FRAME}, False, False) for _ in range(3)]; {A}.update(r, step=0)",
     ("batch", "replay", "transitions")),
    (RESOLVE + "resolve('cpu', {'agent.recipe': 'rad', 'agent.augmentation': 'shift'})",
     ("augmentation",), True),
    (RESOLVE + CONFIG_DICT + "d['agent']['lr_typo'] = 1; from_dict(d)", "lr_typo"),
    (RESOLVE + CONFIG_DICT + "del d['agent']['lr']; from_dict(d)", ("lr",), True),
    (RESOLVE + "resolve('dm_control/cheetah-run-v0', {})", ("preset", "cheetah-run")),
    # the replay's files
    (AGENT + FILLED + "r.save('r'); FrameReplay.load('r').sample(4)", ("r.npz",), True),
    (AGENT + FILLED + "r.save('no/such/dir/r.npz')", ("no/such/dir", "directory")),
    (AGENT + "r = FrameReplay(100, (3, 32, 32), 1); r.start_episode(" + FRAME + "); "
     f"r.add(0.5, 0.0, {FRAME}, False, False)", ("action",), True),
    # the online models' configs, copies and closed threads
    (RND + f"RNDModel.for_env({S64}, config={{'lr': 1e-4}})", ("config", "RNDConfig")),
    (CUR + RNDC + f"CuriosityModel.for_env({S64}, config=RNDConfig())",
     ("config", "CuriosityConfig")),
    (CUR + MODEL + f"c = CuriosityModel.for_env({S64}); m.load_state_dict(c.state_dict())",
     ("RNDModel", "CuriosityModel", "state")),
    (MODEL + "n = RNDModel.for_env(w.SimounObservation(" + M + ", size=64)); "
     "n.load_state_dict(m.state_dict())", ("action", "shape", "state")),
    (MODEL + "m.watch(np.zeros((2, 3, 3, 32, 32), np.uint8), np.zeros((2, 1), np.float32), "
     "np.zeros((2, 3, 3, 32, 32), np.uint8), np.zeros(2, bool), np.zeros(2, bool))",
     ("64", "32", "shape")),
]  # fmt: skip

CASES: list[dict] = [
    *(api(code.format(value), names) for code, names, *values in SEVENTH_REFUSED
      for value in values),
    *(api(code, names, ok=ok[0] if ok else not names) for code, names, *ok in SEVENTH_CODES),
]  # fmt: skip
