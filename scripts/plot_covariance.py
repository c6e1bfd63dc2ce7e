#!/usr/bin/env python3
"""Figures of `gfins-sim covariance`: predicted 1-sigma envelopes and the error budget.

Usage: plot_covariance.py OUT_DIR
Reads OUT_DIR/covariance.csv (t_s, sigma_<state> for the twelve navigation errors) and
OUT_DIR/budget.csv (source, t_s, sigma_<state>); writes OUT_DIR/covariance.png (envelopes,
linear and log-log) and OUT_DIR/budget.png (each source's sigma at the last budget time).
Run it with /usr/bin/python3 (Debian's python3-matplotlib).
"""
import csv
import math
import os
import sys

try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # noqa: E402
except ImportError as e:
    # A clear message and a non-zero exit (gfins-sim then exits 3), not a traceback.
    sys.exit(f"{sys.argv[0]}: cannot plot: {e} (Debian: apt install python3-matplotlib; "
             f"this interpreter is {sys.executable})")

BLOCKS = [
    ("attitude error phi (n frame)", "phi_n", "deg", 180.0 / math.pi),
    ("position error dr (NED)", "dr_n", "m", 1.0),
    ("velocity error dv (NED)", "dv_n", "m/s", 1.0),
    ("rate error dw (body)", "dw_b", "rad/s", 1.0),
]


def read_csv(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        sys.exit(f"plot_covariance: {path} has no rows")
    return rows


def column(rows, name):
    return [float(r[name]) for r in rows]


def state_columns(header, prefix):
    return [h for h in header if h.startswith("sigma_" + prefix)]


def plot_envelopes(out_dir):
    rows = read_csv(os.path.join(out_dir, "covariance.csv"))
    t = column(rows, "t_s")
    header = list(rows[0].keys())
    fig, axes = plt.subplots(4, 2, figsize=(12, 13))
    for i, (title, prefix, unit, scale) in enumerate(BLOCKS):
        for name in state_columns(header, prefix):
            y = [v * scale for v in column(rows, name)]
            # The column names carry the CSV's unit (rad, m, ...); the axis states the plotted one.
            label = name.replace("sigma_", "").rsplit("_", 1)[0]
            axes[i][0].plot(t, y, label=label)
            pos = [(a, b) for a, b in zip(t, y) if a > 0 and b > 0]
            if pos:
                axes[i][1].loglog([p[0] for p in pos], [p[1] for p in pos], label=label)
        axes[i][0].set_title(f"{title}: predicted 1 sigma")
        axes[i][0].set_ylabel(unit)
        axes[i][1].set_title("log-log (slope = growth exponent)")
        for ax in axes[i]:
            ax.grid(True, which="both", alpha=0.3)
            ax.legend(fontsize=7)
    for ax in axes[-1]:
        ax.set_xlabel("t, s")
    fig.tight_layout()
    fig.savefig(os.path.join(out_dir, "covariance.png"), dpi=110)
    plt.close(fig)


def plot_budget(out_dir):
    path = os.path.join(out_dir, "budget.csv")
    if not os.path.exists(path):
        return
    rows = read_csv(path)
    t_last = max(float(r["t_s"]) for r in rows)
    rows = [r for r in rows if float(r["t_s"]) == t_last]
    header = [h for h in rows[0].keys() if h.startswith("sigma_")]
    sources = [r["source"] for r in rows]
    fig, axes = plt.subplots(2, 2, figsize=(12, 8))
    for ax, (title, prefix, unit, scale) in zip(axes.flat, BLOCKS):
        names = [h for h in header if h.startswith("sigma_" + prefix)]
        width = 0.8 / max(1, len(sources))
        for k, r in enumerate(rows):
            xs = [i + k * width for i in range(len(names))]
            ys = [float(r[n]) * scale for n in names]
            ax.bar(xs, ys, width, label=sources[k])
        ax.set_xticks([i + 0.4 - width / 2 for i in range(len(names))])
        ax.set_xticklabels([n.replace("sigma_", "") for n in names], fontsize=8)
        ax.set_yscale("log")
        ax.set_ylabel(unit)
        ax.set_title(f"{title}: 1 sigma by source at t = {t_last:g} s")
        ax.grid(True, axis="y", which="both", alpha=0.3)
    axes.flat[0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(out_dir, "budget.png"), dpi=110)
    plt.close(fig)


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    plot_envelopes(sys.argv[1])
    plot_budget(sys.argv[1])
    print(f"figures: {sys.argv[1]}/covariance.png, {sys.argv[1]}/budget.png")


if __name__ == "__main__":
    main()
