#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Turns accuracy_bench results (JSON lines) into the accuracy-against-cost tables and plot of docs/performance.md.

    python3 bench/make_accuracy.py RESULTS.jsonl [--machine MACHINE.json] [--doc docs/performance.md]
                                   [--svg docs/bench/accuracy.svg]

The tables replace whatever lies between this script's GENERATED markers in the doc; without --doc
they go to standard output. Plain python, SVG by hand, as make_tables.py (whose helpers it uses).
"""

import math
import os
import pathlib
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
sys.dont_write_bytecode = True  # no __pycache__ in bench/: machine_json.sh counts files there as changes
import make_tables  # noqa: E402  (the sibling script: table, machine and splice helpers)

BEGIN = "<!-- BEGIN GENERATED: bench/make_accuracy.py -->"
END = "<!-- END GENERATED: bench/make_accuracy.py -->"

# One panel per scene and kind of error: (title, scene, [(key, series label, colour)], guide). guide
# draws a line of slope -1 through the first series' smallest-dt point: error proportional to dt,
# since step mode's cost is proportional to 1/dt.
PANELS = [
    ("balls under gravity: position error at T", "ballistic",
     [("max_position_error", "max over balls", "#d62728"), ("rms_position_error", "RMS over balls", "#1f77b4")], True),
    ("balls under gravity: energy error", "ballistic",
     [("rms_ball_energy_error", "each ball's, RMS", "#9467bd"), ("energy_error", "total", "#2ca02c")], True),
    ("the memo's gas under gravity: energy error", "gas",
     [("energy_error", "total", "#ff7f0e")], False),
]


def dt_label(r):
    return "exact" if r["mode"] == "exact" else f"1/{round(1 / r['dt'])}"


def scene_rows(rows, scene):
    """Exact mode first, then step mode from the largest dt down (cheapest first)."""
    chosen = [r for r in rows if r["scene"] == scene]
    return sorted(chosen, key=lambda r: (r["mode"] != "exact", -(r["dt"] or 0)))


def g3(x):
    return "–" if x is None else f"{x:.3g}"


def cost_cells(r, exact):
    """The columns every table starts with: mode, dt, cost, cost against exact mode's."""
    return [r["mode"], dt_label(r) if r["mode"] == "step" else "–", g3(r["cpu_per_sim_second"]),
            g3(r['cpu_per_sim_second'] / exact['cpu_per_sim_second']) if exact else "–"]


def ballistic_table(rows):
    exact = next((r for r in rows if r["mode"] == "exact"), None)
    out = []
    for r in rows:
        out.append(cost_cells(r, exact) + [
            g3(r["max_position_error"]), g3(r["rms_position_error"]), g3(r["rms_ball_energy_error"]),
            g3(r["energy_error"]), f"{r['collisions']:,}", make_tables.flag(r) or "",
        ])
    return make_tables.md_table(["mode", "dt (s)", "CPU s / sim s", "cost ÷ exact", "max position error",
                                 "RMS position error", "energy error, each ball (RMS)", "energy error, total",
                                 "collisions", "notes"], out)


def gas_table(rows):
    exact = next((r for r in rows if r["mode"] == "exact"), None)
    out = []
    for r in rows:
        out.append(cost_cells(r, exact) + [
            f"{r['energy_drift']:+.1e}", f"{r['collisions']:,}",
            f"{100 * (r['collisions'] / exact['collisions'] - 1):+.1f} %" if exact and exact["collisions"] else "–",
            make_tables.flag(r) or "",
        ])
    return make_tables.md_table(["mode", "dt (s)", "CPU s / sim s", "cost ÷ exact", "energy drift",
                                 "collisions", "collisions − exact", "notes"], out)


def power(e):
    """10^e as SVG text, the exponent raised."""
    return f'10<tspan dy="-5" font-size="9">{e}</tspan>'


def svg_plot(rows, path):
    """Log-log, one panel per entry of PANELS: error against CPU seconds per simulated second."""
    pw, ph = 380, 440               # one panel, margins included
    left, right, top, bottom = 64, 14, 58, 52
    width, height = pw * len(PANELS) + 40, ph + 30
    xs = [r["cpu_per_sim_second"] for r in rows if r["cpu_per_sim_second"] > 0]
    x0, x1 = math.floor(math.log10(min(xs))), math.ceil(math.log10(max(xs)))
    svg = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" '
           f'font-family="sans-serif" font-size="12">',
           f'<rect width="{width}" height="{height}" fill="white"/>',
           '<text x="14" y="22" font-size="15">turtlegas: what accuracy costs — error against CPU seconds per '
           'simulated second (log-log); step mode labelled by dt, exact mode ◆</text>']
    for k, (title, scene, series, guide) in enumerate(PANELS):
        ox = k * pw + 30
        chosen = scene_rows(rows, scene)
        # Zero errors cannot sit on a log axis; none occur in practice (round-off is never exactly 0),
        # but a floor keeps the plot drawable if one did.
        vals = [max(r[key], 1e-17) for r in chosen for key, _, _ in series]
        if not vals:
            continue
        y0, y1 = math.floor(math.log10(min(vals))), math.ceil(math.log10(max(vals)))
        if y1 == y0:
            y1 += 1
        px0, px1, py0, py1 = ox + left, ox + pw - right, top + 30, ph + 30 - bottom

        def px(x):
            return px0 + (math.log10(x) - x0) / (x1 - x0) * (px1 - px0)

        def py(v):
            return py1 - (math.log10(max(v, 1e-17)) - y0) / (y1 - y0) * (py1 - py0)

        svg.append(f'<text x="{(px0 + px1) / 2:.0f}" y="{top + 18}" text-anchor="middle" font-size="13">{title}</text>')
        step_e = 1 if y1 - y0 <= 10 else 2  # a label every decade, or every other one on tall axes
        for e in range(y0, y1 + 1):
            y = py(10.0**e)
            svg.append(f'<line x1="{px0}" y1="{y:.1f}" x2="{px1}" y2="{y:.1f}" stroke="#ddd"/>')
            if (e - y0) % step_e == 0:
                svg.append(f'<text x="{px0 - 6}" y="{y + 4:.1f}" text-anchor="end">{power(e)}</text>')
        for e in range(x0, x1 + 1):
            x = px(10.0**e)
            svg.append(f'<line x1="{x:.1f}" y1="{py0}" x2="{x:.1f}" y2="{py1}" stroke="#ddd"/>')
            svg.append(f'<text x="{x:.1f}" y="{py1 + 18}" text-anchor="middle">{power(e)}</text>')
        svg.append(f'<rect x="{px0}" y="{py0}" width="{px1 - px0}" height="{py1 - py0}" fill="none" stroke="#333"/>')
        svg.append(f'<text x="{(px0 + px1) / 2:.0f}" y="{py1 + 40}" text-anchor="middle">'
                   'CPU seconds per simulated second</text>')
        svg.append(f'<text transform="translate({ox + 16},{(py0 + py1) / 2:.0f}) rotate(-90)" '
                   f'text-anchor="middle">{"position error (units)" if "position" in title else "relative energy error"}'
                   '</text>')
        steps = [r for r in chosen if r["mode"] == "step"]
        exact = [r for r in chosen if r["mode"] == "exact"]
        if guide and steps:
            key = series[0][0]
            last = steps[-1]
            xa, xb = 10.0**x0, 10.0**x1
            ya, yb = last[key] * last["cpu_per_sim_second"] / xa, last[key] * last["cpu_per_sim_second"] / xb
            svg.append(f'<clipPath id="clip{k}"><rect x="{px0}" y="{py0}" width="{px1 - px0}" height="{py1 - py0}"/>'
                       '</clipPath>')
            svg.append(f'<line x1="{px(xa):.1f}" y1="{py(ya):.1f}" x2="{px(xb):.1f}" y2="{py(yb):.1f}" '
                       f'stroke="#999" stroke-dasharray="3,4" clip-path="url(#clip{k})"/>')
        for s, (key, label, colour) in enumerate(series):
            pts = [(px(r["cpu_per_sim_second"]), py(r[key]), dt_label(r)) for r in steps]
            if pts:
                d = " ".join(f"{x:.1f},{y:.1f}" for x, y, _ in pts)
                svg.append(f'<polyline points="{d}" fill="none" stroke="{colour}" stroke-width="2"/>')
            for x, y, lab in pts:
                svg.append(f'<circle cx="{x:.1f}" cy="{y:.1f}" r="3.5" fill="{colour}"/>')
                if s == 0:
                    svg.append(f'<text x="{x + 6:.1f}" y="{y - 6:.1f}" font-size="10" fill="#333">{lab}</text>')
            for r in exact:
                x, y = px(r["cpu_per_sim_second"]), py(r[key])
                svg.append(f'<path d="M{x:.1f},{y - 7:.1f} L{x + 7:.1f},{y:.1f} L{x:.1f},{y + 7:.1f} '
                           f'L{x - 7:.1f},{y:.1f} Z" fill="{colour}" stroke="#000" stroke-width="1"/>')
                if s == 0:
                    svg.append(f'<text x="{x + 10:.1f}" y="{y + 4:.1f}" font-size="11" fill="#333">exact</text>')
        # Legend in the bottom right corner, which the data leave empty: step mode's errors sit high
        # (its cheap runs are inaccurate), exact mode's at the bottom left.
        entries = [(f"step: {label}", colour, "line") for _, label, colour in series]
        entries += [(f"exact: {label}", colour, "diamond") for _, label, colour in series]
        if guide:
            entries.append(("error ∝ dt (slope −1)", "#999", "guide"))
        lx, ly = px1 - 150, py1 - 18 * len(entries) + 4
        svg.append(f'<rect x="{lx - 8}" y="{ly - 12}" width="156" height="{18 * len(entries) + 6}" fill="white" '
                   'stroke="#bbb"/>')
        for j, (text, colour, kind) in enumerate(entries):
            y = ly + 18 * j
            if kind == "line":
                svg.append(f'<line x1="{lx}" y1="{y}" x2="{lx + 22}" y2="{y}" stroke="{colour}" stroke-width="2"/>')
                svg.append(f'<circle cx="{lx + 11}" cy="{y}" r="3.5" fill="{colour}"/>')
            elif kind == "diamond":
                svg.append(f'<path d="M{lx + 11},{y - 6} L{lx + 17},{y} L{lx + 11},{y + 6} L{lx + 5},{y} Z" '
                           f'fill="{colour}" stroke="#000" stroke-width="1"/>')
            else:
                svg.append(f'<line x1="{lx}" y1="{y}" x2="{lx + 22}" y2="{y}" stroke="{colour}" '
                           'stroke-dasharray="3,4"/>')
            svg.append(f'<text x="{lx + 28}" y="{y + 4}" font-size="11">{text}</text>')
    svg.append("</svg>")
    pathlib.Path(path).parent.mkdir(parents=True, exist_ok=True)
    pathlib.Path(path).write_text("\n".join(svg) + "\n")


def main():
    report = make_tables.Report(__doc__.splitlines()[0])
    rows = report.rows
    parts = report.header()
    ballistic, gas = scene_rows(rows, "ballistic"), scene_rows(rows, "gas")
    if ballistic:
        b = ballistic[0]
        parts += [f"### Balls under gravity, closed-form reference (`{b['world_file']}`: N = {b['N']}, "
                  f"T = {b['sim_seconds']:.3g} s)", "", ballistic_table(ballistic), ""]
    if gas:
        g = gas[0]
        parts += [f"### The memo's gas under gravity (`{g['world_file']}`: N = {g['N']}, "
                  f"T = {g['sim_seconds']:.3g} s)",
                  "", gas_table(gas), ""]
    if report.args.svg:
        svg_plot(rows, report.args.svg)
        parts += [f"![error against CPU seconds per simulated second]({report.rel(report.args.svg)})", ""]
    report.publish(BEGIN, END, parts)

if __name__ == "__main__":
    main()
