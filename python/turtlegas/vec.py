# SPDX-License-Identifier: MIT
"""Vectorised worlds for learning: ``turtlegas.VecWorld(world, n, seed)``.

n independent copies of one world, stepped together by a pool of C++ threads (one per core unless
``threads`` says otherwise; the GIL is released while they step). Every turtle is driven by an
action per control step instead of its program; observations, rewards, ``terminated`` and
``truncated`` come back as numpy arrays in the shapes of the PettingZoo parallel API, one column
per turtle, one row per copy (docs/python.md, "Vectorised worlds")::

    vec = turtlegas.VecWorld("worlds/learn/swarm16.json", n=64, seed=1)
    obs, info = vec.reset(seed=1)                 # obs: (64, 16, obs_size) float32
    obs, reward, terminated, truncated, info = vec.step(vec.sample_actions())
"""
import json
import os

import numpy as np

from . import _turtlegas as _core
from .reward import RewardExpression

ACTION_KINDS = ("velocity", "wheels", "logo")
LOGO_ACTIONS = ("wait", "forward", "back", "left", "right")


class VecWorld:
    """n copies of a world, stepped together.

    world: a world file's path, or the world as a dict (the JSON a world file holds).
    n: the number of copies. seed: the first reset's seed (reset(seed) draws again).
    threads: C++ threads that step the copies (0: one per core).
    actions: "velocity" ((v, omega) per turtle, each in [-1, 1]: fractions of half the turtle's
        speed and turn rate; a turn then a stroke each control step), "wheels" ((left, right) in
        [-1, 1], the differential drive v = (l + r) / 2, omega = (l - r) / 2) or "logo" (one integer
        per turtle: 0 wait, 1 forward, 2 back, 3 left, 4 right, for a whole control step).
    reward: a callable reward(vec, obs, actions) -> array (n, turtles), called after each step
        (vec.positions() and the rest give it the ground truth); or an expression as a string
        ("distance / stroke - touch": turtlegas.reward.NAMES lists the figures); None: the world
        file's {"learn": {"reward": ...}} when it has one, else rewards are 0.
    random_start: each reset scatters the turtles at random free poses (False: the file's poses).
    max_steps: control steps after which a copy is truncated (0: never).
    mode: "exact" or "step", the engine's mode.
    """

    def __init__(self, world, n, seed=0, *, threads=0, actions="velocity", reward=None, random_start=True,
                 max_steps=0, mode="exact"):
        if isinstance(world, dict):
            text, name = json.dumps(world), str(world.get("name", "<dict>")) + ".json"
        else:
            path = os.fspath(world)
            with open(path, encoding="utf-8") as f:
                text = f.read()
            name = path
        if actions not in ACTION_KINDS:
            raise ValueError(f"actions must be one of {ACTION_KINDS}, not {actions!r}")
        if reward is None:
            learn = json.loads(text).get("learn") if text.lstrip().startswith("{") else None
            if isinstance(learn, dict) and "reward" in learn:
                reward = RewardExpression(learn["reward"], f"{name}: /learn/reward")
        elif isinstance(reward, str):
            reward = RewardExpression(reward, "reward=")
        elif not callable(reward):
            raise TypeError("reward must be a callable reward(vec, obs, actions) -> (n, turtles) array, "
                            "an expression (a string), or None")
        self._vec = _core._VecWorld(text, name, int(n), threads=int(threads), actions=actions,
                                    random_start=bool(random_start), max_steps=int(max_steps), mode=mode)
        self.actions = actions
        self.reward_fn = reward
        self.seed = int(seed)
        self._obs = None

    # Sizes and layout.
    @property
    def num_envs(self):
        """The number of copies, n."""
        return self._vec.size

    @property
    def n(self):
        return self._vec.size

    @property
    def turtle_count(self):
        return self._vec.turtle_count

    @property
    def agents(self):
        """The turtles' ids, in world-file order: the columns of every array."""
        return list(self._vec.turtle_ids)

    @property
    def threads(self):
        return self._vec.thread_count

    @property
    def dt(self):
        """The control step, seconds."""
        return self._vec.dt

    @property
    def obs_size(self):
        return self._vec.obs_size

    @property
    def layout(self):
        """Slices of an observation row: touch, range, odometry, heading, gps (empty when no turtle has gps)."""
        return self._vec.layout

    @property
    def observation_shape(self):
        return (self._vec.size, self._vec.turtle_count, self._vec.obs_size)

    @property
    def action_shape(self):
        t = (self._vec.size, self._vec.turtle_count)
        return t if self.actions == "logo" else t + (2,)

    # Running.
    def reset(self, seed=None):
        """Rebuilds every copy (copy i's start from seed and i alone): (obs, info)."""
        if seed is not None:
            self.seed = int(seed)
        self._obs = self._vec.reset(self.seed)
        return self._obs, self._info()

    def reset_one(self, i, seed=None):
        """Rebuilds copy i alone, as reset(seed) does for it; returns the observations of all copies."""
        if self._obs is None:
            raise RuntimeError("reset() first")
        self._vec.reset_one(int(i), self.seed if seed is None else int(seed), self._obs)
        return self._obs

    def step(self, actions):
        """One control step of every copy not done: (obs, reward, terminated, truncated, info).

        obs (n, turtles, obs_size) float32; reward (n, turtles) float32; terminated and truncated
        (n, turtles) bool (a copy's flags for each of its turtles: a turtle left the world, or
        max_steps was reached); info: dict of arrays, one row per copy.
        """
        if self._obs is None:
            raise RuntimeError("reset() first")
        a = np.asarray(actions, dtype=np.int32 if self.actions == "logo" else np.float32)
        if a.shape != self.action_shape:
            raise ValueError(f"actions of shape {a.shape}; this VecWorld takes {self.action_shape}")
        obs, term, trunc = self._vec.step(a)
        self._obs = obs
        t = self._vec.turtle_count
        terminated = np.repeat(term[:, None], t, axis=1)
        truncated = np.repeat(trunc[:, None], t, axis=1)
        if self.reward_fn is None:
            reward = np.zeros((self._vec.size, t), dtype=np.float32)
        elif isinstance(self.reward_fn, RewardExpression):
            reward = self._expression_reward(obs, a)
        else:
            reward = np.asarray(self.reward_fn(self, obs, a), dtype=np.float32)
            if reward.shape != (self._vec.size, t):
                raise ValueError(f"the reward callable returned shape {reward.shape}; it must be (n, turtles) = {(self._vec.size, t)}")
        return obs, reward, terminated, truncated, self._info()

    def sample_actions(self):
        """Random valid actions, uniform, from each copy's own seeded stream."""
        return self._vec.sample_actions()

    # Ground truth, for rewards and analysis (not observations unless the world grants gps).
    def positions(self):
        """(n, turtles, 2) world units; NaN for a turtle gone."""
        return self._vec.positions()

    def headings(self):
        """(n, turtles) degrees, Logo convention (0 is +y, clockwise)."""
        return self._vec.headings()

    def _expression_reward(self, obs, a):
        """The world file's (or reward=) expression over this step's figures, (n, turtles) float32."""
        expr, lay, shape = self.reward_fn, self.layout, (self._vec.size, self._vec.turtle_count)
        figures = {}
        for name in expr.names:
            if name in ("distance", "turned"):
                figures[name] = obs[:, :, lay["odometry"].start + int(name == "turned")].astype(np.float64)
            elif name in ("touch", "touches"):
                arcs = obs[:, :, lay["touch"]].astype(np.float64)
                if arcs.shape[2] == 0:
                    figures[name] = np.zeros(shape)
                else:
                    figures[name] = arcs.max(axis=2) if name == "touch" else arcs.sum(axis=2)
            elif name in ("near", "range_min"):
                rays = obs[:, :, lay["range"]].astype(np.float64)
                shortest = rays.min(axis=2) if rays.shape[2] else np.ones(shape)
                figures[name] = 1.0 - shortest if name == "near" else shortest
            elif name in ("v", "omega"):
                figures[name] = self._action_parts(a)[int(name == "omega")]
            elif name in ("speed", "stroke"):
                speed = np.asarray(self._vec.turtle_speeds, dtype=np.float64)[None, :]
                figures[name] = speed if name == "speed" else speed * self.dt * (1.0 if self.actions == "logo" else 0.5)
            elif name in ("x", "y"):
                figures[name] = self.positions()[:, :, int(name == "y")].astype(np.float64)
            elif name == "heading":
                figures[name] = self.headings().astype(np.float64)
            else:  # contacts, t, steps: one per copy
                figures[name] = np.asarray(self._info()[name], dtype=np.float64)[:, None]
        alive = ~np.isnan(self.positions()[:, :, 0])
        return expr.evaluate(figures, shape, alive)

    def _action_parts(self, a):
        """(v, omega) of the actions as the turtles took them: clamped to [-1, 1], NaN as 0."""
        if self.actions == "logo":
            v = np.where(a == 1, 1.0, np.where(a == 2, -1.0, 0.0))
            omega = np.where(a == 4, 1.0, np.where(a == 3, -1.0, 0.0))
            return v, omega
        x = np.clip(np.nan_to_num(a[:, :, 0].astype(np.float64), nan=0.0), -1.0, 1.0)
        y = np.clip(np.nan_to_num(a[:, :, 1].astype(np.float64), nan=0.0), -1.0, 1.0)
        if self.actions == "wheels":
            return 0.5 * (x + y), 0.5 * (x - y)
        return x, y

    def _info(self):
        return {"contacts": self._vec.contacts(), "steps": self._vec.steps(), "t": self._vec.times()}
