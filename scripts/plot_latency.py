#!/usr/bin/env python3
"""Plot gfins-fw's data-ready -> CAN latency histogram (--latency-csv) as a PNG.

usage: plot_latency.py HISTOGRAM.csv OUT.png [TITLE]

HISTOGRAM.csv has the columns latency_us,count (1 us bins, what gfins-fw --latency-csv writes).
TITLE names the run (scenario, duration, pacing); the default names the CSV. Both panels mark
the median, the 99th percentile and the maximum, read from the histogram itself.
"""
import csv
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

# The histogram panel shows the body of the distribution; the tail beyond it is counted in its
# legend and drawn on the cumulative panel (log axis).
HIST_LIMIT_US = 2000
# gfins-fw's histogram (LatencyHistogram in firmware/app/include/gfins/app/sample_loop.hpp) has
# 20,000 bins of 1 µs; the last one holds every latency beyond it. gfins-fw prints the exact
# maximum at the end of its run.
OVERFLOW_BIN_US = 19999


def quantile_us(us, n, q):
    """The upper edge of the first 1 µs bin with at least q of the epochs at or below it: the
    convention of gfins-fw's own "latency edge → CAN: p50 ... µs" line (LatencyHistogram::
    quantile_us), so the figure and the log agree."""
    total = sum(n)
    want = math.ceil(q * total)
    acc = 0
    for u, c in zip(us, n):
        acc += c
        if acc >= want:
            return u + 1
    return us[-1] + 1


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    us, n = [], []
    try:
        with open(sys.argv[1], newline="") as f:
            for line, row in enumerate(csv.DictReader(f), start=2):
                try:
                    us.append(int(row["latency_us"]))
                    n.append(int(row["count"]))
                except (KeyError, TypeError, ValueError):
                    sys.exit(f"plot_latency: {sys.argv[1]}:{line}: expected integer columns "
                             f"latency_us,count, got {row!r}")
    except OSError as e:
        sys.exit(f"plot_latency: cannot read {sys.argv[1]}: {e.strerror}")
    total = sum(n)
    if total == 0:
        sys.exit(f"plot_latency: {sys.argv[1]} holds no epoch")
    cum, acc = [], 0
    for c in n:
        acc += c
        cum.append(acc / total)
    p50, p99, top = quantile_us(us, n, 0.5), quantile_us(us, n, 0.99), us[-1] + 1
    beyond = sum(c for u, c in zip(us, n) if u > HIST_LIMIT_US)
    top_text = f"≥ {top - 1} µs (overflow bin)" if top > OVERFLOW_BIN_US else f"≤ {top} µs"
    marks = [(p50, "p50", "tab:green"), (p99, "p99", "tab:orange"), (top, "max", "tab:red")]

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(12, 4.5))
    ax1.bar(us, n, width=1.0, color="tab:blue", label=f"epochs per 1 µs bin ({total} in all)")
    for v, name, colour in marks:
        if v <= HIST_LIMIT_US:
            ax1.axvline(v, color=colour, lw=1, ls="--",
                        label=f"{name} {top_text if name == 'max' else f'≤ {v} µs'}")
    if beyond:
        ax1.plot([], [], " ", label=f"{beyond} epoch(s) beyond {HIST_LIMIT_US} µs (max {top_text})")
    ax1.set_yscale("log")
    ax1.set_xlim(0, max(200, min(top, HIST_LIMIT_US)))
    ax1.set_xlabel("latency, data-ready edge to frames handed to the CAN sink (µs)")
    ax1.set_ylabel("epochs (log)")
    ax1.set_title("histogram")
    ax1.legend(loc="upper right", fontsize=8)

    ax2.semilogx([u + 1 for u in us], cum, color="tab:blue", label="fraction at or below")
    for v, name, colour in marks:
        ax2.axvline(v, color=colour, lw=1, ls="--",
                    label=f"{name} {top_text if name == 'max' else f'≤ {v} µs'}")
    ax2.set_xlabel("latency, upper edge of its 1 µs bin (µs, log)")
    ax2.set_ylabel("fraction of epochs at or below")
    ax2.set_ylim(0, 1.01)
    ax2.set_title("cumulative distribution")
    ax2.legend(loc="lower right", fontsize=8)

    default = f"gfins-fw latency, {os.path.basename(sys.argv[1])}"
    fig.suptitle(sys.argv[3] if len(sys.argv) > 3 else default)
    fig.tight_layout()
    fig.savefig(sys.argv[2], dpi=100)


if __name__ == "__main__":
    main()
