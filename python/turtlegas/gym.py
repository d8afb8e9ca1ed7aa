# SPDX-License-Identifier: MIT
"""Gymnasium and PettingZoo adapters over turtlegas.VecWorld.

Neither library is a Debian package, and turtlegas needs neither: this module imports gymnasium
only when an adapter is made, and says so plainly when it is missing. With gymnasium importable:

* ``make_vector_env(world, n, seed=0, **kw)``: a ``gymnasium.vector.VectorEnv`` whose one
  environment is a whole world, all its turtles acting together: observation (turtles, obs_size),
  action (turtles, 2) (velocity, wheels) or turtles integers (logo); the reward of a copy is the
  mean of its turtles' rewards. Copies that end are reset on the next step (Gymnasium's
  "next-step" autoreset: that step returns the reset observation, reward 0, not done).
* ``ParallelEnv(world, seed=0, **kw)``: the PettingZoo parallel API for one world, a dict per
  turtle id (``reset`` -> (obs, infos), ``step(actions)`` -> (obs, rewards, terminations,
  truncations, infos)); its spaces are gymnasium's. PettingZoo itself is not imported.

The keyword arguments are VecWorld's (threads, actions, reward, random_start, max_steps, mode).
"""
import numpy as np

from .vec import VecWorld, LOGO_ACTIONS


def _gymnasium():
    try:
        import gymnasium
        import gymnasium.spaces  # noqa: F401
        import gymnasium.vector  # noqa: F401
    except ImportError as e:  # pragma: no cover - the message is the point
        raise ImportError("turtlegas.gym needs gymnasium, which is not installed here (it is not a Debian package: "
                          "pip install gymnasium); turtlegas.VecWorld works without it") from e
    return gymnasium


def _spaces(gym, vec):
    t, d = vec.turtle_count, vec.obs_size
    obs = gym.spaces.Box(low=-np.inf, high=np.inf, shape=(t, d), dtype=np.float32)
    if vec.actions == "logo":
        act = gym.spaces.MultiDiscrete([len(LOGO_ACTIONS)] * t)
    else:
        act = gym.spaces.Box(low=-1.0, high=1.0, shape=(t, 2), dtype=np.float32)
    return obs, act


def _batch(gym, space, n):
    if isinstance(space, gym.spaces.MultiDiscrete):
        return gym.spaces.MultiDiscrete(np.tile(space.nvec, (n, 1)))
    return gym.spaces.Box(low=np.broadcast_to(space.low, (n,) + space.shape), high=np.broadcast_to(space.high, (n,) + space.shape),
                          dtype=space.dtype)


def make_vector_env(world, n, seed=0, **kw):
    """A gymnasium.vector.VectorEnv over n copies of world (see the module's text)."""
    gym = _gymnasium()

    class TurtleVectorEnv(gym.vector.VectorEnv):
        metadata = {"autoreset_mode": "NextStep", "render_modes": []}

        def __init__(self):
            self.vec = VecWorld(world, n, seed, **kw)
            self.num_envs = self.vec.num_envs
            self.single_observation_space, self.single_action_space = _spaces(gym, self.vec)
            self.observation_space = _batch(gym, self.single_observation_space, self.num_envs)
            self.action_space = _batch(gym, self.single_action_space, self.num_envs)
            self._seed = seed
            self._done = np.zeros(self.num_envs, dtype=bool)

        def reset(self, *, seed=None, options=None):
            if seed is not None:
                self._seed = seed
            obs, info = self.vec.reset(self._seed)
            self._done[:] = False
            return obs, info

        def step(self, actions):
            done_before = self._done.copy()
            obs, reward, term, trunc, info = self.vec.step(actions)
            term, trunc = term[:, 0].copy(), trunc[:, 0].copy()
            rew = reward.mean(axis=1)
            for i in np.flatnonzero(done_before):
                # Next-step autoreset: the copy done at the last step starts again now.
                obs = self.vec.reset_one(i)
                rew[i] = 0.0
                term[i] = trunc[i] = False
            if done_before.any():
                info = self.vec._info()
            self._done = term | trunc
            return obs, rew, term, trunc, info

        def close(self):
            pass

    return TurtleVectorEnv()


class ParallelEnv:
    """The PettingZoo parallel API over one world (see the module's text)."""

    metadata = {"name": "turtlegas_parallel_v0", "render_modes": [], "is_parallelizable": True}

    def __init__(self, world, seed=0, **kw):
        gym = _gymnasium()
        self.vec = VecWorld(world, 1, seed, **kw)
        self.possible_agents = self.vec.agents
        self.agents = []
        self._obs_space, self._act_space = _spaces(gym, self.vec)
        # One turtle's spaces: a row of the world's.
        t = self.vec.turtle_count
        self._one_obs = gym.spaces.Box(low=-np.inf, high=np.inf, shape=(self.vec.obs_size,), dtype=np.float32)
        self._one_act = (gym.spaces.Discrete(len(LOGO_ACTIONS)) if self.vec.actions == "logo"
                         else gym.spaces.Box(low=-1.0, high=1.0, shape=(2,), dtype=np.float32))
        self._index = {a: k for k, a in enumerate(self.possible_agents)}
        self._t = t
        self._seed = seed

    def observation_space(self, agent):
        return self._one_obs

    def action_space(self, agent):
        return self._one_act

    def _split(self, rows):
        return {a: rows[k] for a, k in self._index.items() if a in self.agents}

    def reset(self, seed=None, options=None):
        if seed is not None:
            self._seed = seed
        obs, info = self.vec.reset(self._seed)
        self.agents = list(self.possible_agents)
        return self._split(obs[0]), {a: {} for a in self.agents}

    def step(self, actions):
        if self.vec.actions == "logo":
            a = np.zeros((1, self._t), dtype=np.int32)
        else:
            a = np.zeros((1, self._t, 2), dtype=np.float32)
        for agent, act in actions.items():
            a[0, self._index[agent]] = act
        obs, reward, term, trunc, info = self.vec.step(a)
        out = (self._split(obs[0]), {k: float(v) for k, v in self._split(reward[0]).items()},
               {k: bool(v) for k, v in self._split(term[0]).items()}, {k: bool(v) for k, v in self._split(trunc[0]).items()},
               {a: {"contacts": int(info["contacts"][0])} for a in self.agents})
        if term[0, 0] or trunc[0, 0]:
            self.agents = []
        return out

    def close(self):
        pass
