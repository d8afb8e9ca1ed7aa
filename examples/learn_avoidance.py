#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Learn obstacle avoidance for a swarm with the cross-entropy method, in numpy.

Eight turtles among pillars (worlds/learn/avoidance.json), each with an 8-ray ring of range 60,
share one linear policy: (v, omega) = tanh(W [1 - ring readings, 1]), 18 numbers. A turtle earns
its forward stroke each control step (1 for a full stroke ahead) and loses 1 for each step in
which a touch sensor fires. Each generation draws a population of W from a Gaussian, runs every
candidate on its own copies of the world (all copies stepped together by turtlegas.VecWorld on C++
threads), and refits the Gaussian to the best fifth. The policy that drives straight on runs into
a wall within seconds and stays there; the learned one turns away from what its ring sees.

    python3 examples/learn_avoidance.py [--generations 20] [--population 32] [--plot docs/images/learning_curve.png]

Prints one line a generation: the mean policy's score on fresh starts, the population's mean and
best. docs/python.md, "Vectorised worlds", shows the curve.
"""
import argparse
import os
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
WORLD = os.path.join(HERE, "..", "worlds", "learn", "avoidance.json")


def features(obs, layout):
    """(n, turtles, 9): each ray's nearness (0 nothing within range, 1 touching) and a bias."""
    near = 1.0 - obs[:, :, layout["range"]]
    return np.concatenate([near, np.ones(near.shape[:2] + (1,), dtype=np.float32)], axis=2)


def evaluate(vec, weights, copies_each, steps, seed):
    """Mean reward a step and a turtle of each policy in weights (P, 2, 9), on copies_each copies each."""
    import turtlegas  # noqa: F401  (vec is one)
    p = weights.shape[0]
    assert vec.num_envs == p * copies_each
    w = np.repeat(weights, copies_each, axis=0)  # (n, 2, 9): copy i runs policy i // copies_each
    obs, _ = vec.reset(seed)
    total = np.zeros(vec.num_envs)
    for _ in range(steps):
        x = features(obs, vec.layout)
        act = np.tanh(np.einsum("nod,ntd->nto", w, x)).astype(np.float32)
        obs, r, term, trunc, _ = vec.step(act)
        total += r.mean(axis=1)
    return (total / steps).reshape(p, copies_each).mean(axis=1)


def cem(generations=20, population=32, copies_each=4, steps=100, elite_frac=0.2, seed=1, threads=0,
        select="best", log=print):
    """The cross-entropy method. Returns a list of dicts a generation: mean_policy, population_mean, best.

    select="best" keeps the best fifth; "random" keeps a random fifth (a learner that learns
    nothing, for the test's control).
    """
    import turtlegas

    rng = np.random.default_rng(seed)
    dim = (2, 9)
    mu, sigma = np.zeros(dim), np.ones(dim)
    # One VecWorld for the population and the mean policy: (population + 1) x copies_each copies.
    # The reward is the world file's: {"learn": {"reward": "distance / stroke - touch"}}, the forward
    # stroke as a fraction of the longest, minus 1 for a step with a touch.
    vec = turtlegas.VecWorld(WORLD, (population + 1) * copies_each, seed, threads=threads)
    n_elite = max(2, int(round(elite_frac * population)))
    history = []
    for g in range(generations):
        cand = mu + sigma * rng.standard_normal((population,) + dim)
        weights = np.concatenate([mu[None], cand])
        scores = evaluate(vec, weights, copies_each, steps, seed=1000 * seed + g)
        pop = scores[1:]
        if select == "best":
            elite = cand[np.argsort(pop)[-n_elite:]]
        else:
            elite = cand[rng.choice(population, n_elite, replace=False)]
        mu = elite.mean(axis=0)
        # A floor on the spread that shrinks, so the search neither collapses early nor wanders late.
        sigma = elite.std(axis=0) + 0.3 * (1.0 - g / generations)
        row = {"generation": g, "mean_policy": float(scores[0]), "population_mean": float(pop.mean()), "best": float(pop.max())}
        history.append(row)
        log(f"generation {g:2d}: mean policy {row['mean_policy']:+.3f}  population mean {row['population_mean']:+.3f}  best {row['best']:+.3f}")
    history.append({"mu": mu})
    return history


def plot(history, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = [h for h in history if "generation" in h]
    g = [h["generation"] for h in rows]
    fig, ax = plt.subplots(figsize=(6.4, 3.6), dpi=120)
    ax.plot(g, [h["mean_policy"] for h in rows], "o-", label="mean policy (fresh starts)")
    ax.plot(g, [h["population_mean"] for h in rows], "s--", label="population mean")
    ax.plot(g, [h["best"] for h in rows], "^:", label="best candidate")
    ax.axhline(0.0, color="grey", linewidth=0.8)
    ax.set_xlabel("generation")
    ax.set_ylabel("reward per turtle per step")
    ax.set_title("8 turtles learn to avoid obstacles (cross-entropy method)")
    ax.legend(loc="lower right", fontsize=8)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    fig.savefig(path)


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--generations", type=int, default=20)
    p.add_argument("--population", type=int, default=32)
    p.add_argument("--copies", type=int, default=4, help="copies of the world each candidate runs on")
    p.add_argument("--steps", type=int, default=100, help="control steps an episode (0.1 s each)")
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--threads", type=int, default=0)
    p.add_argument("--plot", help="write the learning curve to this PNG")
    a = p.parse_args()
    t0 = time.perf_counter()
    history = cem(a.generations, a.population, a.copies, a.steps, seed=a.seed, threads=a.threads)
    print(f"{time.perf_counter() - t0:.1f} s")
    if a.plot:
        plot(history, a.plot)
        print("wrote", a.plot)
    return 0


if __name__ == "__main__":
    sys.exit(main())
