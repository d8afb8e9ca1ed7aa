#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Runs turtlegas side by side with other codes, interleaved, and writes one JSON line per run.

    python3 bench/peers_bench.py --tg-build DIR --peer-build DIR --work DIR --out RESULTS.jsonl
        [--sets edmd,box2d] [--points N1e4_phi0p05,...] [--rounds 5] [--collisions 3e6]
        [--peers cell_tuned_o3,cell_tuned_ofast] [--per-disc 10] [--core 1]
        [--box2d BIN] [--box2d-points N1e4_phi0p05_dt60,...] [--ball-steps 3e6]
        [--scaling-points N1e3_phi0p05,N1e6_phi0p05,...] [--scaling-rounds 3]

bench/run_peers.sh builds everything and calls this; see docs/performance.md, "Side by side with
the best event-driven code".

Set edmd: turtlegas exact mode (bench/gas_bench) against the 2-D ports of Smallenburg's EDMD
(../shared/peers/smallenburg_edmd, built by its build.sh) on the periodic scenes
worlds/bench/periodic_gas_<point>.json. One start per point for every program: turtlegas runs the
scene for --per-disc collisions per disc (the Enskog estimate of the time), and its final state
(exact doubles) becomes a turtlegas world of balls and a peer .sph file. Each timed run then
simulates the same span from that start: T = 2 K / (N Gamma_Enskog) for K = --collisions, in
turtlegas seconds; the peer, which rescales the loaded velocities to kT = 1, runs T sqrt(kT) of
its own time (the same trajectories in another time unit). Rounds alternate the order (turtlegas
first, then last: A B, B A, ...), so that neither program always follows the other.

Set box2d: turtlegas step mode (gas_bench --mode step) against Box2D (bench/box2d_gas.cpp) on the
walled scenes worlds/bench/gas_<N>_<phi>.json at dt = 1/n (point names end in _dt<n>), both from
the scene's generated start, --ball-steps ball-steps (body-steps) each, interleaved the same way.

Set scaling: turtlegas alone on the walled scenes at N = 10^3 and 10^6 (gas_bench's default budget),
alternating, for the cost per collision at 10^6 against 10^3 and the bytes per ball.

Every run is pinned with taskset to --core (empty: not pinned) and timed by its own CPU clock
over the simulation loop alone (turtlegas: thread CPU inside advance_to; EDMD: process CPU of its
event loop; Box2D: thread CPU of Step() after the first).
"""

import argparse
import hashlib
import json
import math
import os
import pathlib
import statistics
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent

# The peer's tuned settings (its tools/sidebyside.py, chosen by its tools/sweep2d.sh): below
# phi = 0.15 larger cells (at most 3 N of them) and longer calendar blocks, above only the blocks.
TUNED = {"cell": {"dilute": ["-cellmax", "3", "-elt", "4"], "dense": ["-elt", "4"]},
         "single": {"dilute": ["-shell", "4"], "dense": ["-shell", "2.5"]}}


def point_params(point):
    """N1e4_phi0p05 -> (10000, 0.05); a trailing _dt<n> gives dt = 1/n."""
    parts = point.split("_")
    n = int(float(parts[0][1:]))
    phi = float(parts[1][3:].replace("p", "."))
    dt = 1.0 / int(parts[2][2:]) if len(parts) > 2 else None
    return n, phi, dt


def henderson_g(phi):
    """The contact value of the pair correlation of hard discs (Henderson 1975)."""
    return (1 - 7 * phi / 16) / (1 - phi) ** 2


def enskog_rate(n_density, sigma, kT, mass, phi):
    """Collisions per disc per unit time, Enskog with Henderson's contact value (2-D)."""
    return 2 * n_density * sigma * math.sqrt(math.pi * kT / mass) * henderson_g(phi)


def run_json(cmd, core):
    """Runs a program (pinned) and returns its last line that is a JSON object."""
    full = (["taskset", "-c", str(core)] if core != "" else []) + [str(c) for c in cmd]
    res = subprocess.run(full, capture_output=True, text=True)
    if res.returncode != 0:
        sys.exit(f"peers_bench: {' '.join(full)} failed ({res.returncode}):\n{res.stderr[-2000:]}")
    return json.loads([line for line in res.stdout.splitlines() if line.startswith("{")][-1]), " ".join(full)


def load_average():
    return float(pathlib.Path("/proc/loadavg").read_text().split()[0])


def write_sph(path, width, height, balls, radius):
    """The EDMD ports' start file: N, the box, then 'a x y r vx vy' per disc (exact doubles)."""
    with open(path, "w") as f:
        f.write(f"{len(balls)}\n{width!r} {height!r}\n")
        for b in balls:
            (x, y), (vx, vy) = b["pos"], b["vel"]
            f.write(f"a {x!r} {y!r} {radius!r} {vx!r} {vy!r}\n")


class Scene:
    """A world file of one monodisperse gas entry, and what the Enskog estimate says about it."""

    def __init__(self, path):
        self.path = pathlib.Path(path)
        self.world = json.loads(self.path.read_text())
        gas = self.world["gas"][0]
        arena = self.world["arena"]
        self.n, self.radius, self.mass, self.speed = gas["count"], gas["radius"], gas.get("mass", 1), gas["speed"]
        self.width, self.height = arena["width"], arena["height"]
        self.phi = self.n * math.pi * self.radius ** 2 / (self.width * self.height)
        self.kT = self.mass * self.speed ** 2 / 2  # 2-D equipartition; every disc starts at `speed`
        self.rate = enskog_rate(self.n / (self.width * self.height), 2 * self.radius, self.kT, self.mass, self.phi)

    def state(self, tg, until, out):
        """turtlegas's state of the scene at `until` (exact doubles)."""
        subprocess.run([str(tg), "run", str(self.path), "--until", repr(until), "--state-out", str(out)],
                       check=True, stdout=subprocess.DEVNULL)
        return json.loads(pathlib.Path(out).read_text())

    def digest(self):
        return hashlib.sha256(self.path.read_bytes()).hexdigest()[:16]


def equilibrated_start(scene, point, a):
    """The shared start of one edmd point: (world file, .sph file, its record), made once and reused
    while the scene and --per-disc stay the same."""
    work = pathlib.Path(a.work)
    world_path, sph_path, stamp_path = (work / f"{point}.world.json", work / f"{point}.sph",
                                        work / f"{point}.start.json")
    stamp = {"scene": str(scene.path.relative_to(ROOT)), "scene_sha256": scene.digest(), "per_disc": a.per_disc}
    if stamp_path.exists() and world_path.exists() and sph_path.exists():
        record = json.loads(stamp_path.read_text())
        if all(record.get(k) == v for k, v in stamp.items()):
            return world_path, sph_path, record
    t_eq = a.per_disc / scene.rate
    print(f"{point}: equilibrating, {a.per_disc:g} collisions per disc (t = {t_eq:.4g} s)", file=sys.stderr, flush=True)
    state = scene.state(pathlib.Path(a.tg_build) / "turtlegas", t_eq, work / f"{point}.state.json")
    (work / f"{point}.state.json").unlink()
    balls = state["balls"]
    v2 = [b["vel"][0] ** 2 + b["vel"][1] ** 2 for b in balls]
    mean_v2 = sum(v2) / len(v2)
    world = {
        "format": "turtlegas-world/1",
        "name": f"{scene.world['name']} after {a.per_disc:g} collisions per disc",
        "x-about": f"state of {stamp['scene']} at t = {state['t']!r}, written by bench/peers_bench.py",
        "seed": scene.world.get("seed", 1),
        "dt": scene.world.get("dt", 1 / 30),
        "arena": scene.world["arena"],
        "balls": [{"id": b["id"], "pos": b["pos"], "vel": b["vel"], "radius": scene.radius, "mass": scene.mass}
                  for b in balls],
    }
    world_path.write_text(json.dumps(world))
    write_sph(sph_path, scene.width, scene.height, balls, scene.radius)
    # <v^4> / <v^2>^2: 2 for a 2-D Maxwell-Boltzmann gas, 1 for the generator's equal speeds.
    record = {**stamp, "t_eq": t_eq, "v4_over_v2sq": sum(x * x for x in v2) / len(v2) / mean_v2 ** 2}
    stamp_path.write_text(json.dumps(record))
    return world_path, sph_path, record


def peer_command(program, sph, phi, peer_time, a):
    """cell_tuned_o3 -> [PEER_BUILD/cell2d-o3, -in SPH, -time T, -cellmax 3, -elt 4] (below phi 0.15)."""
    parts = program.split("_")
    variant, build = parts[0], parts[-1]
    if variant not in TUNED or build not in ("o3", "ofast") or parts[1:-1] not in ([], ["tuned"]):
        sys.exit(f"peers_bench: unknown peer program '{program}' (cell|single [_tuned] _o3|_ofast)")
    cmd = [pathlib.Path(a.peer_build) / f"{variant}2d-{build}", "-in", sph, "-time", repr(peer_time)]
    if parts[1:-1] == ["tuned"]:
        cmd += TUNED[variant]["dilute" if phi < 0.15 else "dense"]
    return cmd


def batch_stderr(chunk_ends, n):
    """Relative standard error of the collision rate from the equal spans of a --sim-seconds run."""
    rates, prev_t, prev_c = [], 0.0, 0
    for t, c in chunk_ends:
        rates.append((c - prev_c) / (t - prev_t))
        prev_t, prev_c = t, c
    if len(rates) < 2:
        return None
    return statistics.stdev(rates) / math.sqrt(len(rates)) / statistics.mean(rates)


def edmd_line(program, scene, raw, cmd):
    """One run of the edmd set, in the same terms for both codes (rates per disc in the code's own
    time unit, so each is compared with Enskog at its own temperature)."""
    n = scene.n
    area = scene.width * scene.height
    if program == "turtlegas":
        coll, events, cpu, wall, t = raw["collisions"], raw["events"], raw["cpu_seconds"], raw["wall_seconds"], raw["sim_seconds"]
        crossings, stale = raw["cell_crossings"], raw["stale"]
        kT = raw["energy_start"] / n  # mass 1 here: the mean kinetic energy of a disc is kT in 2-D
        cell = raw["cell_size"] / (2 * scene.radius)
        extra = {"gamma_batch_stderr": batch_stderr(raw["chunk_ends"], n), "overlap_end": raw["overlap_end"],
                 "max_contact_overlap": raw["max_contact_overlap"], "cells": raw["cells"]}
    else:
        coll, events, cpu, wall, t = raw["collisions"], raw["events"], raw["cpu_s"], raw["wall_s"], raw["sim_time"]
        crossings, stale = raw["ev_cellcross"], raw["ev_stale"]
        kT = raw["kT"]
        cx, cy = raw["cells"]
        cell = scene.width / cx / (2 * scene.radius)
        extra = {"cells": cx * cy, "Z": raw["Z"]}
    gamma = 2 * coll / (n * t)
    gamma_enskog = enskog_rate(n / area, 2 * scene.radius, kT, scene.mass, scene.phi)
    return {"program": program, "cmd": cmd, "collisions": coll, "events": events, "cell_crossings": crossings,
            "stale": stale, "events_per_collision": events / coll, "crossings_per_collision": crossings / coll,
            "stale_per_collision": stale / coll, "cpu_seconds": cpu, "wall_seconds": wall,
            "cpu_over_wall": cpu / wall if wall > 0 else None, "collisions_per_cpu_second": coll / cpu,
            "ns_per_collision": 1e9 * cpu / coll, "sim_seconds": t, "kT": kT, "gamma": gamma,
            "gamma_enskog": gamma_enskog, "gamma_over_enskog": gamma / gamma_enskog, "energy_drift": raw["energy_drift"],
            "cell_diameters": cell, **extra}


def run_edmd(a, out):
    tg_build = pathlib.Path(a.tg_build)
    peers = [p for p in a.peers.split(",") if p]
    starts = {}
    for point in a.points:
        scene = Scene(ROOT / "worlds" / "bench" / f"periodic_gas_{point}.json")
        world, sph, record = equilibrated_start(scene, point, a)
        starts[point] = (scene, world, sph)
        emit(out, {"set": "edmd-start", "point": point, "N": scene.n, "phi": scene.phi, **record})
    for rnd in range(a.rounds):
        for point in a.points:
            scene, world, sph = starts[point]
            t_run = 2 * a.collisions / (scene.n * scene.rate)
            order = ["turtlegas"] + peers
            if rnd % 2 == 1:
                order.reverse()
            for slot, program in enumerate(order):
                load = load_average()
                if program == "turtlegas":
                    cmd = [tg_build / "bench" / "gas_bench", world, "--sim-seconds", repr(t_run), "--max-wall", "3000"]
                else:
                    cmd = peer_command(program, sph, scene.phi, t_run * math.sqrt(scene.kT), a)
                raw, shown = run_json(cmd, a.core)
                line = {"set": "edmd", "point": point, "N": scene.n, "phi": scene.phi, "round": rnd, "slot": slot,
                        "load_average": load, **edmd_line(program, scene, raw, shown), "raw": raw}
                emit(out, line)
                print(f"round {rnd} {point} {program:16s} {line['collisions_per_cpu_second'] / 1e6:6.3f} M coll/CPU-s "
                      f"({line['ns_per_collision']:5.0f} ns, {line['events_per_collision']:.2f} ev/coll, "
                      f"cpu/wall {line['cpu_over_wall']:.2f}, load {load:.1f})", file=sys.stderr, flush=True)


def run_box2d(a, out):
    tg_build = pathlib.Path(a.tg_build)
    work = pathlib.Path(a.work)
    cases = {}
    for point in a.box2d_points:
        n, phi, dt = point_params(point)
        base = "_".join(point.split("_")[:2])
        scene = Scene(ROOT / "worlds" / "bench" / f"gas_{base}.json")
        world = dict(scene.world, dt=dt)
        world_path = work / f"walled_{point}.json"
        world_path.write_text(json.dumps(world))
        sph = work / f"walled_{base}.start.sph"
        if not sph.exists():
            state = scene.state(tg_build / "turtlegas", 0.0, work / f"walled_{base}.state.json")
            write_sph(sph, scene.width, scene.height, state["balls"], scene.radius)
            (work / f"walled_{base}.state.json").unlink()
        cases[point] = (scene, world_path, sph, dt, max(10, round(a.ball_steps / scene.n)))
    for rnd in range(a.rounds):
        for point in a.box2d_points:
            scene, world_path, sph, dt, steps = cases[point]
            order = ["turtlegas-step", "box2d"] if rnd % 2 == 0 else ["box2d", "turtlegas-step"]
            for slot, program in enumerate(order):
                load = load_average()
                if program == "box2d":
                    # One step more: Box2D's first step (building every pair) is not timed.
                    raw, shown = run_json([a.box2d, sph, "--dt", repr(dt), "--steps", str(steps + 1)], a.core)
                    body_steps, cpu, wall = raw["steps"] - 1, raw["cpu_seconds"], raw["wall_seconds"]
                    contacts, drift = raw["contacts_begun"], raw["energy_drift"]
                else:
                    raw, shown = run_json([tg_build / "bench" / "gas_bench", world_path, "--mode", "step",
                                           "--steps", str(steps)], a.core)
                    body_steps, cpu, wall = raw["steps"], raw["cpu_seconds"], raw["wall_seconds"]
                    contacts, drift = raw["collisions"], raw["energy_drift"]
                rate = body_steps * scene.n / cpu
                line = {"set": "box2d", "point": point, "N": scene.n, "phi": scene.phi, "dt": dt, "round": rnd,
                        "slot": slot, "load_average": load, "program": program, "cmd": shown, "steps": body_steps,
                        "cpu_seconds": cpu, "wall_seconds": wall, "cpu_over_wall": cpu / wall if wall > 0 else None,
                        "body_steps_per_cpu_second": rate, "contacts": contacts, "energy_drift": drift, "raw": raw}
                emit(out, line)
                print(f"round {rnd} {point} {program:16s} {rate / 1e6:6.3f} M body-steps/CPU-s "
                      f"(cpu/wall {line['cpu_over_wall']:.2f}, load {load:.1f})", file=sys.stderr, flush=True)


def run_scaling(a, out):
    """turtlegas alone on the walled scenes worlds/bench/gas_<point>.json with gas_bench's default
    budget (max(5e6, 10 N) collisions), the points of one density in alternating order each round:
    cost per collision in CPU time at each N, and memory per ball."""
    gas_bench = pathlib.Path(a.tg_build) / "bench" / "gas_bench"
    for rnd in range(a.scaling_rounds):
        order = a.scaling_points if rnd % 2 == 0 else a.scaling_points[::-1]
        for slot, point in enumerate(order):
            n, phi, _ = point_params(point)
            load = load_average()
            raw, shown = run_json([gas_bench, ROOT / "worlds" / "bench" / f"gas_{point}.json", "--max-wall", "3000"], a.core)
            line = {"set": "scaling", "point": point, "N": raw["N"], "phi": raw["phi"], "round": rnd, "slot": slot,
                    "load_average": load, "program": "turtlegas", "cmd": shown, "collisions": raw["collisions"],
                    "events": raw["events"], "cpu_seconds": raw["cpu_seconds"], "wall_seconds": raw["wall_seconds"],
                    "cpu_over_wall": raw["cpu_seconds"] / raw["wall_seconds"],
                    "ns_per_collision": 1e9 * raw["cpu_seconds"] / raw["collisions"],
                    "bytes_per_ball": raw["bytes_per_ball"], "engine_bytes_per_ball": raw["engine_bytes_per_ball"],
                    "raw": raw}
            emit(out, line)
            print(f"round {rnd} {point} {line['ns_per_collision']:6.0f} CPU ns/collision, "
                  f"{line['bytes_per_ball']:.0f} B/ball (cpu/wall {line['cpu_over_wall']:.2f}, load {load:.1f})",
                  file=sys.stderr, flush=True)


def emit(out, line):
    out.write(json.dumps(line) + "\n")
    out.flush()


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--tg-build", required=True, help="turtlegas build directory (bench/gas_bench, turtlegas)")
    ap.add_argument("--peer-build", required=True, help="where smallenburg_edmd/build.sh put the peers")
    ap.add_argument("--work", required=True, help="starts and scratch files (kept: starts are reused)")
    ap.add_argument("--out", required=True)
    ap.add_argument("--sets", default="edmd,box2d,scaling")
    ap.add_argument("--points", default="N1e4_phi0p05,N1e4_phi0p30,N1e4_phi0p45,N1e5_phi0p05,N1e5_phi0p30,"
                    "N1e5_phi0p45,N1e6_phi0p05,N1e6_phi0p30,N1e6_phi0p45")
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--collisions", type=float, default=3e6, help="collisions per timed run (Enskog estimate)")
    ap.add_argument("--peers", default="cell_tuned_o3,cell_tuned_ofast")
    ap.add_argument("--per-disc", type=float, default=10, help="collisions per disc of the equilibration")
    ap.add_argument("--core", default="1", help="taskset core; empty: not pinned")
    ap.add_argument("--box2d", help="the box2d_gas program (set box2d)")
    ap.add_argument("--box2d-points", default="N1e4_phi0p05_dt60,N1e4_phi0p30_dt60,N1e4_phi0p05_dt600,N1e4_phi0p30_dt600")
    ap.add_argument("--ball-steps", type=float, default=3e6, help="ball-steps (body-steps) per timed run, set box2d")
    ap.add_argument("--scaling-points", default="N1e3_phi0p05,N1e6_phi0p05,N1e3_phi0p30,N1e6_phi0p30")
    ap.add_argument("--scaling-rounds", type=int, default=3)
    a = ap.parse_args()
    a.points = [p for p in a.points.split(",") if p]
    a.box2d_points = [p for p in a.box2d_points.split(",") if p]
    a.scaling_points = [p for p in a.scaling_points.split(",") if p]
    sets = [s for s in a.sets.split(",") if s]
    if "box2d" in sets and not a.box2d:
        sys.exit("peers_bench: set box2d needs --box2d BIN")
    pathlib.Path(a.work).mkdir(parents=True, exist_ok=True)
    with open(a.out, "w") as out:
        if "edmd" in sets:
            run_edmd(a, out)
        if "box2d" in sets:
            run_box2d(a, out)
        if "scaling" in sets:
            run_scaling(a, out)


if __name__ == "__main__":
    main()
