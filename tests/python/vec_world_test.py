#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""turtlegas.VecWorld from Python, and the Gymnasium / PettingZoo adapters (turtlegas.gym) against
the API contract, with a stand-in for gymnasium (it is not installed here, and nothing is
downloaded): shapes and dtypes, the same seed the same observations on one thread or two, the
reward callable, sample_actions, truncation and the next-step autoreset, the parallel API's dicts,
and the plain error without gymnasium.

    vec_world_test.py --source SOURCE_DIR      (turtlegas importable: PYTHONPATH set by ctest)
"""
import argparse
import os
import sys
import tempfile
import textwrap
import unittest

import numpy as np

SOURCE = None
STAND_IN = textwrap.dedent('''
    # A stand-in for gymnasium: the spaces and the VectorEnv base class the adapters use, with the
    # signatures and contains() semantics of gymnasium 1.x.
    import numpy as np

    class _Space:
        pass

    class Box(_Space):
        def __init__(self, low, high, shape=None, dtype=np.float32):
            self.dtype = np.dtype(dtype)
            self.shape = tuple(shape) if shape is not None else np.shape(low)
            self.low = np.broadcast_to(np.asarray(low, dtype=self.dtype), self.shape)
            self.high = np.broadcast_to(np.asarray(high, dtype=self.dtype), self.shape)
        def contains(self, x):
            x = np.asarray(x)
            return x.shape == self.shape and np.can_cast(x.dtype, self.dtype) and bool(np.all(x >= self.low) and np.all(x <= self.high))

    class Discrete(_Space):
        def __init__(self, n):
            self.n = int(n); self.shape = (); self.dtype = np.dtype(np.int64)
        def contains(self, x):
            return 0 <= int(x) < self.n

    class MultiDiscrete(_Space):
        def __init__(self, nvec):
            self.nvec = np.asarray(nvec, dtype=np.int64); self.shape = self.nvec.shape; self.dtype = np.dtype(np.int64)
        def contains(self, x):
            x = np.asarray(x)
            return x.shape == self.shape and np.issubdtype(x.dtype, np.integer) and bool(np.all(x >= 0) and np.all(x < self.nvec))
''')
STAND_IN_VECTOR = textwrap.dedent('''
    class VectorEnv:
        metadata = {}
        def reset(self, *, seed=None, options=None):
            raise NotImplementedError
        def step(self, actions):
            raise NotImplementedError
''')


def swarm():
    return os.path.join(SOURCE, "worlds", "learn", "swarm16.json")


class VecWorldTest(unittest.TestCase):
    def test_shapes_dtypes_and_layout(self):
        import turtlegas
        v = turtlegas.VecWorld(swarm(), 5, seed=3, threads=2)
        self.assertEqual((v.num_envs, v.turtle_count, v.obs_size, v.threads), (5, 16, 16, 2))
        self.assertEqual(v.agents[:2], ["t0", "t1"])
        obs, info = v.reset()
        self.assertEqual(obs.shape, (5, 16, 16))
        self.assertEqual(obs.dtype, np.float32)
        self.assertEqual(info["steps"].tolist(), [0] * 5)
        lay = v.layout
        self.assertEqual(obs[:, :, lay["range"]].shape, (5, 16, 8))
        self.assertEqual(obs[:, :, lay["gps"]].shape, (5, 16, 0))
        a = v.sample_actions()
        self.assertEqual(a.shape, (5, 16, 2))
        self.assertTrue(np.all(np.abs(a) <= 1.0))
        obs, rew, term, trunc, info = v.step(a)
        self.assertEqual(rew.shape, (5, 16))
        self.assertEqual(rew.dtype, np.float32)
        self.assertEqual(term.shape, (5, 16))
        self.assertEqual(term.dtype, np.bool_)
        self.assertEqual(trunc.shape, (5, 16))
        self.assertEqual(info["t"].tolist(), [0.1] * 5)
        self.assertEqual(v.positions().shape, (5, 16, 2))
        with self.assertRaises(ValueError):
            v.step(np.zeros((5, 16)))
        with self.assertRaises(ValueError):
            turtlegas.VecWorld(swarm(), 2, actions="jump")

    def test_same_seed_same_observations_on_one_thread_or_two(self):
        import turtlegas
        runs = []
        for threads, seed in ((1, 7), (2, 7), (2, 8)):
            v = turtlegas.VecWorld(swarm(), 6, seed=seed, threads=threads)
            obs, _ = v.reset()
            seen = [obs]
            for _ in range(30):
                seen.append(v.step(v.sample_actions())[0])
            runs.append(np.stack(seen))
        self.assertTrue(np.array_equal(runs[0], runs[1]))
        self.assertFalse(np.array_equal(runs[0], runs[2]))

    def test_reward_callable_sees_the_step(self):
        import turtlegas
        calls = []

        def reward(vec, obs, actions):
            calls.append(actions.shape)
            # Distance driven this step, from the odometry.
            return obs[:, :, vec.layout["odometry"]][:, :, 0]

        v = turtlegas.VecWorld(swarm(), 3, seed=1, reward=reward, random_start=False)
        v.reset()
        ahead = np.zeros((3, 16, 2), dtype=np.float32)
        ahead[:, :, 0] = 1.0
        _, rew, _, _, _ = v.step(ahead)
        self.assertEqual(calls, [(3, 16, 2)])
        # Full ahead for half of 0.1 s at 100 units/s: 5 units, unless a wall or a turtle was nearer.
        self.assertAlmostEqual(float(rew.max()), 5.0, places=5)
        self.assertTrue(np.all(rew >= 0))
        bad = turtlegas.VecWorld(swarm(), 3, reward=lambda vec, obs, a: np.zeros(3))
        bad.reset()
        with self.assertRaises(ValueError):
            bad.step(ahead)

    def test_reward_expression_from_the_world_file(self):
        import json
        import turtlegas
        with open(swarm(), encoding="utf-8") as f:
            world = json.load(f)
        world["learn"] = {"reward": "distance / stroke - 2 * touch + 0 * (x + y + heading + t + steps + contacts)"}

        def by_hand(vec, obs, actions):
            lay = vec.layout
            moved = obs[:, :, lay["odometry"]][:, :, 0] / (100.0 * vec.dt * 0.5)
            return moved - 2.0 * obs[:, :, lay["touch"]].max(axis=2)

        a = turtlegas.VecWorld(world, 4, seed=2)
        b = turtlegas.VecWorld(world, 4, seed=2, reward=by_hand)
        a.reset(), b.reset()
        touched = 0
        for _ in range(40):
            actions = a.sample_actions()
            actions[:, :, 0] = np.abs(actions[:, :, 0])  # ahead: they meet walls and each other
            oa, ra, *_ = a.step(actions)
            ob, rb, *_ = b.step(actions)
            self.assertTrue(np.array_equal(oa, ob))
            self.assertTrue(np.allclose(ra, rb, rtol=0, atol=1e-6), (ra - rb).max())
            touched += int((oa[:, :, a.layout["touch"]].max(axis=2) > 0).sum())
        self.assertGreater(touched, 0)  # the touch term was exercised
        # A string given to reward= overrides the file's; "v" is the clamped action's linear part.
        c = turtlegas.VecWorld(world, 2, seed=2, reward="where(v > 0.5, 1, -1) + (omega if omega > 0 else 0)")
        c.reset()
        actions = np.zeros((2, 16, 2), dtype=np.float32)
        actions[0, :, 0], actions[1, :, 0], actions[:, :, 1] = 0.9, 7.0, -0.3  # 7 clamps to 1
        actions[0, 0, 1] = float("nan")  # NaN reads as 0
        _, r, *_ = c.step(actions)
        self.assertTrue(np.all(r == 1.0), r)
        w = turtlegas.VecWorld(world, 2, seed=2, actions="wheels", reward="omega - v")
        w.reset()
        actions[:] = 0
        actions[:, :, 0], actions[:, :, 1] = 1.0, 0.5  # left 1, right 0.5: v 0.75, omega 0.25
        self.assertTrue(np.allclose(w.step(actions)[1], -0.5))

    def test_reward_expression_errors(self):
        import turtlegas
        cases = {
            "distance - touhc": "unknown name 'touhc'",
            "distance +": "not an expression",
            "__import__('os')": "only the functions",
            "distance.real": "attribute is not part",
            "min(distance)": "min takes 2 argument",
            "'a'": "is not a number",
            "[distance]": "list is not part",
            "lambda: 1": "lambda is not part",
        }
        for text, says in cases.items():
            with self.assertRaises(ValueError) as e:
                turtlegas.VecWorld(swarm(), 1, reward=text)
            self.assertIn(says, str(e.exception), text)
            self.assertIn("reward=", str(e.exception))
        import json
        with open(swarm(), encoding="utf-8") as f:
            world = json.load(f)
        world["learn"] = {"reward": "distance / sqrt(-1 + touch)"}
        v = turtlegas.VecWorld(world, 2, seed=1)
        v.reset()
        with self.assertRaises(FloatingPointError) as e:
            v.step(v.sample_actions())
        self.assertIn("/learn/reward", str(e.exception))
        self.assertIn("copy 0, turtle 0", str(e.exception))
        with self.assertRaises(turtlegas.WorldError) as e:
            world["learn"] = {"reward": "touch", "penalty": 1}
            turtlegas.VecWorld(world, 1)
        self.assertIn("/learn", str(e.exception))

    def test_logo_actions(self):
        import turtlegas
        v = turtlegas.VecWorld(swarm(), 2, actions="logo", random_start=False)
        v.reset()
        a = v.sample_actions()
        self.assertEqual(a.shape, (2, 16))
        self.assertTrue(np.all((a >= 0) & (a < 5)))
        before = v.positions()
        fwd = np.ones((2, 16), dtype=np.int32)
        v.step(fwd)
        moved = np.linalg.norm(v.positions() - before, axis=2)
        self.assertAlmostEqual(float(moved.max()), 10.0, places=9)  # speed 100 x dt 0.1


class GymAdapterTest(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.TemporaryDirectory()
        pkg = os.path.join(self.dir.name, "gymnasium")
        os.makedirs(pkg)
        with open(os.path.join(pkg, "__init__.py"), "w") as f:
            f.write("from . import spaces, vector\n")
        with open(os.path.join(pkg, "spaces.py"), "w") as f:
            f.write(STAND_IN)
        with open(os.path.join(pkg, "vector.py"), "w") as f:
            f.write(STAND_IN_VECTOR)
        sys.path.insert(0, self.dir.name)
        for m in [m for m in sys.modules if m.startswith("gymnasium")]:
            del sys.modules[m]

    def tearDown(self):
        sys.path.remove(self.dir.name)
        for m in [m for m in sys.modules if m.startswith("gymnasium")]:
            del sys.modules[m]
        self.dir.cleanup()

    def test_vector_env_contract_and_next_step_autoreset(self):
        import gymnasium
        from turtlegas import gym as tg
        env = tg.make_vector_env(swarm(), 4, seed=2, max_steps=3, threads=2)
        self.assertIsInstance(env, gymnasium.vector.VectorEnv)
        self.assertEqual(env.num_envs, 4)
        self.assertEqual(env.single_observation_space.shape, (16, 16))
        self.assertEqual(env.observation_space.shape, (4, 16, 16))
        self.assertEqual(env.action_space.shape, (4, 16, 2))
        obs, info = env.reset(seed=5)
        self.assertTrue(env.observation_space.contains(obs))
        first = obs.copy()
        for k in range(3):
            a = env.vec.sample_actions()
            self.assertTrue(env.action_space.contains(a))
            obs, rew, term, trunc, info = env.step(a)
            self.assertEqual(rew.shape, (4,))
            self.assertEqual(term.shape, (4,))
            self.assertTrue(env.observation_space.contains(obs))
        self.assertTrue(trunc.all())   # max_steps = 3
        self.assertFalse(term.any())
        obs, rew, term, trunc, info = env.step(env.vec.sample_actions())
        # Next-step autoreset: each copy starts again, as reset(seed=5) started it.
        self.assertTrue(np.array_equal(obs, first))
        self.assertTrue(np.all(rew == 0))
        self.assertFalse(trunc.any() or term.any())
        self.assertEqual(info["steps"].tolist(), [0] * 4)

    def test_logo_vector_env_spaces(self):
        from turtlegas import gym as tg
        env = tg.make_vector_env(swarm(), 2, actions="logo")
        env.reset()
        a = env.vec.sample_actions()
        self.assertTrue(env.action_space.contains(a))
        self.assertEqual(env.single_action_space.nvec.tolist(), [5] * 16)

    def test_parallel_env_contract(self):
        from turtlegas import gym as tg
        env = tg.ParallelEnv(swarm(), seed=1, max_steps=2)
        self.assertEqual(env.agents, [])
        obs, infos = env.reset(seed=4)
        self.assertEqual(list(obs), env.possible_agents)
        self.assertEqual(set(infos), set(env.agents))
        for agent in env.agents:
            self.assertTrue(env.observation_space(agent).contains(obs[agent]))
        actions = {a: np.array([1.0, 0.0], dtype=np.float32) for a in env.agents}
        self.assertTrue(env.action_space("t0").contains(actions["t0"]))
        obs, rew, term, trunc, infos = env.step(actions)
        for d in (obs, rew, term, trunc, infos):
            self.assertEqual(set(d), set(env.possible_agents))
        self.assertIsInstance(rew["t0"], float)
        self.assertFalse(any(trunc.values()))
        obs, rew, term, trunc, infos = env.step(actions)
        self.assertTrue(all(trunc.values()))
        self.assertEqual(env.agents, [])


class WithoutGymnasiumTest(unittest.TestCase):
    def test_a_plain_error(self):
        import importlib.util
        if importlib.util.find_spec("gymnasium") is not None:
            self.skipTest("gymnasium is installed here")
        from turtlegas import gym as tg
        with self.assertRaises(ImportError) as e:
            tg.make_vector_env(swarm(), 2)
        self.assertIn("gymnasium", str(e.exception))
        self.assertIn("turtlegas.VecWorld works without it", str(e.exception))


if __name__ == "__main__":
    p = argparse.ArgumentParser()
    p.add_argument("--source", required=True)
    a, rest = p.parse_known_args()
    SOURCE = a.source
    unittest.main(argv=[sys.argv[0]] + rest, verbosity=2)
