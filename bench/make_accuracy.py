#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Turns accuracy_bench results (JSON lines) into the accuracy-against-cost tables and plot of docs/performance.md.

    python3 bench/make_accuracy.py RESULTS.jsonl [--machine MACHINE.json] [--doc docs/performance.md]
                                   [--svg docs/bench/accuracy.svg] [--svg-box2d docs/bench/accuracy_box2d.svg]

Lines of the walled scenes (accuracy_bench --walled) and of bench/box2d_gas on them get tables of
their own and the plot --svg-box2d.

The tables replace whatever lies between this script's GENERATED markers in the doc; without --doc
they go to standard output. Plain python, SVG by hand, as make_tables.py (whose helpers it uses).
"""

import math
import os
import pathlib
import statistics
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


def charged_table(rows):
    exact = next((r for r in rows if r["mode"] == "exact"), None)
    out = []
    for r in rows:
        out.append(cost_cells(r, exact) + [
            g3(r["max_position_error"]) if r["mode"] == "step" else "reference",
            g3(r["rms_position_error"]) if r["mode"] == "step" else "–",
            g3(r["median_position_error"]) if r["mode"] == "step" else "–", g3(r["rms_speed_error"]),
            f"{r['collisions']:,}", make_tables.flag(r) or "",
        ])
    return make_tables.md_table(["mode", "dt (s)", "CPU s / sim s", "cost ÷ exact", "max position error",
                                 "RMS position error", "median position error", "speed error, each ball (RMS)",
                                 "collisions", "notes"], out)


# Errors below a double's round-off at the quantity's own size are counted as this much in the
# ratios against Box2D (an exact 0 is round-off that happened to cancel).
ROUND_OFF = 1e-16
SPEED_TARGET, ACCURACY_TARGET = 20.0, 1e6  # issue 15, target 3: exact mode against Box2D at dt = 1/60
WALLED_COLOURS = {"step": "#1f77b4", "box2d": "#d62728", "exact": "#2ca02c"}
WALLED_NAMES = {"exact": "exact", "step": "step mode", "box2d": "Box2D"}


def walled_groups(rows):
    """The walled scene's rows by world file, smallest N first; in each, exact mode, step mode and
    Box2D, each from the largest dt down, one row per code and dt (merge_rounds)."""
    groups = {}
    for r in rows:
        if r.get("scene") == "walled":
            groups.setdefault(r["world_file"], []).append(r)
    order = {"exact": 0, "step": 1, "box2d": 2}
    return [sorted(merge_rounds(g), key=lambda r: (order[r["mode"]], -(r["dt"] or 0)))
            for g in sorted(groups.values(), key=lambda g: g[0]["N"])]


def run_key(r):
    return r["mode"], r["dt"]


def merge_rounds(rows):
    """One row per code and dt out of the rounds (bench/run_accuracy.sh's "round", absent in
    results of one round): the first round's, its cost the median over the rounds, with "costs"
    (every round's, by round) added. Both codes are deterministic, so the errors must be the same
    in every round; "errors_differ" marks a row where they are not."""
    runs = {}
    for r in rows:
        runs.setdefault(run_key(r), []).append(r)
    merged = []
    for same in runs.values():
        same.sort(key=lambda r: r.get("round", 0))
        m = dict(same[0])
        m["costs"] = {r.get("round", 0): r["cpu_per_sim_second"] for r in same}
        m["cpu_per_sim_second"] = statistics.median(m["costs"].values())
        m["errors_differ"] = any(r[k] != m[k] for r in same for k in ("energy_error", "rms_position_error"))
        merged.append(m)
    return merged


def walled_table(rows):
    exact = next((r for r in rows if r["mode"] == "exact"), None)
    out = []
    for r in rows:
        collisions = r.get("contacts_begun", r.get("collisions"))
        costs = list(r["costs"].values())
        notes = [n for n in (make_tables.flag(r), "errors differ between rounds" if r["errors_differ"] else "") if n]
        out.append([WALLED_NAMES[r["mode"]], dt_label(r) if r["mode"] != "exact" else "–", g3(r["cpu_per_sim_second"]),
                    f"{g3(min(costs))}–{g3(max(costs))} ({len(costs)})",
                    g3(r["cpu_per_sim_second"] / exact["cpu_per_sim_second"]) if exact else "–",
                    g3(r["rms_position_error"]), g3(r["max_position_error"]), g3(r["energy_error"]),
                    f"{collisions:,}", "; ".join(notes)])
    return make_tables.md_table(["code", "dt (s)", "CPU s / sim s (median)", "rounds: range (count)", "cost ÷ exact",
                                 "RMS position error at H", "max position error at H", "energy error at T",
                                 "collisions (Box2D: contacts begun)", "notes"], out)


def walled_target(rows):
    """Exact mode against Box2D at dt = 1/60: how much cheaper (the ratio of each round's pair, their
    median and range) and how much more accurate."""
    exact = next((r for r in rows if r["mode"] == "exact"), None)
    box = next((r for r in rows if r["mode"] == "box2d" and round(1 / r["dt"]) == 60), None)
    if not exact or not box:
        return None
    pairs = [box["costs"][k] / exact["costs"][k] for k in sorted(box["costs"]) if k in exact["costs"]]
    speed = statistics.median(pairs)
    acc = {k: max(box[k], ROUND_OFF) / max(exact[k], ROUND_OFF) for k in ("energy_error", "rms_position_error")}
    ok = speed >= SPEED_TARGET and min(acc.values()) >= ACCURACY_TARGET
    return (f"- N = {make_tables.n_label(exact['N'])}: exact mode **{speed:.0f}×** cheaper than Box2D at dt = 1/60 "
            f"(median of {len(pairs)} interleaved rounds, range {min(pairs):.0f}–{max(pairs):.0f}), "
            f"its energy error **{acc['energy_error']:.1e}×** and its RMS position error at H "
            f"**{acc['rms_position_error']:.1e}×** smaller — " + ("met" if ok else "not met") +
            (f" (every round ≥ {SPEED_TARGET:g}×)" if min(pairs) >= SPEED_TARGET else ""))


def walled_svg(groups, path):
    """Two rows of panels (position error at H, energy error at T), one column per scene."""
    pw, ph = 380, 440
    svg = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{pw * len(groups) + 40}" height="{2 * ph + 40}" '
           f'font-family="sans-serif" font-size="12">',
           f'<rect width="{pw * len(groups) + 40}" height="{2 * ph + 40}" fill="white"/>',
           '<text x="14" y="18" font-size="14">the walled gas: turtlegas (exact mode ◆, step mode) and Box2D,</text>',
           '<text x="14" y="35" font-size="14">error against CPU seconds per simulated second (log-log), by dt; '
           'an error of 0 sits on the bottom edge</text>']
    x_range = cost_range([r for g in groups for r in g])
    for col, g in enumerate(groups):
        n = make_tables.n_label(g[0]["N"])
        for row, (key, what, y_label) in enumerate(
                [("rms_position_error", f"RMS position error at {g[0]['horizon']:.3g} s", "position error (units)"),
                 ("energy_error", f"energy error at {g[0]['sim_seconds']:.3g} s", "relative energy error")]):
            lines = [(WALLED_NAMES[mode], WALLED_COLOURS[mode],
                      [(r["cpu_per_sim_second"], r[key], dt_label(r)) for r in g if r["mode"] == mode], True)
                     for mode in ("step", "box2d")]
            diamonds = [("exact", WALLED_COLOURS["exact"],
                         [(r["cpu_per_sim_second"], r[key]) for r in g if r["mode"] == "exact"], True)]
            svg += draw_panel(2 * col + row, col * pw + 30, row * ph + 10, pw, ph, x_range, f"N = {n}: {what}",
                              y_label, lines, diamonds, False, legend_mid_right=True)
    write_svg(svg, path)


def power(e):
    """10^e as SVG text, the exponent raised."""
    return f'10<tspan dy="-5" font-size="9">{e}</tspan>'


def svg_plot(rows, path):
    """Log-log, one panel per entry of PANELS: error against CPU seconds per simulated second."""
    pw, ph = 380, 440               # one panel, margins included
    panels = []
    for title, scene, series, guide in PANELS:
        chosen = scene_rows(rows, scene)
        steps = [r for r in chosen if r["mode"] == "step"]
        exact = [r for r in chosen if r["mode"] == "exact"]
        lines = [(f"step: {label}", colour, [(r["cpu_per_sim_second"], r[key], dt_label(r)) for r in steps], s == 0)
                 for s, (key, label, colour) in enumerate(series)]
        diamonds = [(f"exact: {label}", colour, [(r["cpu_per_sim_second"], r[key]) for r in exact], s == 0)
                    for s, (key, label, colour) in enumerate(series)]
        panels.append((title, "position error (units)" if "position" in title else "relative energy error",
                       lines, diamonds, guide))
    svg = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{pw * len(PANELS) + 40}" height="{ph + 30}" '
           f'font-family="sans-serif" font-size="12">',
           f'<rect width="{pw * len(PANELS) + 40}" height="{ph + 30}" fill="white"/>',
           '<text x="14" y="22" font-size="15">turtlegas: what accuracy costs — error against CPU seconds per '
           'simulated second (log-log); step mode labelled by dt, exact mode ◆</text>']
    x_range = cost_range(rows)
    for k, panel in enumerate(panels):
        svg += draw_panel(k, k * pw + 30, 0, pw, ph, x_range, *panel)
    write_svg(svg, path)


def cost_range(rows):
    xs = [r["cpu_per_sim_second"] for r in rows if r["cpu_per_sim_second"] > 0]
    return math.floor(math.log10(min(xs))), math.ceil(math.log10(max(xs)))


def write_svg(svg, path):
    svg.append("</svg>")
    pathlib.Path(path).parent.mkdir(parents=True, exist_ok=True)
    pathlib.Path(path).write_text("\n".join(svg) + "\n")


def draw_panel(k, ox, oy, pw, ph, x_range, title, y_label, lines, diamonds, guide, legend_mid_right=False):
    """One log-log panel at (ox, oy), pw by ph with its margins: lines are (label, colour,
    [(cost, error, point label)], whether to print the point labels), diamonds (label, colour,
    [(cost, error)], whether to print the label beside them); guide draws a line of slope -1
    through the first line's last point. The legend goes in the bottom right corner, or half way up
    the right edge. Returns the SVG elements."""
    left, right, top, bottom = 64, 14, 58, 52
    x0, x1 = x_range
    # Zero errors cannot sit on a log axis; they occur only where round-off cancels exactly, and
    # a floor keeps them drawable.
    vals = [max(y, 1e-17) for *_, pts, _ in lines + diamonds for _, y, *_ in pts]
    if not vals:
        return []
    y0, y1 = math.floor(math.log10(min(vals))), math.ceil(math.log10(max(vals)))
    if y1 == y0:
        y1 += 1
    px0, px1, py0, py1 = ox + left, ox + pw - right, oy + top + 30, oy + ph + 30 - bottom

    def px(x):
        return px0 + (math.log10(x) - x0) / (x1 - x0) * (px1 - px0)

    def py(v):
        return py1 - (math.log10(max(v, 1e-17)) - y0) / (y1 - y0) * (py1 - py0)

    svg = [f'<text x="{(px0 + px1) / 2:.0f}" y="{oy + top + 18}" text-anchor="middle" font-size="13">{title}</text>']
    step_e = 1 if y1 - y0 <= 10 else 2  # a label every decade, or every other one on tall axes
    for e in range(y0, y1 + 1):
        y = py(10.0**e)
        svg.append(f'<line x1="{px0}" y1="{y:.1f}" x2="{px1}" y2="{y:.1f}" stroke="#ddd"/>')
        if (e - y0) % step_e == 0:
            svg.append(f'<text x="{px0 - 6}" y="{y + 4:.1f}" text-anchor="end">{power(e)}</text>')
    svg += make_tables.x_decades(x0, x1, px, py0, py1, "#ddd", power)
    svg.append(f'<rect x="{px0}" y="{py0}" width="{px1 - px0}" height="{py1 - py0}" fill="none" stroke="#333"/>')
    svg.append(f'<text x="{(px0 + px1) / 2:.0f}" y="{py1 + 40}" text-anchor="middle">'
               'CPU seconds per simulated second</text>')
    svg.append(f'<text transform="translate({ox + 16},{(py0 + py1) / 2:.0f}) rotate(-90)" '
               f'text-anchor="middle">{y_label}</text>')
    if guide and lines and lines[0][2]:
        xl, yl, _ = lines[0][2][-1]
        xa, xb = 10.0**x0, 10.0**x1
        ya, yb = yl * xl / xa, yl * xl / xb
        svg.append(f'<clipPath id="clip{k}"><rect x="{px0}" y="{py0}" width="{px1 - px0}" height="{py1 - py0}"/>'
                   '</clipPath>')
        svg.append(f'<line x1="{px(xa):.1f}" y1="{py(ya):.1f}" x2="{px(xb):.1f}" y2="{py(yb):.1f}" '
                   f'stroke="#999" stroke-dasharray="3,4" clip-path="url(#clip{k})"/>')
    # Each line, then the diamonds of the same index (exact mode's point of the same error).
    for s in range(max(len(lines), len(diamonds))):
        if s < len(lines):
            _, colour, pts, labelled = lines[s]
            if pts:
                d = " ".join(f"{px(x):.1f},{py(y):.1f}" for x, y, _ in pts)
                svg.append(f'<polyline points="{d}" fill="none" stroke="{colour}" stroke-width="2"/>')
            for x, y, lab in pts:
                svg.append(f'<circle cx="{px(x):.1f}" cy="{py(y):.1f}" r="3.5" fill="{colour}"/>')
                if labelled:
                    svg.append(f'<text x="{px(x) + 6:.1f}" y="{py(y) - 6:.1f}" font-size="10" fill="#333">{lab}</text>')
        if s < len(diamonds):
            _, colour, pts, labelled = diamonds[s]
            for x, y in pts:
                x, y = px(x), py(y)
                svg.append(f'<path d="M{x:.1f},{y - 7:.1f} L{x + 7:.1f},{y:.1f} L{x:.1f},{y + 7:.1f} '
                           f'L{x - 7:.1f},{y:.1f} Z" fill="{colour}" stroke="#000" stroke-width="1"/>')
                if labelled:
                    svg.append(f'<text x="{x + 10:.1f}" y="{y + 4:.1f}" font-size="11" fill="#333">exact</text>')
    # Legend in a corner the data leave empty: in the report's own panels the bottom right (step
    # mode's errors sit high, as its cheap runs are inaccurate; exact mode's at the bottom left).
    entries = [(label, colour, "line") for label, colour, *_ in lines]
    entries += [(label, colour, "diamond") for label, colour, *_ in diamonds]
    if guide:
        entries.append(("error ∝ dt (slope −1)", "#999", "guide"))
    # Beside Box2D the errors sit at the top (Box2D) and the bottom (turtlegas) and the costs span
    # the width: the middle of the right edge is what they leave empty.
    lx, ly = ((px1 - 150, (py0 + py1) / 2 - 9 * len(entries) + 12) if legend_mid_right
              else (px1 - 150, py1 - 18 * len(entries) + 4))
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
    return svg


def main():
    report = make_tables.Report(__doc__.splitlines()[0], options=("--svg-box2d",))
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
    charged = scene_rows(rows, "charged")
    if charged:
        c = charged[0]
        parts += [f"### Charged balls in B: step mode's rotation kick against exact circles (`{c['world_file']}`: "
                  f"N = {c['N']}, T = {c['sim_seconds']:.3g} s; positions against exact mode's)", "",
                  charged_table(charged), ""]
    if report.args.svg and (ballistic or gas):
        svg_plot([r for r in rows if r["scene"] in ("ballistic", "gas")], report.args.svg)
        parts += [f"![error against CPU seconds per simulated second]({report.rel(report.args.svg)})", ""]
    groups = walled_groups(rows)
    for g in groups:
        e = g[0]
        parts += [f"### The walled gas beside Box2D (`{e['world_file']}`: N = {e['N']}, φ = {e['phi']:.2f}; "
                  f"positions at H = {e['horizon']:.3g} s, energy at T = {e['sim_seconds']:.3g} s)", "",
                  walled_table(g), ""]
    targets = [t for t in (walled_target(g) for g in groups) if t]
    if targets:
        parts += [f"Target: exact mode ≥ {SPEED_TARGET:g}× cheaper than Box2D at dt = 1/60 and ≥ {ACCURACY_TARGET:.0e}× "
                  "more accurate (energy error and RMS position error; errors below 1e-16 count as 1e-16):", "",
                  *targets, ""]
    if report.args.svg_box2d and groups:
        walled_svg(groups, report.args.svg_box2d)
        parts += [f"![the walled gas: error against cost, turtlegas and Box2D]({report.rel(report.args.svg_box2d)})", ""]
    report.publish(BEGIN, END, parts)

if __name__ == "__main__":
    main()
