#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Writes the benchmark scenes worlds/bench/gas_N<n>_phi<f>.json, periodic_gas_N<n>_phi<f>.json and
effects_<name>.json.

A random gas in a square box with four walls: N discs of radius 0.5, mass 1 and speed 3 in random
directions, at area fraction phi, so the box side is sqrt(N * pi * r^2 / phi). The files are data
shared with other engines' benchmarks; rerun this script only to change the scene set.

The periodic_gas_*.json scenes are the same gas in a periodic square (no walls), for the side by
side with event-driven codes that have no walls (bench/run_peers.sh): N = 10^4, 10^5, 10^6 at
phi = 0.05, 0.30 and 0.45. Above phi = 0.35 the loader's generator starts the balls on a jittered
hexagonal lattice instead of placing them at random (random placement jams near 0.547); the side
by side equilibrates every scene before it measures, so the start does not matter.

The effects_*.json scenes are the N = 10^4, phi = 0.05 gas with one effect switched on at a
strength that changes nothing measurable (gravity of 1e-12, one wall in a category of its own
that every ball still collides with), so that the engine runs its general code for that effect:
bench/run_effects.sh measures what the plain scene saves by not declaring it.

    python3 bench/make_worlds.py [OUT_DIR]
"""

import json
import math
import pathlib
import re
import sys

RADIUS = 0.5
SPEED = 3.0
SEED = 272
DT = 1.0 / 30.0  # the memo's step: moves a ball 0.1 per step, so the memo's rule asks for cells > 1.2
COUNTS = [("1e3", 1_000), ("1e4", 10_000), ("1e5", 100_000), ("1e6", 1_000_000)]
FRACTIONS = [("0p05", 0.05), ("0p30", 0.30)]
PERIODIC_COUNTS = COUNTS[1:]
PERIODIC_FRACTIONS = FRACTIONS + [("0p45", 0.45)]


def scene(count: int, phi: float) -> dict:
    side = math.sqrt(count * math.pi * RADIUS * RADIUS / phi)
    return {
        "format": "turtlegas-world/1",
        "name": f"gas benchmark N={count} phi={phi:g}",
        "x-about": (
            f"{count} discs of radius {RADIUS:g} and speed {SPEED:g} in random directions in a square "
            f"box with walls at area fraction {phi:g} (side sqrt(N pi r^2 / phi)). "
            "Written by bench/make_worlds.py; run by bench/gas_bench (docs/performance.md)."
        ),
        "seed": SEED,
        "dt": DT,
        "arena": {"width": side, "height": side, "boundary": "walls"},
        "gas": [
            {
                "count": count,
                "radius": RADIUS,
                "mass": 1,
                "speed": SPEED,
                "region": [[0, 0], [side, side]],
                "seed": SEED,
            }
        ],
    }


def periodic_scene(count: int, phi: float) -> dict:
    s = scene(count, phi)
    s["name"] = f"periodic gas benchmark N={count} phi={phi:g}"
    s["x-about"] = (
        f"{count} discs of radius {RADIUS:g} and speed {SPEED:g} in random directions in a periodic square "
        f"at area fraction {phi:g} (side sqrt(N pi r^2 / phi)), no walls. Written by bench/make_worlds.py; "
        "run side by side with other event-driven codes by bench/run_peers.sh (docs/performance.md)."
    )
    s["arena"]["boundary"] = "periodic"
    return s


# One collision layer, declared by a short wall on the left edge that is in a category of its own.
TAGGED_WALL = {"id": "tagged", "from": [0, 0], "to": [0, 1], "category": "tagged"}
EFFECTS = [
    ("plain", {}, []),
    ("gravity", {"gravity": [0, -1e-12]}, []),
    ("layers", {}, [TAGGED_WALL]),
    ("gravity_layers", {"gravity": [0, -1e-12]}, [TAGGED_WALL]),
]


def effects_scene(name: str, effects: dict, walls: list) -> dict:
    s = scene(10_000, 0.05)
    s["name"] = f"effects benchmark: {name}"
    s["x-about"] = (
        "The N=10000 phi=0.05 gas benchmark with effects declared that change nothing measurable "
        f"({name}). Written by bench/make_worlds.py; run by bench/run_effects.sh (docs/performance.md)."
    )
    if effects:
        s["effects"] = effects
    if walls:
        s["walls"] = walls
    return s


def write(path: pathlib.Path, world: dict) -> None:
    # repr-exact doubles: the side must give exactly this phi in every engine that reads it.
    text = json.dumps(world, indent=2)
    # Number pairs on one line: [[0, 0], [side, side]] reads better than eight lines.
    text = re.sub(r"\[\s*([-\d.e+]+),\s*([-\d.e+]+)\s*\]", r"[\1, \2]", text)
    text = re.sub(r"\[\s*(\[[^\[\]]*\]),\s*(\[[^\[\]]*\])\s*\]", r"[\1, \2]", text)
    path.write_text(text + "\n")
    print(path)


def main() -> None:
    root = pathlib.Path(__file__).resolve().parent.parent
    out = pathlib.Path(sys.argv[1]) if len(sys.argv) > 1 else root / "worlds" / "bench"
    out.mkdir(parents=True, exist_ok=True)
    for count_name, count in COUNTS:
        for phi_name, phi in FRACTIONS:
            write(out / f"gas_N{count_name}_phi{phi_name}.json", scene(count, phi))
    for count_name, count in PERIODIC_COUNTS:
        for phi_name, phi in PERIODIC_FRACTIONS:
            write(out / f"periodic_gas_N{count_name}_phi{phi_name}.json", periodic_scene(count, phi))
    for name, effects, walls in EFFECTS:
        write(out / f"effects_{name}.json", effects_scene(name, effects, walls))

if __name__ == "__main__":
    main()
