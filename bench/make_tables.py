#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Turns gas_bench results (JSON lines) into the tables of docs/performance.md and an SVG plot.

    python3 bench/make_tables.py RESULTS.jsonl [--machine MACHINE.json] [--doc docs/performance.md]
                                 [--svg docs/bench/ns_per_collision.svg]

The tables replace whatever lies between the GENERATED markers in the doc; without --doc they go
to standard output. Plain python: no matplotlib on the benchmark machine, so the plot is written
as SVG by hand.
"""

import argparse
import json
import math
import os
import pathlib
import sys

BEGIN = "<!-- BEGIN GENERATED: bench/make_tables.py -->"
END = "<!-- END GENERATED: bench/make_tables.py -->"


def load(path):
    rows = []
    for line in pathlib.Path(path).read_text().splitlines():
        line = line.strip()
        if line:
            rows.append(json.loads(line))
    return rows


def phi_key(row):
    return round(row["phi"], 3)


def n_label(n):
    e = round(math.log10(n))
    return f"10^{e}" if 10**e == n else f"{n:,}"


def si(x, digits=3):
    """3.21 M, 456 k, 12.3: a compact number for a table cell."""
    if x is None:
        return "–"
    for div, suffix in ((1e9, " G"), (1e6, " M"), (1e3, " k")):
        if abs(x) >= div:
            return f"{x / div:.{digits}g}{suffix}"
    return f"{x:.{digits}g}"


def fixed(x, places):
    return "–" if x is None else f"{x:.{places}f}"


def md_table(header, rows):
    out = ["| " + " | ".join(header) + " |", "|" + "|".join("---:" for _ in header) + "|"]
    out += ["| " + " | ".join(r) + " |" for r in rows]
    return "\n".join(out)


def by_mode(rows, mode):
    chosen = [r for r in rows if r["mode"] == mode]
    return sorted(chosen, key=lambda r: (phi_key(r), r["N"]))


def reference(rows, key):
    """Per phi, the value of `key` at the smallest N (10^3 in the standard set)."""
    ref = {}
    for r in sorted(rows, key=lambda r: r["N"]):
        ref.setdefault(phi_key(r), r[key])
    return ref


def flag(r):
    notes = []
    if r.get("truncated"):
        notes.append("truncated by --max-wall")
    cpu, wall = r.get("cpu_seconds"), r["wall_seconds"]
    if cpu is not None and wall > 0 and cpu / wall < 0.9:
        notes.append(f"cpu/wall {cpu / wall:.2f}: core shared")
    return "; ".join(notes)


def exact_tables(rows):
    ref = reference(rows, "ns_per_collision")
    main = []
    for r in rows:
        c = r["collisions"]
        main.append([
            n_label(r["N"]), f"{r['phi']:.2f}", si(r["collisions_per_second"]), fixed(r["ns_per_event"], 0),
            fixed(r["ns_per_collision"], 0), fixed(r["ns_per_collision"] / ref[phi_key(r)], 2),
            f"{r['wall_per_sim_second']:.3g}", fixed(r["bytes_per_ball"], 0),
            fixed(r.get("engine_bytes_per_ball"), 0), fixed(r["cell_crossings"] / c if c else None, 2),
        ])
    detail = []
    for r in rows:
        c = r["collisions"]
        detail.append([
            n_label(r["N"]), f"{r['phi']:.2f}", si(c), fixed(c / r["N"], 1), f"{r['sim_seconds']:.4g}",
            fixed(r["wall_seconds"], 2), fixed(r.get("cpu_seconds"), 2), si(r["events"]),
            fixed(r["stale"] / c if c else None, 2), f"{r['cell_size']:.3g}", fixed(r["load_seconds"], 2),
            fixed(r.get("construct_seconds"), 2), f"{r['energy_drift']:.1e}", f"{r['max_contact_overlap']:.1e}",
            flag(r) or "",
        ])
    return (
        md_table(["N", "φ", "collisions/s", "ns/event", "ns/collision", "ns/collision ÷ N=10^3",
                  "wall s / sim s", "bytes/ball (process)", "bytes/ball (engine)", "cell crossings / collision"],
                 main),
        md_table(["N", "φ", "collisions", "per ball", "sim s", "wall s", "cpu s", "events", "stale / collision",
                  "cell", "load s", "build s", "energy drift", "max contact overlap", "notes"], detail),
    )


def step_table(rows):
    ref = reference(rows, "ball_steps_per_second")
    out = []
    for r in rows:
        bs = r["ball_steps_per_second"]
        c = r["collisions"]
        out.append([
            n_label(r["N"]), f"{r['phi']:.2f}", si(bs), fixed(1e9 / bs if bs else None, 1),
            fixed(ref[phi_key(r)] / bs if bs else None, 2), f"{r['steps']:,}", si(r["collisions_per_second"]),
            fixed(r["ns_per_collision"] if c else None, 0), f"{r['wall_per_sim_second']:.3g}",
            fixed(r["bytes_per_ball"], 0), f"{r['energy_drift']:.1e}", flag(r) or "",
        ])
    return md_table(["N", "φ", "ball-steps/s", "ns/ball-step", "ns/ball-step ÷ N=10^3", "steps", "collisions/s",
                     "ns/collision", "wall s / sim s", "bytes/ball (process)", "energy drift", "notes"], out)


def targets(exact):
    lines = []
    for r in exact:
        if r["N"] == 10_000 and abs(r["phi"] - 0.05) < 1e-3:
            ok = r["collisions_per_second"] >= 5e6
            lines.append(f"- ≥ 5 M collisions/s at N = 10^4, φ = 0.05: **{si(r['collisions_per_second'])}** — "
                         + ("met" if ok else "not met"))
    ref = reference(exact, "ns_per_collision")
    for phi in sorted(ref):
        series = [r for r in exact if phi_key(r) == phi]
        worst = max(r["ns_per_collision"] / ref[phi] for r in series)
        top = max(series, key=lambda r: r["N"])
        lines.append(f"- cost per collision within 1.5× from N = 10^3 to {n_label(top['N'])} at φ = {phi:.2f}: "
                     f"worst ratio **{worst:.2f}** — " + ("met" if worst <= 1.5 else "not met"))
    for key, what in (("bytes_per_ball", "whole process, loader included"),
                      ("engine_bytes_per_ball", "engine alone, while running")):
        vals = [r[key] for r in exact if r.get(key) is not None and r["N"] >= 100_000]
        if vals:
            lines.append(f"- ≤ 200 bytes per ball ({what}, N ≥ 10^5): worst **{max(vals):.0f}** — "
                         + ("met" if max(vals) <= 200 else "not met"))
    return "\n".join(lines)


def machine_text(machine):
    if not machine:
        return ""
    keys = [("cpu", "CPU"), ("cores", "cores"), ("compiler", "compiler"), ("flags", "build"),
            ("kernel", "kernel"), ("commit", "source"), ("date", "date (UTC)"), ("loadavg", "load average before the run")]
    return "\n".join(f"- {label}: {machine[k]}" for k, label in keys if machine.get(k))


def svg_plot(rows, path):
    """ns per collision against N, log-log, one line per (mode, phi)."""
    series = {}
    for r in rows:
        if r["collisions"] > 0:
            series.setdefault((r["mode"], phi_key(r)), []).append((r["N"], r["ns_per_collision"]))
    colours = {("exact", 0.05): "#1f77b4", ("exact", 0.3): "#d62728", ("step", 0.05): "#2ca02c", ("step", 0.3): "#ff7f0e"}
    lines = [(f"{key[0]}, φ = {key[1]:g}", colours.get(key, "#555"), key[0] == "step", pts)
             for key, pts in sorted(series.items())]
    line_plot(path, "turtlegas: wall-clock ns per collision (log-log)", "ns per collision", lines)


def line_plot(path, title, y_label, lines, legend_width=190):
    """A log-log plot against N, written as SVG by hand: lines are (label, colour, dashed, [(N, y)]),
    drawn and listed in the legend in that order."""
    lines = [line for line in lines if line[3]]
    if not lines:
        return
    width, height = 530 + legend_width, 460
    left, right, top, bottom = 80, legend_width, 40, 60
    ns_all = [v for *_, pts in lines for _, v in pts]
    n_all = [n for *_, pts in lines for n, _ in pts]
    x0, x1 = math.floor(math.log10(min(n_all))), math.ceil(math.log10(max(n_all)))
    y0, y1 = math.floor(math.log10(min(ns_all))), math.ceil(math.log10(max(ns_all)))
    if x1 == x0:
        x1 += 1
    if y1 == y0:
        y1 += 1

    def px(n):
        return left + (math.log10(n) - x0) / (x1 - x0) * (width - left - right)

    def py(v):
        return height - bottom - (math.log10(v) - y0) / (y1 - y0) * (height - top - bottom)

    svg = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" '
           f'font-family="sans-serif" font-size="12">',
           f'<rect width="{width}" height="{height}" fill="white"/>',
           f'<text x="{left}" y="22" font-size="14">{title}</text>']
    for e in range(y0, y1 + 1):
        for m in (1, 2, 5):
            v = m * 10**e
            if v > 10**y1:
                break
            y = py(v)
            svg.append(f'<line x1="{left}" y1="{y:.1f}" x2="{width - right}" y2="{y:.1f}" '
                       f'stroke="{"#ccc" if m == 1 else "#eee"}"/>')
            svg.append(f'<text x="{left - 6}" y="{y + 4:.1f}" text-anchor="end">{si(v)}</text>')
    svg += x_decades(x0, x1, px, top, height - bottom, "#ccc", lambda e: f"10^{e}")
    svg.append(f'<text x="{(left + width - right) / 2:.0f}" y="{height - 15}" text-anchor="middle">N (balls)</text>')
    svg.append(f'<text transform="translate(18,{(top + height - bottom) / 2:.0f}) rotate(-90)" '
               f'text-anchor="middle">{y_label}</text>')
    svg.append(f'<rect x="{left}" y="{top}" width="{width - left - right}" height="{height - top - bottom}" '
               f'fill="none" stroke="#333"/>')
    for k, (label, colour, dashed, pts) in enumerate(lines):
        pts = sorted(pts)
        dash = ' stroke-dasharray="6,4"' if dashed else ""
        d = " ".join(f"{px(n):.1f},{py(v):.1f}" for n, v in pts)
        svg.append(f'<polyline points="{d}" fill="none" stroke="{colour}" stroke-width="2"{dash}/>')
        for n, v in pts:
            svg.append(f'<circle cx="{px(n):.1f}" cy="{py(v):.1f}" r="3.5" fill="{colour}"/>')
        ly = top + 10 + 22 * k
        lx = width - right + 14
        svg.append(f'<line x1="{lx}" y1="{ly}" x2="{lx + 28}" y2="{ly}" stroke="{colour}" stroke-width="2"{dash}/>')
        svg.append(f'<text x="{lx + 34}" y="{ly + 4}">{label}</text>')
    svg.append("</svg>")
    pathlib.Path(path).parent.mkdir(parents=True, exist_ok=True)
    pathlib.Path(path).write_text("\n".join(svg) + "\n")


def x_decades(x0, x1, px, y_top, y_bottom, stroke, label):
    """A vertical grid line and its label below the axis at each decade 10^x0 ... 10^x1 of a log
    axis mapped by px; label(e) is the text for 10^e."""
    out = []
    for e in range(x0, x1 + 1):
        x = px(10.0**e)
        out.append(f'<line x1="{x:.1f}" y1="{y_top}" x2="{x:.1f}" y2="{y_bottom}" stroke="{stroke}"/>')
        out.append(f'<text x="{x:.1f}" y="{y_bottom + 18}" text-anchor="middle">{label(e)}</text>')
    return out


class Report:
    """The command line the report scripts share (RESULTS [--machine M] [--doc D] [--svg S]), the
    results and machine files read, and the header and placement of the generated text."""

    def __init__(self, description, options=()):
        """options: more optional arguments (names such as "--svg-box2d") a script takes."""
        ap = argparse.ArgumentParser(description=description)
        ap.add_argument("results")
        ap.add_argument("--machine")
        ap.add_argument("--doc")
        ap.add_argument("--svg")
        for name in options:
            ap.add_argument(name)
        self.args = ap.parse_args()
        self.rows = load(self.args.results)
        self.machine = json.loads(pathlib.Path(self.args.machine).read_text()) if self.args.machine else {}
        self.doc_dir = pathlib.Path(self.args.doc).parent if self.args.doc else pathlib.Path(".")

    def rel(self, path):
        """A path as the doc links it."""
        return os.path.relpath(path, self.doc_dir)

    def header(self):
        """Lines naming the results and machine files, then the machine's description."""
        a = self.args
        parts = [f"Results: [`{self.rel(a.results)}`]({self.rel(a.results)})"
                 + (f", machine: [`{self.rel(a.machine)}`]({self.rel(a.machine)})" if a.machine else "") + ".", ""]
        if self.machine:
            parts += [machine_text(self.machine), ""]
        return parts

    def publish(self, begin, end, parts):
        """Writes the text between the doc's markers, or to stdout without --doc."""
        text = "\n".join(parts)
        if self.args.doc:
            splice(self.args.doc, begin, end, text)
        else:
            sys.stdout.write(text)


def main():
    report = Report(__doc__.splitlines()[0])
    rows = report.rows
    exact, step = by_mode(rows, "exact"), by_mode(rows, "step")
    exact_main, exact_detail = exact_tables(exact)
    parts = report.header()
    if exact:
        parts += ["### Exact mode", "", exact_main, "", "Run details:", "", exact_detail, ""]
    if step:
        parts += ["### Step mode (dt = 1/30 s)", "", step_table(step), ""]
    if exact:
        parts += ["### Targets", "", targets(exact), ""]
    if report.args.svg:
        svg_plot(rows, report.args.svg)
        parts += [f"![ns per collision against N]({report.rel(report.args.svg)})", ""]
    report.publish(BEGIN, END, parts)


def splice(doc_path, begin, end, text):
    """Replaces what lies between the begin and end markers of the doc with text."""
    doc = pathlib.Path(doc_path)
    old = doc.read_text() if doc.exists() else ""
    if begin in old and end in old:
        head, rest = old.split(begin, 1)
        _, tail = rest.split(end, 1)
        doc.write_text(head + begin + "\n" + text + end + tail)
    else:
        sys.exit(f"{doc}: no '{begin}' ... '{end}' markers; add them where the tables belong")


if __name__ == "__main__":
    main()
