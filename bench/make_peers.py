#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Turns bench/peers_bench.py results (JSON lines) into the side-by-side tables of docs/performance.md and a plot.

    python3 bench/make_peers.py RESULTS.jsonl [--machine MACHINE.json] [--doc docs/performance.md]
                                [--svg docs/bench/peers.svg]

The tables replace whatever lies between this script's GENERATED markers in the doc; without --doc
they go to standard output. Plain python, SVG by hand, with make_tables.py's helpers.
"""

import math
import os
import statistics
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
sys.dont_write_bytecode = True  # no __pycache__ in bench/: machine_json.sh counts files there as changes
import make_tables  # noqa: E402  (the sibling script: table, machine, plot and splice helpers)
from make_tables import fixed, md_table, n_label, si  # noqa: E402

BEGIN = "<!-- BEGIN GENERATED: bench/make_peers.py -->"
END = "<!-- END GENERATED: bench/make_peers.py -->"
TARGET_EDMD = 1.5    # issue 15, target 1: turtlegas / best peer, collisions per CPU-second
TARGET_BOX2D = 1.5   # target 4: step mode's ball-steps within 1.5x of Box2D's body-steps
TARGET_SCALING = 2.5  # target 2: cost per collision at N = 10^6 within 2.5x of N = 10^3
COLOURS = {0.05: "#1f77b4", 0.3: "#d62728", 0.45: "#2ca02c"}


def med(xs):
    xs = [x for x in xs if x is not None]
    return statistics.median(xs) if xs else None


class Point:
    """The runs of one point of one set, by program, and the pairs of rounds."""

    def __init__(self, rows, rate_key):
        self.rows = rows
        self.first = rows[0]
        self.rate_key = rate_key
        self.by_program = {}
        for r in rows:
            self.by_program.setdefault(r["program"], []).append(r)

    def rate(self, program):
        return med(r[self.rate_key] for r in self.by_program[program])

    def median(self, program, key):
        return med(r.get(key) for r in self.by_program[program])

    def ratios(self, a, b):
        """Per round, a's rate / b's, for the rounds in which both ran."""
        rb = {r["round"]: r[self.rate_key] for r in self.by_program[b]}
        return [r[self.rate_key] / rb[r["round"]] for r in self.by_program[a] if r["round"] in rb]

    def spread(self):
        """The median cpu/wall of every run of the point."""
        return med(r.get("cpu_over_wall") for r in self.rows)


def points(rows, kind, rate_key):
    chosen = {}
    for r in rows:
        if r["set"] == kind:
            chosen.setdefault(r["point"], []).append(r)
    out = [Point(rs, rate_key) for rs in chosen.values()]
    return sorted(out, key=lambda p: (p.first["N"], p.first["phi"], p.first.get("dt") or 0))


def best_peer(p):
    peers = [k for k in p.by_program if k != "turtlegas"]
    return max(peers, key=p.rate) if peers else None


def ratio_cells(ratios, target):
    if not ratios:
        return ["–", "–", "–"]
    m = statistics.median(ratios)
    return [f"**{m:.2f}**", f"{min(ratios):.2f}–{max(ratios):.2f} ({len(ratios)})", "met" if m >= target else "not met"]


def edmd_table(pts):
    out = []
    for p in pts:
        peer = best_peer(p)
        r = p.first
        out.append([n_label(r["N"]), f"{r['phi']:.2f}", si(p.rate("turtlegas")), peer or "–",
                    si(p.rate(peer)) if peer else "–", *ratio_cells(p.ratios("turtlegas", peer) if peer else [], TARGET_EDMD),
                    fixed(p.spread(), 2)])
    return md_table(["N", "φ", "turtlegas, collisions/CPU-s", "best peer", "peer, collisions/CPU-s",
                     "turtlegas ÷ peer (median of pairs)", "pairs: range (count)", f"≥ {TARGET_EDMD:g}×",
                     "cpu/wall (median)"], out)


def work_table(pts):
    out = []
    for p in pts:
        peer = best_peer(p)
        r = p.first
        tg = ["events_per_collision", "crossings_per_collision", "stale_per_collision", "cell_diameters"]
        cells = [fixed(p.median("turtlegas", k), 2) for k in tg]
        if peer:
            cells += [fixed(p.median(peer, k), 2) for k in ("events_per_collision", "crossings_per_collision",
                                                            "cell_diameters")]
            ns = [1e9 * p.median(prog, "cpu_seconds") / p.median(prog, "events") for prog in ("turtlegas", peer)]
            cells += [f"{ns[0]:.0f}", f"{ns[1]:.0f}"]
        else:
            cells += ["–"] * 5
        out.append([n_label(r["N"]), f"{r['phi']:.2f}", *cells])
    return md_table(["N", "φ", "turtlegas events / collision", "crossings", "stale", "cell (σ)",
                     "peer events / collision", "crossings", "cell (σ)", "turtlegas CPU ns / event",
                     "peer CPU ns / event"], out)


def physics_table(pts, starts):
    out = []
    for p in pts:
        peer = best_peer(p)
        r = p.first
        tg = p.by_program["turtlegas"][0]  # every round is the same run (deterministic)
        err = tg.get("gamma_batch_stderr")
        g_tg = tg["gamma_over_enskog"] - 1
        g_peer = p.by_program[peer][0]["gamma_over_enskog"] - 1 if peer else None
        start = starts.get(r["point"], {})
        out.append([
            n_label(r["N"]), f"{r['phi']:.2f}", fixed(start.get("v4_over_v2sq"), 3), f"{tg['collisions']:,}",
            f"{100 * g_tg:+.3f} % ± {100 * err:.3f} %" if err else f"{100 * g_tg:+.3f} %",
            f"{100 * g_peer:+.3f} %" if g_peer is not None else "–",
            f"{(g_tg - g_peer) / (err * math.sqrt(2)):+.1f}" if err and g_peer is not None else "–",
            f"{tg['energy_drift']:.1e}", f"{p.by_program[peer][0]['energy_drift']:.1e}" if peer else "–",
            f"{tg['max_contact_overlap']:.1e}",
        ])
    return md_table(["N", "φ", "start ⟨v⁴⟩/⟨v²⟩²", "turtlegas collisions", "turtlegas Γ ÷ Enskog − 1 (± batch error)",
                     "peer Γ ÷ Enskog − 1", "turtlegas − peer (in σ of the difference)", "turtlegas energy drift",
                     "peer energy drift", "turtlegas deepest contact overlap (÷ r)"], out)


def box2d_table(pts):
    out = []
    for p in pts:
        r = p.first
        out.append([n_label(r["N"]), f"{r['phi']:.2f}", f"1/{round(1 / r['dt'])}", si(p.rate("turtlegas-step")),
                    si(p.rate("box2d")), *ratio_cells(p.ratios("turtlegas-step", "box2d"), 1 / TARGET_BOX2D),
                    fixed(p.spread(), 2)])
    return md_table(["N", "φ", "dt (s)", "step mode, ball-steps/CPU-s", "Box2D, body-steps/CPU-s",
                     "step mode ÷ Box2D (median of pairs)", "pairs: range (count)", f"≥ 1/{TARGET_BOX2D:g}",
                     "cpu/wall (median)"], out)


def scaling_table(pts):
    """Per density: cost per collision (CPU) at the smallest and the largest N, their ratio per round."""
    out = []
    for phi in sorted({round(p.first["phi"], 3) for p in pts}):
        series = sorted((p for p in pts if round(p.first["phi"], 3) == phi), key=lambda p: p.first["N"])
        small, large = series[0], series[-1]
        ns = {r["round"]: r["ns_per_collision"] for r in small.rows}
        ratios = [r["ns_per_collision"] / ns[r["round"]] for r in large.rows if r["round"] in ns]
        m = statistics.median(ratios)
        out.append([f"{phi:.2f}", f"{med(r['ns_per_collision'] for r in small.rows):.0f}",
                    f"{med(r['ns_per_collision'] for r in large.rows):.0f}",
                    f"**{m:.2f}** ({min(ratios):.2f}–{max(ratios):.2f})", "met" if m <= TARGET_SCALING else "not met",
                    fixed(med(r["bytes_per_ball"] for r in large.rows), 0),
                    fixed(med(r["engine_bytes_per_ball"] for r in large.rows), 0),
                    "met" if med(r["bytes_per_ball"] for r in large.rows) <= 200 else "not met",
                    fixed(med(r.get("cpu_over_wall") for p in (small, large) for r in p.rows), 2)])
    n_small, n_large = n_label(pts[0].first["N"]), n_label(pts[-1].first["N"])
    return md_table(["φ", f"CPU ns / collision, N = {n_small}", f"N = {n_large}",
                     f"{n_large} ÷ {n_small} (median of rounds; range)", f"≤ {TARGET_SCALING:g}×",
                     f"bytes/ball at {n_large} (process)", "(engine)", "≤ 200", "cpu/wall (median)"], out)


def targets(edmd, box2d, scaling):
    lines = []
    if edmd:
        rs = [(statistics.median(p.ratios("turtlegas", best_peer(p))), p) for p in edmd if best_peer(p)]
        met = sum(1 for m, _ in rs if m >= TARGET_EDMD)
        worst, wp = min(rs, key=lambda x: x[0])
        lines.append(f"- ≥ {TARGET_EDMD:g}× the best peer at every point: met at **{met} of {len(rs)}**; lowest "
                     f"**{worst:.2f}** (N = {n_label(wp.first['N'])}, φ = {wp.first['phi']:.2f})")
    if box2d:
        rs = [(statistics.median(p.ratios("turtlegas-step", "box2d")), p) for p in box2d]
        met = sum(1 for m, _ in rs if m >= 1 / TARGET_BOX2D)
        worst, wp = min(rs, key=lambda x: x[0])
        lines.append(f"- step mode's ball-steps within {TARGET_BOX2D:g}× of Box2D's body-steps at the same dt: met at "
                     f"**{met} of {len(rs)}**; lowest **{worst:.2f}** (N = {n_label(wp.first['N'])}, "
                     f"φ = {wp.first['phi']:.2f}, dt = 1/{round(1 / wp.first['dt'])})")
    for phi in sorted({round(p.first["phi"], 3) for p in scaling}):
        series = sorted((p for p in scaling if round(p.first["phi"], 3) == phi), key=lambda p: p.first["N"])
        ns = {r["round"]: r["ns_per_collision"] for r in series[0].rows}
        m = statistics.median(r["ns_per_collision"] / ns[r["round"]] for r in series[-1].rows if r["round"] in ns)
        lines.append(f"- cost per collision at N = {n_label(series[-1].first['N'])} within {TARGET_SCALING:g}× of "
                     f"N = {n_label(series[0].first['N'])} at φ = {phi:.2f}: **{m:.2f}** — "
                     + ("met" if m <= TARGET_SCALING else "not met"))
    return "\n".join(lines)


def svg_plot(edmd, path):
    """Collisions per CPU-second against N, one line per code and density."""
    lines = []
    for phi in sorted({round(p.first["phi"], 3) for p in edmd}):
        series = [p for p in edmd if round(p.first["phi"], 3) == phi]
        colour = COLOURS.get(phi, "#555")
        lines.append((f"turtlegas, φ = {phi:g}", colour, False, [(p.first["N"], p.rate("turtlegas")) for p in series]))
        lines.append((f"best peer, φ = {phi:g}", colour, True,
                      [(p.first["N"], p.rate(best_peer(p))) for p in series if best_peer(p)]))
    make_tables.line_plot(path, "turtlegas exact mode and the best EDMD peer: collisions per CPU-second (log-log)",
                          "collisions per CPU-second", lines, legend_width=210)


def main():
    report = make_tables.Report(__doc__.splitlines()[0])
    rows = report.rows
    edmd = points(rows, "edmd", "collisions_per_cpu_second")
    box2d = points(rows, "box2d", "body_steps_per_cpu_second")
    starts = {r["point"]: r for r in rows if r["set"] == "edmd-start"}
    parts = report.header()
    if edmd:
        rounds = max(r["round"] for p in edmd for r in p.rows) + 1
        parts += [f"### Exact mode against the best EDMD peer (periodic; {rounds} rounds, "
                  f"{si(med(r['collisions'] for p in edmd for r in p.rows))} collisions a run)", "",
                  edmd_table(edmd), "", "Work per collision (medians over the rounds):", "", work_table(edmd), "",
                  "Same physics: the collision rate per disc against Enskog with Henderson's contact value, in "
                  "each code's own temperature and time unit (round 0; the error bar is the batch-means "
                  "standard error of turtlegas's ten equal spans):", "", physics_table(edmd, starts), ""]
    if box2d:
        parts += ["### Step mode against Box2D (walled gas, same start)", "", box2d_table(box2d), ""]
    scaling = points(rows, "scaling", "ns_per_collision")
    if scaling:
        rounds = max(r["round"] for p in scaling for r in p.rows) + 1
        parts += [f"### Scaling: turtlegas alone, walled gas, N = {n_label(scaling[0].first['N'])} and "
                  f"{n_label(scaling[-1].first['N'])} alternating ({rounds} rounds, gas_bench's default budget)", "",
                  scaling_table(scaling), ""]
    if edmd or box2d or scaling:
        parts += ["### Targets", "", targets(edmd, box2d, scaling), ""]
    if report.args.svg and edmd:
        svg_plot(edmd, report.args.svg)
        parts += [f"![collisions per CPU-second against N]({report.rel(report.args.svg)})", ""]
    report.publish(BEGIN, END, parts)


if __name__ == "__main__":
    main()
