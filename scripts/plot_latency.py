#!/usr/bin/env python3
"""Plot gfins-fw's data-ready -> CAN latency histogram (--latency-csv) as a PNG.

usage: plot_latency.py HISTOGRAM.csv OUT.png [TITLE]
"""
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    us, n = [], []
    with open(sys.argv[1], newline="") as f:
        for row in csv.DictReader(f):
            us.append(int(row["latency_us"]))
            n.append(int(row["count"]))
    total = sum(n)
    cum, acc = [], 0
    for c in n:
        acc += c
        cum.append(acc / total)
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4))
    ax1.bar(us, n, width=1.0)
    ax1.set_yscale("log")
    ax1.set_xlim(0, max(200, min(us[-1], 2000)))
    ax1.set_xlabel("latency, data-ready edge to frames handed to the CAN sink (us, 1 us bins)")
    ax1.set_ylabel("epochs")
    ax2.semilogx([u + 1 for u in us], cum)
    for q in (0.5, 0.99):
        ax2.axhline(q, color="grey", lw=0.5)
    ax2.set_xlabel("latency (us, log)")
    ax2.set_ylabel("fraction of epochs at or below")
    ax2.set_ylim(0, 1.01)
    fig.suptitle(sys.argv[3] if len(sys.argv) > 3 else "gfins-fw latency")
    fig.tight_layout()
    fig.savefig(sys.argv[2], dpi=100)


if __name__ == "__main__":
    main()
