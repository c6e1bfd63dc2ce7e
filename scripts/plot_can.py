#!/usr/bin/env python3
"""Figure of a decoded gfins CAN log (gfins-can plot, docs/can-interface.md).

    plot_can.py --csv DECODED.csv --out FIGURE.png [--title TEXT]

DECODED.csv is `gfins-can decode LOG --view csv`: one row per epoch, columns "Name[unit]".
Four panels over device time (GfinsEpoch.TimeUs, unwrapped, from the first epoch): attitude
(ZYX Euler angles of q_nb, deg), angular rate (body FRD, deg/s), velocity (NED, m/s), position
(NED from the alignment point, m). Each node of the log gets its own line style. Matplotlib,
Agg backend (no display needed). Called by gfins-can with an argument vector, never a shell.
"""
import argparse
import csv
import math
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

COLORS = ["tab:red", "tab:green", "tab:blue"]
STYLES = ["-", "--", ":", "-."]
RAD2DEG = 180.0 / math.pi


def load(path):
    """Columns by signal name (unit stripped) per node: {node: {name: [values]}}."""
    nodes = {}
    with open(path, newline="") as f:
        reader = csv.reader(f)
        header = next(reader)
        names = [h.split("[")[0] for h in header]
        for row in reader:
            node = int(row[0])
            cols = nodes.setdefault(node, {n: [] for n in names})
            for n, v in zip(names, row):
                cols[n].append(float(v) if v != "" else math.nan)
    return nodes


def device_time(cols):
    """TimeUs (µs mod 2^32) unwrapped, in s from the first epoch."""
    t, offset, prev, t0 = [], 0.0, None, None
    for us in cols["TimeUs"]:
        if math.isnan(us):
            t.append(math.nan)
            continue
        if prev is not None and us < prev:
            offset += 2.0 ** 32
        prev = us
        v = (us + offset) * 1e-6
        t0 = v if t0 is None else t0
        t.append(v - t0)
    return t


def panel(ax, t, cols, names, labels, scale, style, node, multi):
    for i, (n, lab) in enumerate(zip(names, labels)):
        y = [v * scale for v in cols[n]]
        # Signals sent at a lower rate than the epoch are NaN in between: connect the samples.
        pts = [(a, b) for a, b in zip(t, y) if not (math.isnan(a) or math.isnan(b))]
        if not pts:
            continue
        xs, ys = zip(*pts)
        label = f"{lab} (node {node})" if multi else lab
        ax.plot(xs, ys, STYLES[style % len(STYLES)], color=COLORS[i], lw=1, label=label)
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize=7)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--csv", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--title", default="gfins CAN log")
    a = ap.parse_args()
    nodes = load(a.csv)
    if not nodes:
        print("plot_can.py: no epochs in " + a.csv, file=sys.stderr)
        return 1
    fig, axs = plt.subplots(4, 1, figsize=(10, 10), sharex=True)
    multi = len(nodes) > 1
    for k, (node, cols) in enumerate(sorted(nodes.items())):
        t = device_time(cols)
        panel(axs[0], t, cols, ["Roll", "Pitch", "Yaw"], ["roll", "pitch", "yaw"], RAD2DEG, k,
              node, multi)
        panel(axs[1], t, cols, ["RateX", "RateY", "RateZ"], ["x fwd", "y right", "z down"],
              RAD2DEG, k, node, multi)
        panel(axs[2], t, cols, ["VelN", "VelE", "VelD"], ["north", "east", "down"], 1.0, k, node,
              multi)
        panel(axs[3], t, cols, ["PosN", "PosE", "PosD"], ["north", "east", "down"], 1.0, k, node,
              multi)
    axs[0].set_ylabel("attitude, ZYX Euler of q_nb (deg)")
    axs[1].set_ylabel("angular rate, body FRD (deg/s)")
    axs[2].set_ylabel("velocity, NED (m/s)")
    axs[3].set_ylabel("position from alignment, NED (m)")
    axs[3].set_xlabel("device time from the first epoch (s)")
    fig.suptitle(a.title + ": decoded by gfins-can", fontsize=11)
    fig.tight_layout()
    try:
        fig.savefig(a.out, dpi=80)
    except OSError as e:  # one line naming the file, not a traceback
        print("plot_can.py: cannot write " + a.out + ": " + (e.strerror or str(e)),
              file=sys.stderr)
        return 1
    print("plot_can.py: wrote " + a.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
