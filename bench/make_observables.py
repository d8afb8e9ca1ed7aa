#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Runs the gas-observables scenes through `turtlegas run --observe` and writes docs/observables.md
with its plots: measured against theory (Rayleigh, Henderson's equation of state, Enskog's collision
rate, the barometric column). About a minute on one core.

    python3 bench/make_observables.py [--turtlegas build/release/turtlegas] [--doc docs/observables.md]
                                      [--images docs/images] [--quick]

The scenes are written to a scratch directory as world files (discs on a jittered lattice, every
speed 1 in a random direction, seeded), so anyone can rerun one with the command printed in the
report. Plain python, SVG by hand, like make_accuracy.py (make_tables.py's table helper).
"""

import argparse
import json
import math
import os
import pathlib
import random
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
sys.dont_write_bytecode = True  # no __pycache__ in bench/
import make_tables  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parent.parent


def henderson_z(eta):
    return (1 + eta * eta / 8) / (1 - eta) ** 2


def henderson_g(eta):
    return (1 - 7 * eta / 16) / (1 - eta) ** 2


def lattice_gas(n, eta, radius, seed, periodic, width=None, height=None):
    """n discs of radius r at area fraction eta on a jittered square lattice (never overlapping),
    speed 1 in random directions: the C++ tests' random_gas."""
    rng = random.Random(seed)
    side = math.sqrt(n * math.pi * radius * radius / eta)
    w, h = width or side, height or side
    per_row = math.ceil(math.sqrt(n * w / h))
    rows = math.ceil(n / per_row)
    px, py = w / per_row, h / rows
    slack = max(0.0, min(px, py) - 2 * radius) * 0.49
    balls = []
    for i in range(n):
        cx, cy = (i % per_row + 0.5) * px, (i // per_row + 0.5) * py
        a = 2 * math.pi * rng.random()
        balls.append({"id": f"g{i}", "pos": [cx + (2 * rng.random() - 1) * slack, cy + (2 * rng.random() - 1) * slack],
                      "vel": [math.cos(a), math.sin(a)], "radius": radius, "mass": 1})
    return {"format": "turtlegas-world/1", "name": f"hard discs eta={eta:g}", "seed": seed,
            "arena": {"width": w, "height": h, "boundary": "periodic" if periodic else "walls"}, "balls": balls}


def staggered_square_gas(n, eta, seed):
    """n discs (r = 1) at area fraction eta in a square periodic box on the staggered lattice
    rows x cols = n with the widest gap (dense enough for eta = 0.72 at n = 72): the C++ test's
    staggered_square_gas."""
    rng = random.Random(seed)
    side = math.sqrt(n * math.pi / eta)
    best = max((min(side / (n // r), math.hypot(side / (n // r) / 2, side / r), 2 * side / r), r)
               for r in range(2, n + 1, 2) if n % r == 0)
    assert best[0] > 2, "no staggered lattice fits"
    rows = best[1]
    cols = n // rows
    px, py = side / cols, side / rows
    balls = []
    for i in range(n):
        row, col = divmod(i, cols)
        a = 2 * math.pi * rng.random()
        balls.append({"id": f"g{i}", "pos": [(col + 0.25 + 0.5 * (row % 2)) * px, (row + 0.5) * py],
                      "vel": [math.cos(a), math.sin(a)], "radius": 1, "mass": 1})
    return {"format": "turtlegas-world/1", "name": f"{n} hard discs eta={eta:g}", "seed": seed,
            "arena": {"width": side, "height": side, "boundary": "periodic"}, "balls": balls}


# Li, Nishikawa, Hoellmer, Maggs, Krauth, J. Chem. Phys. 157, 234111 (2022), event-chain Monte Carlo,
# N = 72, square periodic box: beta P (2 sigma)^2 (sigma the radius) and its error, by packing
# fraction (jellyfysh/HistoricDisks, DigitizedData/ThisWork.csv).
LI_2022_N72_SQUARE = {0.650: (6.901074, 0.000071), 0.660: (7.383221, 0.000087), 0.670: (7.85637, 0.00011),
                      0.680: (8.23631, 0.00034), 0.690: (8.41814, 0.00038), 0.700: (8.55170, 0.00059),
                      0.710: (8.88876, 0.00051), 0.720: (9.41867, 0.00050)}


def run(turtlegas, world, path, until, observe):
    path.write_text(json.dumps(world))
    out = path.with_suffix(".obs.json")
    opts = []
    for k, v in observe.items():
        opts += [f"--observe-{k}", f"{v:.6g}" if isinstance(v, float) else str(v)]
    subprocess.run([turtlegas, "run", str(path), "--until", repr(until), "--observe", str(out)] + opts, check=True)
    shown = ["turtlegas", "run", path.name, "--until", f"{until:.6g}", "--observe", "obs.json"] + opts
    return json.loads(out.read_text()), " ".join(shown)


# ---- plots: linear axes, SVG by hand ----------------------------------------------------------

def esc(text):
    return text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")


def panel(title, xlabel, ylabel, series, path, logy=False, width=560, height=380):
    """series: (label, colour, points [(x, y, err or None)], style 'line' | 'points')."""
    title, xlabel, ylabel = esc(title), esc(xlabel), esc(ylabel)
    series = [(esc(label), colour, pts, style) for label, colour, pts, style in series]
    left, right, top, bottom = 70, 20, 40, 50
    xs = [p[0] for _, _, pts, _ in series for p in pts]
    ys = [p[1] + (p[2] or 0) for _, _, pts, _ in series for p in pts] + \
         [p[1] - (p[2] or 0) for _, _, pts, _ in series for p in pts]
    if logy:
        ys = [y for y in ys if y > 0]
    x0, x1 = min(xs), max(xs)
    y0, y1 = (min(ys), max(ys))
    if logy:
        y0, y1 = math.log10(y0), math.log10(y1)
    else:
        y0 = min(0.0, y0)
    pad = 0.05 * (y1 - y0 or 1)
    y0, y1 = y0 - (pad if logy else 0), y1 + pad
    px0, px1, py0, py1 = left, width - right, top, height - bottom

    def X(x):
        return px0 + (x - x0) / (x1 - x0) * (px1 - px0)

    def Y(y):
        v = math.log10(max(y, 1e-300)) if logy else y
        return py1 - (v - y0) / (y1 - y0) * (py1 - py0)

    svg = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" font-family="sans-serif" '
           'font-size="11">', '<rect width="100%" height="100%" fill="white"/>',
           f'<text x="{width / 2}" y="20" text-anchor="middle" font-size="13">{title}</text>',
           f'<rect x="{px0}" y="{py0}" width="{px1 - px0}" height="{py1 - py0}" fill="none" stroke="#333"/>']
    for k in range(6):
        xv = x0 + (x1 - x0) * k / 5
        svg.append(f'<text x="{X(xv):.1f}" y="{py1 + 16}" text-anchor="middle">{xv:.3g}</text>')
        yv = y0 + (y1 - y0) * k / 5
        lab = f"{10 ** yv:.3g}" if logy else f"{yv:.3g}"
        yy = py1 - (yv - y0) / (y1 - y0) * (py1 - py0)
        svg.append(f'<line x1="{px0}" y1="{yy:.1f}" x2="{px1}" y2="{yy:.1f}" stroke="#eee"/>')
        svg.append(f'<text x="{px0 - 6}" y="{yy + 4:.1f}" text-anchor="end">{lab}</text>')
    svg.append(f'<text x="{(px0 + px1) / 2}" y="{height - 12}" text-anchor="middle">{xlabel}</text>')
    svg.append(f'<text transform="translate(16,{(py0 + py1) / 2}) rotate(-90)" text-anchor="middle">{ylabel}</text>')
    for label, colour, pts, style in series:
        if style == "line":
            d = " ".join(f"{X(x):.1f},{Y(y):.1f}" for x, y, _ in pts)
            svg.append(f'<polyline points="{d}" fill="none" stroke="{colour}" stroke-width="2"/>')
        else:
            for x, y, e in pts:
                if e:
                    svg.append(f'<line x1="{X(x):.1f}" y1="{Y(y - e):.1f}" x2="{X(x):.1f}" y2="{Y(y + e):.1f}" '
                               f'stroke="{colour}"/>')
                svg.append(f'<circle cx="{X(x):.1f}" cy="{Y(y):.1f}" r="3" fill="{colour}"/>')
    for j, (label, colour, _, style) in enumerate(series):
        ly = py0 + 16 + 16 * j
        svg.append(f'<line x1="{px1 - 190}" y1="{ly}" x2="{px1 - 168}" y2="{ly}" stroke="{colour}" stroke-width="2"/>'
                   if style == "line" else f'<circle cx="{px1 - 179}" cy="{ly}" r="3" fill="{colour}"/>')
        svg.append(f'<text x="{px1 - 160}" y="{ly + 4}">{label}</text>')
    svg.append("</svg>")
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("\n".join(svg) + "\n")


def maxwell3_cdf(v, mean_sq):
    a = math.sqrt(mean_sq / 3)
    return math.erf(v / (a * math.sqrt(2))) - math.sqrt(2 / math.pi) * v / a * math.exp(-v * v / (2 * a * a))


def column(per_width, mg_kT, r, H, with_eos, steps=20000):
    """Density of hard discs in a column under gravity, local-density approximation with
    Henderson's p(n) (the C++ test's column_density); returns (heights, densities)."""
    a = math.pi * r * r

    def slope(n):
        if not with_eos:
            return -n * mg_kT
        eta = n * a
        dz = (eta / 4 * (1 - eta) + 2 * (1 + eta * eta / 8)) / (1 - eta) ** 3
        return -n * mg_kT / (henderson_z(eta) + eta * dz)

    h = (H - 2 * r) / steps

    def integrate(n0, keep):
        n, total, ys, ns = n0, 0.0, [r], [n0]
        for s in range(steps):
            k1 = slope(n)
            k2 = slope(n + h / 2 * k1)
            k3 = slope(n + h / 2 * k2)
            k4 = slope(n + h * k3)
            nxt = n + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
            total += h / 2 * (n + nxt)
            n = nxt
            if keep:
                ys.append(r + (s + 1) * h)
                ns.append(n)
        return total, ys, ns

    lo, hi = 0.0, 1 / a
    for _ in range(100):
        mid = (lo + hi) / 2
        if integrate(mid, False)[0] < per_width:
            lo = mid
        else:
            hi = mid
    _, ys, ns = integrate((lo + hi) / 2, True)
    return ys, ns


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--turtlegas", default=str(ROOT / "build/release/turtlegas"))
    ap.add_argument("--doc", default=str(ROOT / "docs/observables.md"))
    ap.add_argument("--images", default=str(ROOT / "docs/images"))
    ap.add_argument("--quick", action="store_true", help="smaller runs: checks the script, leaves docs/ alone")
    args = ap.parse_args()
    images = pathlib.Path(args.images)
    scale = 0.2 if args.quick else 1.0
    out = []
    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(tmp)
        # 1. Relaxation to Rayleigh.
        obs, cmd = run(args.turtlegas, lattice_gas(2000, 0.1, 1.0, 14, True), tmp / "rayleigh.json", 400.0,
                       {"from": 100, "window": 30, "samples": 6})
        h = obs["speed_histogram"]
        kT = obs["summary"]["kT"]["mean"]
        mids = [(a + b) / 2 for a, b in zip(h["edges"], h["edges"][1:])]
        edges = h["edges"]
        m3 = [(maxwell3_cdf(b, 2 * kT) - maxwell3_cdf(a, 2 * kT)) / (b - a) for a, b in zip(edges, edges[1:])]
        chi2 = [(f - r) ** 2 / e ** 2 for f, r, e in zip(h["density"], h["rayleigh"], h["error"]) if e > 0]
        chi2w = [(f - r) ** 2 / e ** 2 for f, r, e in zip(h["density"], m3, h["error"]) if e > 0]
        if not args.quick:
            panel("speeds after relaxation from one speed (2000 discs, eta = 0.1)", "speed", "density per unit speed",
                  [("measured (block errors)", "#d62728", list(zip(mids, h["density"], h["error"])), "points"),
                   ("2-D Maxwell (Rayleigh)", "#1f77b4", [(x, y, None) for x, y in zip(mids, h["rayleigh"])], "line"),
                   ("3-D Maxwell, same <v^2>", "#999999", [(x, y, None) for x, y in zip(mids, m3)], "line")],
                  images / "observables_rayleigh.svg")
        out.append("## Relaxation to the 2-D Maxwell–Boltzmann distribution\n")
        out.append(f"2000 discs (r = 1, m = 1), area fraction 0.1, periodic, every speed 1 at t = 0; observed from "
                   f"t = 100 s (about 19 collisions per ball) in 10 windows of 30 s, 6 samples each. "
                   f"`{cmd}`\n")
        out.append(make_tables.md_table(["", "value"], [
            ["kT (measured; 0.5 at the start, exactly conserved)", f"{kT:.6f}"],
            ["χ² per bin against Rayleigh (block errors)", f"{sum(chi2) / len(chi2):.2f} over {len(chi2)} bins"],
            ["χ² per bin against the 3-D Maxwell of the same ⟨v²⟩", f"{sum(chi2w) / len(chi2w):.1f}"],
        ]))
        out.append("\n![speed histogram](images/observables_rayleigh.svg)\n")

        # 2. Z and the collision rate against Henderson and Enskog.
        rows, zpts, zerr, ratio = [], [], [], []
        etas = [0.1, 0.2, 0.3, 0.4, 0.5, 0.6] if not args.quick else [0.1, 0.5]
        for k, eta in enumerate(etas):
            n = 1000
            world = lattice_gas(n, eta, 1.0, 1400 + k, True)
            area = world["arena"]["width"] * world["arena"]["height"]
            nu_h = 2 * (n / area) * 2.0 * henderson_g(eta) * math.sqrt(math.pi * 0.5)
            frm, win = 30 / nu_h, 20 * scale / nu_h
            obs, cmd = run(args.turtlegas, world, tmp / f"eos{k}.json", frm + 10 * win,
                           {"from": frm, "window": win, "samples": 4})
            s = obs["summary"]
            z, ze = s["Z_virial"]["mean"], s["Z_virial"]["error"]
            nu, nue = s["collision_rate"]["mean"], s["collision_rate"]["error"]
            T = s["kT"]["mean"]
            nu_e = 2 * (n / area) * 2.0 * henderson_g(eta) * math.sqrt(math.pi * T)
            rows.append([f"{eta:g}", f"{z:.4f} ± {ze:.4f}", f"{henderson_z(eta):.4f}", f"{(z / henderson_z(eta) - 1) * 100:+.2f} %",
                         f"{nu:.4f} ± {nue:.4f}", f"{nu_e:.4f}", f"{(nu / nu_e - 1) * 100:+.2f} %",
                         f"{(z - 1) / (2 * eta):.4f}", f"{henderson_g(eta):.4f}"])
            zpts.append((eta, z, ze))
            ratio.append((eta, nu / nu_e, nue / nu_e))
        curve = [(e / 100, henderson_z(e / 100), None) for e in range(0, 66)]
        if not args.quick:
            panel("hard discs: Z = PA/(NkT) from the virial", "area fraction eta", "Z",
                  [("measured, 1000 discs", "#d62728", zpts, "points"), ("Henderson", "#1f77b4", curve, "line")],
                  images / "observables_eos.svg")
        out.append("\n## Equation of state and collision rate of hard discs\n")
        out.append("1000 discs (r = 1), periodic, from a lattice at speed 1; observed after 30 collisions per ball "
                   "in 10 windows of 20 collisions per ball. Z from the virial (docs/physics.md, \"Gas observables\"); "
                   "Henderson's Z = (1 + η²/8)/(1 − η)²; Enskog's rate 2 n σ g(σ) √(π kT/m) with Henderson's "
                   "g(σ) = (1 − 7η/16)/(1 − η)²; the contact value measured is (Z − 1)/(2η). "
                   f"`{cmd}` (the last; each η its own world)\n")
        out.append(make_tables.md_table(["η", "Z measured", "Z Henderson", "Δ", "rate measured", "rate Enskog", "Δ",
                                         "g(σ) measured", "g(σ) Henderson"], rows))
        out.append("\n![equation of state](images/observables_eos.svg)\n")

        # 3. The barometric column.
        n, width, H, g = 1000, 400.0, 400.0, 2.5e-3
        world = lattice_gas(n, n * math.pi / (width * H), 1.0, 1414, False, width, H)
        world["effects"] = {"gravity": [0, -g]}
        obs, cmd = run(args.turtlegas, world, tmp / "column.json", 4000 + 12000 * scale,
                       {"from": 4000, "window": 1000 * scale, "samples": 20, "bins": 20})
        kT = obs["summary"]["kT"]["mean"]
        p = obs["density_profile"]
        mids = [(a + b) / 2 for a, b in zip(p["edges"], p["edges"][1:])]
        ys, ns = column(n / (width - 2), g / kT, 1.0, H, True)
        ysi, nsi = column(n / (width - 2), g / kT, 1.0, H, False)
        factor = (width - 2) / width
        walls = {w["id"]: w["pressure"] for w in obs["walls"]}
        floor, ceiling = walls["arena-bottom"], walls["arena-top"]
        if not args.quick:
            panel("density under gravity (1000 discs, 400 x 400, mgH/kT about 2)", "height y", "balls per unit area",
                  [("measured (block errors)", "#d62728", list(zip(mids, p["density"], p["error"])), "points"),
                   ("hydrostatics, Henderson p(n)", "#1f77b4", [(y, v * factor, None) for y, v in zip(ys[::200], ns[::200])], "line"),
                   ("ideal gas: exp(-m g y / kT)", "#999999", [(y, v * factor, None) for y, v in zip(ysi[::200], nsi[::200])], "line")],
                  images / "observables_barometric.svg", logy=True)
        out.append("\n## The barometric column\n")
        out.append(f"1000 discs (r = 1) in a 400 × 400 box with walls, g = 2.5e-3 downwards; observed from t = 4000 s "
                   f"in windows of 1000 s. kT = {kT:.5f}. The curve integrates dp/dy = −n m g with Henderson's "
                   f"p(n) = n kT Z(n π r²) over the centres' range [r, H − r]. `{cmd}`\n")
        load = (floor["mean"] - ceiling["mean"]) * width
        load_err = math.hypot(floor["error"], ceiling["error"]) * width
        out.append(f"The floor carries the gas's weight: (floor − ceiling pressure) × width = {load:.4g} ± {load_err:.2g}, "
                   f"N m g = {n * g:.4g}.\n")
        out.append("\n![barometric profile](images/observables_barometric.svg)\n")
        # 4. Near the liquid-hexatic transition, against published Monte Carlo.
        rows, pts_c, pts_v, ref_pts = [], [], [], []
        n = 72
        etas = sorted(LI_2022_N72_SQUARE) if not args.quick else [0.65, 0.70]
        for k, eta in enumerate(etas):
            world = staggered_square_gas(n, eta, 7200 + k)
            # From eta = 0.69 on the 72 discs switch between a liquid and an ordered state over
            # thousands of collisions per disc: windows five times longer, after a longer start.
            slow = eta >= 0.685
            frm, win = (20000.0, 20000.0 * scale) if slow else (200.0, 4000.0 * scale)
            obs, cmd = run(args.turtlegas, world, tmp / f"li{k}.json", frm + 10 * win,
                           {"from": frm, "window": win, "samples": 4})
            s = obs["summary"]
            to_bp = 4 * eta / math.pi  # Z -> beta P (2 sigma)^2
            zc, zce = s["Z_canonical"]["mean"], s["Z_canonical"]["error"]
            zv = s["Z_virial"]["mean"]
            ref, ref_e = LI_2022_N72_SQUARE[eta]
            dev = (zc * to_bp - ref) / math.hypot(zce * to_bp, ref_e)
            rows.append([f"{eta:.3f}", f"{ref:.5f} ± {ref_e:.5f}", f"{zc * to_bp:.5f} ± {zce * to_bp:.5f}",
                         f"{dev:+.1f}", f"{zv * to_bp:.5f}", f"{(zv * to_bp - ref) / math.hypot(zce * to_bp, ref_e):+.1f}"])
            pts_c.append((eta, zc * to_bp, zce * to_bp))
            pts_v.append((eta, zv * to_bp, zce * to_bp))
            ref_pts.append((eta, ref, ref_e))
        if not args.quick:
            panel("72 discs, square periodic box: beta P (2r)^2", "area fraction eta", "beta P (2r)^2",
                  [("Li et al. 2022, event-chain MC", "#1f77b4", ref_pts, "line"),
                   ("turtlegas, canonical (Z + 1/N)", "#d62728", pts_c, "points"),
                   ("turtlegas, as run (N - 1 dof)", "#999999", pts_v, "points")],
                  images / "observables_li2022.svg")
        out.append("\n## Near the liquid–hexatic transition: against published Monte Carlo\n")
        out.append("72 discs (r = 1) in a square periodic box, the setting of Li, Nishikawa, Hoellmer, Maggs and Krauth, "
                   "J. Chem. Phys. 157, 234111 (2022) (event-chain Monte Carlo, canonical; their table in "
                   "jellyfysh/HistoricDisks, `DigitizedData/ThisWork.csv`), started on a staggered lattice at speed 1, "
                   f"observed from t = 200 in 10 windows of {4000 * scale:g} s (about 2·10^4 collisions per disc each; "
                   f"from η = 0.69, where the 72 discs switch between a liquid and an ordered state over thousands of "
                   f"collisions per disc, from t = 20000 in windows of {20000 * scale:g} s). "
                   "Pressure as β P (2r)², their unit. A momentum-conserving run has one degree of freedom less than a "
                   "Monte Carlo run of the same N: the canonical column is `pressure_canonical` (Z + 1/N, exact: "
                   "docs/physics.md, \"Which ensemble\"); the last columns show ours taken as it is, 1/72 low in Z. "
                   "Deviations in combined standard errors. "
                   f"`{cmd}` (the last; each η its own world)\n")
        out.append(make_tables.md_table(["η", "Li et al. 2022", "turtlegas, canonical", "dev. (se)",
                                         "turtlegas, as run", "dev. (se)"], rows))
        out.append("\n![72 discs against Li et al.](images/observables_li2022.svg)\n")
    text = ("# Gas observables: measured against theory\n\n"
            "Generated by `python3 bench/make_observables.py` (do not edit by hand); the definitions are in "
            "docs/physics.md, \"Gas observables\", the tests that hold the same comparisons to stated "
            "tolerances in `tests/formats/observables_test.cpp`.\n\n" + "\n".join(out) + "\n")
    if args.quick:
        print(text)
    else:
        pathlib.Path(args.doc).write_text(text)


if __name__ == "__main__":
    main()
