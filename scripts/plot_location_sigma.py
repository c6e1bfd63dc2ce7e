#!/usr/bin/env python3
"""Figure of the location σ check (tests/calibration/firmware_calibration_e2e.cpp, location test).

Run the test with GFINS_CAL_E2E_OUT=DIR to write DIR/location_z.csv ((estimate - truth)/σ of the
18 components of Δρ, with the runs' σ alone and with the stated σ, runs + base), then:

    scripts/plot_location_sigma.py DIR -o docs/figures/location-sigma.png
"""
import argparse
import csv
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dir", help="folder the test wrote (GFINS_CAL_E2E_OUT)")
    ap.add_argument("-o", "--out", required=True, help="PNG to write")
    a = ap.parse_args()
    with open(os.path.join(a.dir, "location_z.csv"), newline="") as f:
        rows = list(csv.DictReader(f))
    names = [r["component"] for r in rows]
    x = range(len(rows))
    chi2_runs = float(rows[0]["chi2_runs"])
    chi2_total = float(rows[0]["chi2_total"])
    fig, ax = plt.subplots(figsize=(10, 4.2))
    ax.plot([i - 0.12 for i in x], [float(r["z_runs"]) for r in rows], "o", color="tab:red",
            label=f"σ of the runs' noise alone (before): χ² {chi2_runs:.1f} for 18 dof")
    ax.plot([i + 0.12 for i in x], [float(r["z_total"]) for r in rows], "s", color="tab:blue",
            label=f"stated σ, runs + base calibration (now): χ² {chi2_total:.1f} for 18 dof")
    for level, style in ((1, ":"), (3, "--")):
        ax.axhline(level, color="0.5", lw=0.8, ls=style)
        ax.axhline(-level, color="0.5", lw=0.8, ls=style)
    ax.set_xticks(list(x))
    ax.set_xticklabels(names, fontsize=8)
    ax.set_xlabel("component of Δρ (sensor, body axis)")
    ax.set_ylabel("(estimate − truth) / σ")
    ax.set_title("location errors from rate-table runs through the firmware, on a base "
                 "calibration captured through the firmware")
    ax.legend(fontsize=8, loc="upper left")
    ax.grid(axis="y", lw=0.3)
    ax.set_ylim(-4.5, 4.5)
    fig.tight_layout()
    fig.savefig(a.out, dpi=110)
    print(f"wrote {a.out}")


if __name__ == "__main__":
    main()
