#!/usr/bin/env python3
"""Figure of a decoded gfins CAN log (gfins-can plot, docs/can-interface.md).

    plot_can.py --csv DECODED.csv --out FIGURE.png [--title TEXT]

DECODED.csv is `gfins-can decode LOG --view csv`: one row per epoch, columns "Name[unit]".
Four panels over device time (GfinsEpoch.TimeUs, unwrapped, from the first epoch): attitude
(ZYX Euler angles of q_nb, deg; roll and yaw unwrapped, so a turn through ±180° is no vertical
stroke), angular rate (body FRD, deg/s), velocity (NED, m/s), position (NED from the alignment
point, m). Each node of the log gets its own line style. A signal with no finite value is
reported on stderr and on its panel. Matplotlib, Agg backend (no display needed). Called by
gfins-can with an argument vector, never a shell.
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


def number(text):
    """A CSV field as a float; empty (a signal not sent in this epoch) or unreadable is NaN."""
    try:
        return float(text)
    except ValueError:
        return math.nan


def load(path):
    """Columns by signal name (unit stripped) per node, {node: {name: [values]}}, and the
    header's column of each name ({name: "Name[unit]"})."""
    nodes = {}
    with open(path, newline="") as f:
        reader = csv.reader(f)
        header = next(reader)
        names = [h.split("[")[0] for h in header]
        for row in reader:
            node = int(row[0])
            cols = nodes.setdefault(node, {n: [] for n in names})
            for n, v in zip(names, row):
                cols[n].append(number(v))
    return nodes, dict(zip(names, header))


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


def unwrap_deg(values):
    """Angles in deg without the 360° jump where they cross ±180° (each step taken as the
    shortest turn: the frames must turn less than 180° apart)."""
    out, offset = [], 0.0
    for k, v in enumerate(values):
        if k > 0:
            step = v - values[k - 1]
            offset -= 360.0 * round(step / 360.0)
        out.append(v + offset)
    return out


def panel(ax, t, cols, names, labels, scale, style, node, multi, empty, unwrap=()):
    """Draws the signals names of one node; a signal with no finite value is added to empty
    (the caller reports it). unwrap: the names plotted unwrapped (angles, deg)."""
    for i, (n, lab) in enumerate(zip(names, labels)):
        y = [v * scale for v in cols[n]]
        # Signals sent at a lower rate than the epoch are NaN in between: connect the samples.
        pts = [(a, b) for a, b in zip(t, y) if math.isfinite(a) and math.isfinite(b)]
        if not pts:
            empty.append((n, node))
            continue
        xs, ys = zip(*pts)
        if n in unwrap:
            ys = unwrap_deg(ys)
        label = f"{lab} (node {node})" if multi else lab
        ax.plot(xs, ys, STYLES[style % len(STYLES)], color=COLORS[i], lw=1, label=label)
    ax.grid(True, alpha=0.3)
    if ax.get_legend_handles_labels()[0]:
        ax.legend(loc="best", fontsize=7)


def report_empty(ax, empty, header, source, multi):
    """One line on stderr per signal with no finite value (naming the decoded file and the
    column) and a note on its panel."""
    if not empty:
        return
    shown = []
    for n, node in empty:
        where = f" for node {node}" if multi else ""
        print(f"plot_can.py: warning: {source}: column {header.get(n, n)} has no finite "
              f"value{where}: nothing drawn for it", file=sys.stderr)
        shown.append(f"{header.get(n, n)}{where}")
    ax.text(0.5, 0.5, "no finite values:\n" + "\n".join(shown), transform=ax.transAxes,
            ha="center", va="center", fontsize=9, color="tab:red",
            bbox={"facecolor": "white", "edgecolor": "tab:red", "alpha": 0.9})


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--csv", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--title", default="gfins CAN log")
    a = ap.parse_args()
    nodes, header = load(a.csv)
    if not nodes:
        print("plot_can.py: no epochs in " + a.csv, file=sys.stderr)
        return 1
    fig, axs = plt.subplots(4, 1, figsize=(10, 10), sharex=True)
    multi = len(nodes) > 1
    empty = [[] for _ in axs]
    for k, (node, cols) in enumerate(sorted(nodes.items())):
        t = device_time(cols)
        panel(axs[0], t, cols, ["Roll", "Pitch", "Yaw"], ["roll", "pitch", "yaw"], RAD2DEG, k,
              node, multi, empty[0], unwrap=("Roll", "Yaw"))
        panel(axs[1], t, cols, ["RateX", "RateY", "RateZ"], ["x fwd", "y right", "z down"],
              RAD2DEG, k, node, multi, empty[1])
        panel(axs[2], t, cols, ["VelN", "VelE", "VelD"], ["north", "east", "down"], 1.0, k, node,
              multi, empty[2])
        panel(axs[3], t, cols, ["PosN", "PosE", "PosD"], ["north", "east", "down"], 1.0, k, node,
              multi, empty[3])
    source = f"{a.title} (decoded: {a.csv})"
    for ax, e in zip(axs, empty):
        report_empty(ax, e, header, source, multi)
    axs[0].set_ylabel("attitude, ZYX Euler of q_nb (deg),\nroll and yaw unwrapped")
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
