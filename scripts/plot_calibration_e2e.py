#!/usr/bin/env python3
"""Figure of the end-to-end calibration test (tests/calibration/firmware_calibration_e2e.cpp).

Run the test with GFINS_CAL_E2E_OUT=DIR to write DIR/trace.csv (sensor outputs, V, every 10th
sample), DIR/captures.csv (the accepted capture windows) and DIR/z.csv ((estimate - truth)/sigma
of every parameter per route), then:

    scripts/plot_calibration_e2e.py DIR -o docs/figures/calibration-e2e.png
"""
import argparse
import csv
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def read(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dir", help="folder the test wrote (GFINS_CAL_E2E_OUT)")
    ap.add_argument("-o", "--out", required=True, help="PNG to write")
    a = ap.parse_args()
    trace = read(os.path.join(a.dir, "trace.csv"))
    caps = read(os.path.join(a.dir, "captures.csv"))
    zrows = read(os.path.join(a.dir, "z.csv"))

    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(11, 8), gridspec_kw={"height_ratios": [1, 1]})
    t = [float(r["t_s"]) for r in trace]
    for j in range(1, 7):
        ax1.plot(t, [float(r[f"v{j}"]) for r in trace], lw=0.8, label=f"a{j}")
    for c in caps:
        t0, t1 = float(c["t_start_s"]), float(c["t_end_s"])
        ax1.axvspan(t0, t1, color="0.85", zorder=0)
        ax1.text((t0 + t1) / 2, 1.55, c["label"], ha="center", fontsize=7)
    ax1.set_xlabel("board time (s)")
    ax1.set_ylabel("sensor output (V)")
    ax1.set_ylim(-1.7, 1.75)
    ax1.set_title("simulated board calibration-board: the twelve poses of Tables 2/3, "
                  "captures (grey) through the firmware over CAN")
    ax1.legend(ncol=6, fontsize=8, loc="lower right")

    routes = []
    for r in zrows:
        if r["route"] not in routes:
            routes.append(r["route"])
    params = [r["parameter"] for r in zrows if r["route"] == routes[0]]
    markers = {"general": "o", "paper": "s", "standard gravity": "x"}
    for k, route in enumerate(routes):
        z = [float(r["z"]) for r in zrows if r["route"] == route]
        x = [i + 0.2 * (k - 1) for i in range(len(z))]
        ax2.plot(x, z, markers.get(route, "^"), ms=5, label=route)
    ax2.axhline(5, color="r", lw=0.8, ls="--")
    ax2.axhline(-5, color="r", lw=0.8, ls="--", label="test bound ±5σ")
    ax2.set_yscale("symlog", linthresh=5)
    ax2.set_xticks(range(len(params)))
    ax2.set_xticklabels(params, rotation=70, fontsize=7)
    ax2.set_ylabel("(estimate − truth) / stated σ")
    ax2.set_title("recovered parameters vs the scenario's truth (SI units); with standard "
                  "gravity the SF miss by 100-260σ")
    lo = min(float(r["z"]) for r in zrows)
    ax2.set_ylim(min(-10.0, 1.5 * lo), 20.0)
    ax2.legend(fontsize=8, loc="upper left")
    ax2.grid(axis="y", lw=0.3)
    fig.tight_layout()
    fig.savefig(a.out, dpi=110)
    print(f"wrote {a.out}")


if __name__ == "__main__":
    main()
