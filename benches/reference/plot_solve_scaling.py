"""Draws docs/solve_scaling.svg (solve wall time vs variable count, log-log) from
benches/reference/results/solve_symnlp.jsonl (`cargo bench --bench solve -- --json`) and
benches/reference/results/solve_casadi.jsonl (`python3 benches/reference/solve_casadi.py`).

Run:  python3 benches/reference/plot_solve_scaling.py > docs/solve_scaling.svg

Solid lines symnlp, dashed IPOPT; red hanging chain, blue Van der Pol OCP. A run that did
not succeed (capped or killed) is drawn as an open circle at its cap time (killed runs are
not drawn; a note names them).
"""
import json
import math
import os

HERE = os.path.dirname(os.path.abspath(__file__))
RES = os.path.join(HERE, "results")

X0, X1, Y0, Y1 = 70, 470, 30, 370  # plot box
NMIN, NMAX = 1e2, 10**5.4  # x range (log10 2 .. 5.4)
TMIN, TMAX = 1e-4, 10**3  # y range (log10 -4 .. 3)


def x_of(n):
    return X0 + 23.5 + (math.log10(n) - 2) * (446.5 - 93.5) / 3


def y_of(t):
    return Y1 - (math.log10(t) - math.log10(TMIN)) * (Y1 - Y0) / (math.log10(TMAX) - math.log10(TMIN))


def load(name):
    with open(os.path.join(RES, name)) as f:
        return [json.loads(l) for l in f if l.strip()]


def main():
    sym = load("solve_symnlp.jsonl")
    ref = load("solve_casadi.jsonl")
    out = [
        '<svg xmlns="http://www.w3.org/2000/svg" width="640" height="420" '
        'font-family="sans-serif" font-size="12">',
        '<rect width="640" height="420" fill="white"/>',
    ]
    for e in range(2, 6):
        x = 93.5 + (e - 2) * (446.5 - 93.5) / 3
        out.append(
            f'<line x1="{x:.1f}" y1="{Y0}" x2="{x:.1f}" y2="{Y1}" stroke="#ddd"/>'
            f'<text x="{x:.1f}" y="386" text-anchor="middle">10<tspan dy="-5" font-size="9">{e}</tspan></text>'
        )
    for e in range(-4, 4):
        y = y_of(10.0**e)
        out.append(
            f'<line x1="{X0}" y1="{y:.1f}" x2="{X1}" y2="{y:.1f}" stroke="#ddd"/>'
            f'<text x="64" y="{y + 4:.1f}" text-anchor="end">10<tspan dy="-5" font-size="9">{e}</tspan></text>'
        )
    out.append(f'<rect x="{X0}" y="{Y0}" width="{X1 - X0}" height="{Y1 - Y0}" fill="none" stroke="black"/>')
    out.append('<text x="270.0" y="408" text-anchor="middle">variables n</text>')
    out.append(
        '<text x="16" y="200.0" text-anchor="middle" transform="rotate(-90 16 200.0)">solve wall time [s]</text>'
    )
    series = [
        (sym, "hanging_chain", "#c0392b", "0", "symnlp, hanging chain"),
        (sym, "ocp", "#2471a3", "0", "symnlp, Van der Pol OCP"),
        (ref, "hanging_chain", "#c0392b", "6,4", "IPOPT, hanging chain"),
        (ref, "ocp", "#2471a3", "6,4", "IPOPT, Van der Pol OCP"),
    ]
    notes = []
    any_capped = False
    ly = 44
    for rows, prob, col, dash, label in series:
        pts = []
        for r in rows:
            if r["problem"] != prob:
                continue
            if "solve_s" not in r:  # killed by the harness: no time to draw
                notes.append(f"{label.split(',')[0]} chain 10^{round(math.log10(r['n']))}: "
                             f"killed at {r.get('killed_after_s', 0):.0f} s")
                continue
            ok = r.get("status", r.get("return_status")) in ("SolveSucceeded", "Solve_Succeeded")
            pts.append((x_of(r["n"]), y_of(r["solve_s"]), ok))
            any_capped = any_capped or not ok
        if pts:
            d = " ".join(("M" if i == 0 else "L") + f"{x:.1f},{y:.1f}" for i, (x, y, _) in enumerate(pts))
            out.append(f'<path d="{d}" fill="none" stroke="{col}" stroke-width="2" stroke-dasharray="{dash}"/>')
            for x, y, ok in pts:
                if ok:
                    out.append(f'<circle cx="{x:.1f}" cy="{y:.1f}" r="3.5" fill="{col}"/>')
                else:
                    out.append(
                        f'<circle cx="{x:.1f}" cy="{y:.1f}" r="4" fill="white" stroke="{col}" stroke-width="2"/>'
                    )
        out.append(
            f'<line x1="480" y1="{ly}" x2="504" y2="{ly}" stroke="{col}" stroke-width="2" '
            f'stroke-dasharray="{dash}"/><text x="508" y="{ly + 4}" font-size="10">{label}</text>'
        )
        ly += 18
    if any_capped:
        out.append(
            f'<circle cx="492" cy="{ly + 6}" r="4" fill="white" stroke="black" stroke-width="2"/>'
            f'<text x="508" y="{ly + 10}" font-size="10">not solved (cap)</text>'
        )
        ly += 28
    else:
        ly += 10
    for note in notes:
        a, b = note.split(": ")
        out.append(f'<text x="480" y="{ly}" font-size="10">{a.replace("^5", "⁵").replace("^4", "⁴")}:</text>'
                   f'<text x="480" y="{ly + 14}" font-size="10">{b}</text>')
        ly += 32
    out.append("</svg>")
    print("\n".join(out))


if __name__ == "__main__":
    main()
