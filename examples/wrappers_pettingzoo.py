"""SimounParallelObservation on PettingZoo's pistonball: one triplet per agent.

python examples/wrappers_pettingzoo.py
"""

import pettingzoo

from simoun_wrappers.pettingzoo import SimounParallelObservation

env = pettingzoo.make("parallel", "butterfly/pistonball-v6", n_pistons=4, max_cycles=50)
env = SimounParallelObservation(env, size=64, grayscale=True)
obs, _ = env.reset(seed=0)
while env.agents:
    actions = {agent: env.action_space(agent).sample() for agent in env.agents}
    obs, rewards, terminations, truncations, _ = env.step(actions)
agent = env.possible_agents[0]
print(agent, env.observation_space(agent))
env.close()
