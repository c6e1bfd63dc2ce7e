#!/usr/bin/env python3
"""Figure of the parity monitor's detection and exclusion against fault size (docs/redundancy.md).

Run the long test with GFINS_PARITY_CSV=FILE to write the table, then:

    GFINS_PARITY_CSV=/tmp/parity.csv build/host-release/tests/nav_core/nav_core_parity_evaluation_long
    scripts/plot_parity_evaluation.py /tmp/parity.csv -o docs/figures/parity-evaluation.png
"""
import argparse
import csv
import math

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("csv", help="table the test wrote (GFINS_PARITY_CSV)")
    ap.add_argument("-o", "--out", required=True, help="PNG to write")
    a = ap.parse_args()
    with open(a.csv, newline="") as f:
        rows = list(csv.DictReader(f))
    sizes = sorted({int(r["n"]) for r in rows})
    fig, axes = plt.subplots(1, 3, figsize=(14, 4.4))
    for n in sizes:
        rs = [r for r in rows if int(r["n"]) == n]
        mg = [float(r["fault_mg"]) for r in rs]
        trials = [int(r["trials"]) for r in rs]
        axes[0].plot(mg, [float(r["missed_rate"]) for r in rs], "o-", label=f"N = {n}")
        delay = [float(r["mean_detect_delay_s"]) for r in rs]
        axes[1].plot(mg, [d * 1e3 if not math.isnan(d) else math.nan for d in delay], "o-",
                     label=f"N = {n}, first alarm")
        excl = [int(r["excluded_right"]) / t for r, t in zip(rs, trials)]
        axes[2].plot(mg, excl, "o-", label=f"N = {n}")
        wrong = sum(int(r["excluded_wrong"]) for r in rs)
        if wrong:
            axes[2].annotate(f"N = {n}: {wrong} wrong", (mg[-1], excl[-1]))
    axes[0].set_title("missed detections (no alarm within 1 s)")
    axes[0].set_ylabel("fraction of 200 faults")
    axes[1].set_title("fault onset to first alarm (mean)")
    axes[1].set_ylabel("ms")
    axes[2].set_title("faulty channel excluded (right channel)")
    axes[2].set_ylabel("fraction of 200 faults")
    for ax in axes:
        ax.set_xscale("log")
        ax.set_xlabel("bias fault on one channel, mg")
        ax.grid(True, which="both", lw=0.3)
        ax.legend(fontsize=8)
    fig.suptitle("Parity monitor, float32, W = 100 at 1 kHz, σ = 0.5 mm/s² per sample, "
                 "0.01 false alarms per hour", fontsize=10)
    fig.tight_layout()
    fig.savefig(a.out, dpi=110)


if __name__ == "__main__":
    main()
