"""The sixth reliability trial's cases: api (see reliability_trial.py).

The Python API as a researcher uses it, on surfaces the earlier trials left alone: the
normalisations as objects (``ReturnStd``, ``PaperMaxima``, a user's own ``Normalization``),
feature and novelty sources that misbehave or were built for another env, models and agents
matched to the wrong wrapper, Gymnasium's own wrappers and vector classes around and under the
wrappers, specs written to JSON and re-made, PettingZoo's API test, numpy scalars
where Python numbers are expected (which must be accepted), bools and strings where numbers are,
configs changed after they were made, and the agent's and replay's files and copies.
"""

from reliability_trial import (
    ADD,
    AGENT,
    CUR,
    CURC,
    DMC,
    FEAT,
    FILLED,
    FRAME,
    FRAMES,
    M64,
    NOV,
    PZ,
    RESOLVE,
    RND,
    RNDC,
    S40,
    S64,
    STEP,
    STEPS3,
    TS,
    A,
    C,
    M,
    P,
    S,
    api,
    vec,
)

NORM = "from simoun_wrappers.intrinsic_normalization import PaperMaxima, ReturnStd; "
# a user's own normalization whose __call__ returns {}: (raw, extrinsic, envs, counted) in scope
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
AF = "from simoun_agent.curiosity_model import AgentFeatures; "
S32 = f"w.SimounObservation({P}, size=32)"
CART = vec("NEXT_STEP", "CartPole-v1")
CART_SAME = vec("SAME_STEP", "CartPole-v1")
SPEC_JSON = "from gymnasium.envs.registration import EnvSpec; "
CAM = "lambda e: e.render()"

# (code with one {}, the name the refusal must give, the values)
SIXTH_REFUSED = [
    (NORM + "ReturnStd(gamma={})", "gamma", "1.0", "False", "'0.99'", "float('nan')", "-0.1"),
    (NORM + "PaperMaxima({})", "r_e_max_init", "r_e_max_init=0", "r_e_max_init=float('inf')"),
    (NORM + "PaperMaxima({})", "r_i_max_init", "r_i_max_init='1'"),
    (NOV + NORM + f"w.RNDReward({S}, nov, normalization={{}})", "normalization",
     "ReturnStd", "'return-std'"),
    (f"w.FrameTriplet({P}, num_frames={{}})", "num_frames", "np.bool_(True)"),
    (f"w.ActionRepeat({P}, repeat={{}})", "repeat", "np.bool_(True)", "np.float32(2)"),
    (f"w.RandomConvolution({P}, kernel_size={{}})", "kernel_size", "np.int64(4)"),
    (f"w.SimounObservation({P}, size={{}})", "size", "np.float64(16)", "np.array(16.5)"),
    (f"w.MultiCamera({P}, cameras=[{CAM}], size={{}})", "size", "np.bool_(True)"),
    (f"w.ConstantBonusReward({S}, scale={{}})", "scale", "np.int64(-1)", "[0.1]"),
    (NOV + f"w.RNDReward({S}, nov, warmup={{}})", "warmup", "np.float64(10)", "'0'"),
    (FEAT + f"w.ConsistencyCuriosityReward({S}, feat, progress={{}})", "progress", "0", "1.5"),
    (CURC + "CuriosityConfig({})", "motion_contrastive_weight", "motion_contrastive_weight=-1"),
    (CURC + "CuriosityConfig({})", "update_every", "update_every=2.5"),
    (CURC + "CuriosityConfig({})", "encoder_size", "encoder_size=0"),
    (CURC + "CuriosityConfig({})", "seed", "seed=1.5"),
    (AGENT + f"{A}.act({FRAMES}, deterministic={{}})", "deterministic", "1"),
    (AGENT + "FrameReplay(100, (3, 32, 32), 1, seed={})", "seed", "True"),
    (RESOLVE + "resolve('cpu', {})", ("DrQ", "recipe"), "{'agent.recipe': 'DrQ'}"),
    (RESOLVE + "resolve('cpu', {})", ("agent-lr", "agent.lr"), "{'agent-lr': 1e-3}"),
]  # fmt: skip

# (code, the name the refusal must give, or "" for valid input[, valid: either])
SIXTH_CODES = [
    # the normalisations as objects, and a user's own
    (NORM + "ReturnStd(gamma=np.float32(0.99))", ""),
    (NORM + "PaperMaxima(r_i_max_init=np.float32(0.5))", ""),
    (FEAT + NORM + f"e = w.ConsistencyCuriosityReward({S}, feat, normalization=PaperMaxima()); "
     "assert e.decay == 2e-5, e.decay", ""),
    (FEAT + NORM + f"w.ConsistencyCuriosityReward({S}, feat, normalization=PaperMaxima(), "
     "r_e_max_init=5.0)", "r_e_max_init", True),
    (OWN_NORM.format("np.ones(len(raw) + 1)") + NOV
     + f"e = w.RNDReward({S}, nov, warmup=0, normalization=Half()); " + STEP,
     ("Half", "rows", "shape")),
    (OWN_NORM.format("np.full(len(raw), np.nan)") + NOV
     + f"e = w.RNDReward({S}, nov, warmup=0, normalization=Half()); " + STEP,
     ("Half", "NaN", "finite")),
    (NOV + f"e = w.RNDReward({S}, nov, warmup=0, normalization='return_std'); {STEP}; "
     f"f = w.RNDReward({S}, nov, warmup=0); f.load_state_dict(e.state_dict())",
     ("return_std", "reward_std")),
    (NOV + f"v = w.RNDVectorReward({CART}, nov, warmup=0, normalization='return_std'); "
     f"{STEPS3}; u = w.RNDVectorReward({vec('NEXT_STEP', 'CartPole-v1').replace(', 2,', ', 3,')}"
     ", nov, warmup=0, normalization='return_std'); u.load_state_dict(v.state_dict())",
     ("returns", "sub-env", "num_envs", "3")),
    # feature and novelty sources that misbehave, or were built for another env
    (f"e = w.ConsistencyCuriosityReward({S}, lambda t: (t, t, t)); " + STEP,
     ("feature", "f_m", "tuple")),
    ("def neg(t):\n    return -np.ones(len(t))\n"
     f"e = w.RNDReward({S}, neg, warmup=0); " + STEP, "novelty"),
    ("import torch\ndef feat(t):\n    return torch.zeros(len(t), 4), torch.zeros(len(t), 3, 4)\n"
     f"e = w.ConsistencyCuriosityReward({S}, feat); " + STEP, ""),
    (AGENT + AF + f"e = w.ConsistencyCuriosityReward({S32}, AgentFeatures({A})); " + STEP, ""),
    (AGENT + AF + f"e = w.ConsistencyCuriosityReward({S}, AgentFeatures({A})); " + STEP,
     ("32", "frame_shape", "shape")),
    (AGENT + AF + "import dataclasses; a = SimounAgent((3, 32, 32), 1, dataclasses.replace(cfg, "
     f"encoder='single'), device='cpu'); e = w.ConsistencyCuriosityReward({S32}, "
     "AgentFeatures(a)); " + STEP, ("dual", "encoder")),
    (AF + "AgentFeatures(None)", ("AgentFeatures", "encoder_features")),
    (RND + f"m = RNDModel.for_env({S64}); e = w.RNDReward({S}, m, warmup=0); " + STEP,
     ("64", "16", "shape")),
    (CUR + f"m = CuriosityModel.for_env({S64}); e = w.ConsistencyCuriosityReward("
     f"w.SimounObservation({P}, size=64, grayscale=True), m); " + STEP,
     ("channel", "shape", "(1,", "(3,")),
    (CUR + f"m = CuriosityModel.for_env({S64}); e = w.RNDReward({S64}, m, warmup=0); " + STEP,
     ("ConsistencyCuriosityReward", "novelty")),
    (RND + f"m = RNDModel.for_env({S64}); e = w.ConsistencyCuriosityReward({S64}, m); " + STEP,
     ("RNDReward", "FeatureSource", "features")),
    (RNDC + "RNDConfig(lr=np.float32(1e-4), batch_size=np.int64(32), seed=np.uint32(1), "
     "background=np.bool_(False))", ""),
    # the agent, its configs and recipes
    (AGENT + f"cfg.lr = -1; {A}", "lr"),
    (AGENT + "import dataclasses; dataclasses.replace(cfg, discount=1.5)", "discount"),
    (AGENT + "AgentConfig(batch_size=np.int64(16), lr=np.float32(1e-3), "
     "discount=np.float64(0.99))", ""),
    (AGENT + f"a = {A}; a.load_state_dict(a.state_dict(), strict=False)", "strict"),
    (AGENT + f"a = {A}; a.to('cpu')", ("device", "to(")),
    (AGENT + f"s = {A}.state_dict(); SimounAgent((3, 48, 48), 1, cfg, device='cpu')"
     ".load_state_dict(s)", ("frame_shape", "48", "shape")),
    (AGENT + "c = AgentConfig(recipe='drqv2'); SimounAgent((3, 32, 32), 1, c, device='cpu'); "
     "assert c.actor == 'deterministic', c.actor", ("recipe", "resolve"), True),
    (RESOLVE + "resolve('cpu', {'agent.batch_size': np.int64(32)})", ""),
    (RESOLVE + "resolve('cpu', {'agent.batch-size': 32})", ("batch_size", "batch-size"), True),
    (RESOLVE + "import json; from simoun_agent.config import from_dict, to_dict; "
     "c = resolve('cpu', {'agent.recipe': 'drq'}); "
     "assert from_dict(json.loads(json.dumps(to_dict(c)))) == c", ""),
    (RESOLVE + "from simoun_agent.config import from_dict, to_dict; d = to_dict(resolve('cpu', "
     "{})); d['agent']['lr'] = '1e-3'; from_dict(d)", "lr"),
    # the replay's files, copies and values
    (AGENT + FILLED + "import pathlib; r.save(pathlib.Path('r.npz')); "
     "FrameReplay.load(pathlib.Path('r.npz')).sample(4)", ""),
    (AGENT + FILLED + f"import torch; torch.save({A}.state_dict(), 'a.pt'); "
     "FrameReplay.load('a.pt')", "a.pt"),
    (AGENT + FILLED + "r.save('r.npz'); FrameReplay(100, (3, 32, 32), 2).load('r.npz')",
     "action"),
    (AGENT + FILLED + "r.save('r.npz'); FrameReplay(100, (3, 32, 32), 1, num_frames=2)"
     ".load('r.npz')", "num_frames"),
    (AGENT + ADD.format(f"np.zeros(1), 0.0, {FRAME}, True, True"),
     ("terminated", "truncated"), True),
    (AGENT + "r = FrameReplay(100, (3, 32, 32), 1); r.start_episode(np.zeros((32, 32, 3), "
     "np.uint8))", ("(3, 32, 32)", "frame")),
    (AGENT + ADD.format(f"np.array([2.0]), 0.0, {FRAME}, False, False"),
     ("action", "[-1, 1]"), True),
    # observations through Gymnasium's own wrappers
    (f"e = w.SimounObservation(gym.wrappers.AddRenderObservation({C}, render_only=False), "
     "size=16); " + STEP, ""),
    (f"w.SimounObservation(gym.wrappers.RenderCollection({P}), size=16).reset(seed=0)",
     ("render", "RenderCollection", "list")),
    (f"w.ConstantBonusReward(gym.wrappers.NormalizeObservation({S40}), 0.1)",
     ("uint8", "NormalizeObservation", "triplet")),
    (f"w.ConstantBonusReward(gym.wrappers.FlattenObservation({S}), 0.1)",
     ("triplet", "FlattenObservation", "frames")),
    (f"e = w.ConstantBonusReward(gym.wrappers.FilterObservation({S}, ['frames']), 0.1); "
     + STEP, ""),
    (f"e = gym.wrappers.Autoreset(w.ConstantBonusReward({S}, 0.1)); e.reset(seed=0); "
     "[e.step(e.action_space.sample()) for _ in range(205)]", ""),
    # the vector forms' arguments
    (FEAT + f"w.ConsistencyCuriosityVectorReward({CART}, feat, scale=-0.2)", "scale"),
    (FEAT + f"w.ConsistencyCuriosityVectorReward({CART}, feat, r_i_max_init=float('inf'))",
     "r_i_max_init"),
    (NOV + f"w.RNDVectorReward({CART_SAME}, nov, warmup=-1)", "warmup"),
    (f"w.ConstantBonusVectorReward({vec('SAME_STEP')}, scale=float('nan'))", "scale"),
    # vector envs: Gymnasium's classes and wrappers, seeds and actions
    (f"v = gym.vector.AsyncVectorEnv([lambda: {S}] * 2, shared_memory=True); "
     "v = w.ConstantBonusVectorReward(v, 0.1); " + STEPS3 + "; v.close()", ""),
    (NOV + f"v = w.RNDVectorReward({CART}, nov, warmup=0); v.reset(seed=[0, 1, 2])", "seed"),
    (f"v = w.ConstantBonusVectorReward({vec('NEXT_STEP')}, 0.1); v.reset(seed=[0, None]); "
     "v.step(v.action_space.sample())", ""),
    (FEAT + f"v = w.ConsistencyCuriosityVectorReward({CART_SAME}, feat); v.reset(seed=0); "
     "v.step(np.zeros(1, np.int64))", ("action", "2")),
    # specs written to JSON and re-made
    (SPEC_JSON + f"e = gym.make(EnvSpec.from_json(w.ConstantBonusReward({S}, 0.1).spec"
     ".to_json())); " + STEP, ""),
    (SPEC_JSON + f"e = gym.make(EnvSpec.from_json(w.ConstantBonusReward({S}, "
     "np.float32(0.1)).spec.to_json())); " + STEP, ""),
    # PettingZoo: conversions, the API test, agents and seeds
    (PZ + "import pettingzoo.test; pettingzoo.test.parallel_api_test(SPO(pz, size=16), "
     "num_cycles=3)", ""),
    (PZ + "SPO(pz, size=16).observation_space('nope')", "nope"),
    (PZ + "e = SPO(pz, size=None, source='render'); e.observation_space('piston_0')", "reset"),
    (PZ + "e = SPO(pz, size=16); e.reset(seed=0); "
     "e.step({'piston_0': e.action_space('piston_0').sample()})", ("piston_1", "action")),
    (PZ + "e = SPO(pz, size=np.int64(16), num_frames=np.int32(3), grayscale=np.bool_(True)); "
     "e.reset(seed=np.int64(0))", ""),
    (PZ + "SPO(pz, size=16).reset(seed=True)", "seed"),
    # wrappers given numpy scalars, edge values and odd cameras
    (f"e = w.ActionRepeat({P}, np.uint8(2)); " + STEP, ""),
    (f"e = w.ConstantBonusReward({S}, np.float32(0.1), decay=np.float16(1e-3)); " + STEP, ""),
    (f"e = w.ConstantBonusReward({S}, scale=0); " + STEP, ""),
    (DMC + "w.MultiCamera(d, cameras=[0, 'nope'], size=16).reset(seed=0)", "nope"),
    (DMC + "w.MultiCamera(d, cameras=[7], size=16).reset(seed=0)", ("7", "camera")),
    (DMC + "w.MultiCamera(d, cameras=[0.0], size=16)", "camera"),
    (DMC + "e = w.MultiCamera(d, cameras=[np.int64(0), 1], size=16); " + STEP, ""),
    (DMC + "import pathlib; w.MovingBackground(d, videos=pathlib.Path('nowhere'))", "nowhere"),
    (f"w.check_sb3_policy({S40}, 'CnnPolicy ')", "CnnPolicy"),
    # steps and resets given odd actions and seeds
    (f"e = w.ActionRepeat({M}, 2); e.reset(seed=0); e.step(7)", "action"),
    (f"e = w.SimounObservation({P}, size=16); e.reset(seed=0); e.step(np.float64(0.5))",
     "action", True),
    (f"e = w.ConstantBonusReward({TS}, 0.1); e.reset(seed=0); e.step(2.5)", "action"),
    (f"w.ActionRepeat({P}, 2).reset(seed=True)", "seed"),
    (f"w.MultiCamera({P}, cameras=[{CAM}], size=16).reset(seed=float('nan'))", "seed"),
    # misspelt or missing keywords, bools and None where values are expected
    (NOV + f"w.RNDReward({S}, nov, normalisation='none')", "normalisation"),
    (f"w.SimounObservation({P}, frame_size=16)", "frame_size"),
    (f"w.ActionRepeat({P}, action_repeat=2)", "action_repeat"),
    (f"w.ConstantBonusReward({S})", "scale"),
    (f"w.ConstantBonusReward({S}, 0.1, normalization='standardize')", "normalization", True),
    (FEAT + f"w.ConsistencyCuriosityReward({S}, feat, warmup=True)", "warmup"),
    (NOV + f"w.RNDReward({S}, nov, decay=True)", "decay"),
    (f"w.ConstantBonusReward({S}, 0.1, decay=np.bool_(False))", "decay"),
    ("w.ActionRepeat('Pendulum-v1', 2)", ("env", "gymnasium.Env")),
    ("w.FrameTriplet(None)", ("env", "gymnasium.Env")),
    (f"w.MultiCamera(gym.spec('Pendulum-v1'), cameras=[{CAM}])", ("env", "EnvSpec", "gym.make")),
    (f"e = w.ActionRepeat({P}, 2); e.reset(seed=0); e.step(None)", "action"),
    (f"e = w.FrameTriplet({P}); e.reset(seed=0); e.step(np.zeros(3, np.float32))", "action"),
    (NOV + f"v = w.RNDVectorReward({CART}, nov, warmup=0); v.reset(seed=0); "
     "v.step(np.array([0.5, 0.5]))", "action"),
    (PZ + "SPO(pz, size=(16,))", "size"),
    (DMC + "w.MovingBackground(d, level='hard', videos='')", "videos"),
    (CUR + f"CuriosityModel.for_env({S64}, device='cuda:3')", ("cuda", "device")),
    (CUR + "CuriosityModel.for_env(gym.make('CartPole-v1'))", ("SimounObservation", "triplet")),
    (AGENT + f"{A}.act({FRAMES}, step=np.float64(3))", "step"),
    (RESOLVE + "from simoun_agent.config import from_dict, to_dict; d = to_dict(resolve('cpu', "
     "{})); d['agent']['recipe'] = 'drqq'; from_dict(d)", "drqq"),
    # copies of a wrapper whose model trains in a thread
    (CUR + f"m = CuriosityModel.for_env({M64}); e = w.ConsistencyCuriosityReward({M64}, m); "
     f"{STEP}; c = pickle.loads(pickle.dumps(e)); c.reset(seed=1); "
     "c.step(c.action_space.sample())",
     ("pickle", "CuriosityModel", "thread"), True),
]  # fmt: skip

CASES: list[dict] = [
    *(api(code.format(value), names) for code, names, *values in SIXTH_REFUSED
      for value in values),
    *(api(code, names, ok=ok[0] if ok else not names) for code, names, *ok in SIXTH_CODES),
]  # fmt: skip
