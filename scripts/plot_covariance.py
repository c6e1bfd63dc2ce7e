#!/usr/bin/env python3
"""Figures of `gfins-sim covariance`: predicted 1-sigma envelopes and the error budget.

Usage: plot_covariance.py OUT_DIR [TITLE]
Reads OUT_DIR/covariance.csv (t_s, sigma_<state> for the twelve navigation errors),
OUT_DIR/budget.csv (source, t_s, sigma_<state>) and, when present, OUT_DIR/reference_run.csv
(one run of the scenario through the navigation core, gfins-sim run's columns); writes
OUT_DIR/covariance.png (envelopes, linear and log-log, with the run's errors) and
OUT_DIR/budget.png (each non-zero source's sigma at every budget time). TITLE (the scenario and
the core) heads both figures.
Run it with /usr/bin/python3 (Debian's python3-matplotlib).
"""
import csv
import math
import os
import signal
import sys

from plot_common import note_nonfinite

# Ctrl-C (SIGINT, which the terminal sends to gfins-sim and this script alike) ends the script
# the way it ends any command-line program, without a Python traceback: the default action.
signal.signal(signal.SIGINT, signal.SIG_DFL)

try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # noqa: E402
except ImportError as e:
    # A clear message and a non-zero exit (gfins-sim then exits 3), not a traceback.
    sys.exit(f"{sys.argv[0]}: cannot plot: {e} (Debian: apt install python3-matplotlib; "
             f"this interpreter is {sys.executable})")

# Angles in deg and angular rates in deg/s, as in every figure of gfins-sim (the CSV holds rad,
# rad/s).
RAD2DEG = 180.0 / math.pi
BLOCKS = [
    ("attitude error phi (n frame)", "phi_n", "deg", RAD2DEG),
    ("position error dr (NED)", "dr_n", "m", 1.0),
    ("velocity error dv (NED)", "dv_n", "m/s", 1.0),
    ("rate error dw (body)", "dw_b", "deg/s", RAD2DEG),
]


def read_csv(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        sys.exit(f"plot_covariance: {path} has no rows")
    return rows


def number(text):
    """A CSV field as a float; an empty or unreadable field is NaN (reported by column)."""
    try:
        return float(text)
    except (TypeError, ValueError):
        return math.nan


REPORTED = set()


def column(rows, name, path=None):
    """The column's values. With path (a column drawn on a figure): a column with no finite
    value, or with some, is reported once on stderr naming the file and the column."""
    values = [number(r[name]) for r in rows]
    if path is not None and (path, name) not in REPORTED:
        bad = sum(1 for v in values if not math.isfinite(v))
        if bad:
            REPORTED.add((path, name))
            what = (f" has no finite value (NaN, inf or empty in all {len(values)} rows): its "
                    "panel says so and draws nothing for it" if bad == len(values) else
                    f": {bad} of {len(values)} values are not finite (NaN, inf or empty): left "
                    "out of its panel")
            print(f"plot_covariance: warning: {path}: column {name}{what}", file=sys.stderr)
    return values


def state_columns(header, prefix):
    return [h for h in header if h.startswith("sigma_" + prefix)]


# The reference run's error columns for the blocks whose frame matches (the run's attitude error
# is in the body frame, the covariance's phi in the navigation frame: not overlaid).
RUN_COLUMNS = {"dr_n": ("err_r_n", "m"), "dv_n": ("err_v_n", "mps"), "dw_b": ("err_w_b", "rps")}


def plot_envelopes(out_dir, fig_title):
    path = os.path.join(out_dir, "covariance.csv")
    rows = read_csv(path)
    t = column(rows, "t_s", path)
    header = list(rows[0].keys())
    run_path = os.path.join(out_dir, "reference_run.csv")
    run = read_csv(run_path) if os.path.exists(run_path) else None
    # One row per block: predicted 1σ on linear axes (left, with the reference run's |error|)
    # and log-log (right). Each column shares its time axis, named on the bottom row; the
    # constrained layout keeps every title, label and tick label clear of its neighbours.
    fig, axes = plt.subplots(4, 2, figsize=(12, 13), sharex="col", layout="constrained")
    colors = ["tab:red", "tab:green", "tab:blue"]
    for i, (title, prefix, unit, scale) in enumerate(BLOCKS):
        lin, log = axes[i]
        series = []
        for k, name in enumerate(state_columns(header, prefix)):
            y = [v * scale for v in column(rows, name, path)]
            series.append((name, y))
            # The column names carry the CSV's unit (rad, m, ...); the axis states the plotted one.
            label = name.replace("sigma_", "").rsplit("_", 1)[0]
            lin.plot(t, y, color=colors[k], label="1σ " + label)
            pos = [(a, b) for a, b in zip(t, y)
                   if math.isfinite(a) and math.isfinite(b) and a > 0 and b > 0]
            if pos:
                log.loglog([p[0] for p in pos], [p[1] for p in pos], color=colors[k],
                           label="1σ " + label)
            if run is not None and prefix in RUN_COLUMNS:
                pre, u = RUN_COLUMNS[prefix]
                axis = "xyz"[k]
                tr = column(run, "t_s", run_path)
                er = [abs(v) * scale for v in column(run, f"{pre}_{axis}_{u}", run_path)]
                lin.plot(tr, er, color=colors[k], ls=":", lw=1, label=f"|one run| {axis}")
        note_nonfinite(lin, series)
        note_nonfinite(log, series)
        lin.set_title(f"{title}: predicted 1σ, linear", fontsize=10)
        log.set_title(f"{title}: predicted 1σ, log-log (slope = growth exponent)", fontsize=10)
        for ax in (lin, log):
            ax.set_ylabel(f"1σ ({unit})")
            ax.grid(True, which="both", alpha=0.3)
            ax.legend(fontsize=7)
    for ax in axes[-1]:
        ax.set_xlabel("t (s)")
    fig.suptitle(f"predicted error envelopes: {fig_title}", fontsize=12)
    fig.savefig(os.path.join(out_dir, "covariance.png"), dpi=110)
    plt.close(fig)


def plot_budget(out_dir, fig_title):
    path = os.path.join(out_dir, "budget.csv")
    if not os.path.exists(path):
        return
    all_rows = read_csv(path)
    header = [h for h in all_rows[0].keys() if h.startswith("sigma_")]
    for name in ["t_s"] + header:
        column(all_rows, name, path)  # reports non-finite values
    times = sorted({number(r["t_s"]) for r in all_rows if math.isfinite(number(r["t_s"]))})
    if not times:
        fig, ax = plt.subplots(figsize=(8, 3))
        note_nonfinite(ax, [("t_s", [math.nan])])
        fig.suptitle(f"error budget by source: {fig_title}", fontsize=11)
        fig.savefig(os.path.join(out_dir, "budget.png"), dpi=90)
        plt.close(fig)
        return

    def value(r, h):  # a σ drawn as a bar: finite and positive (log axis), else 0 (no bar)
        v = number(r[h])
        return v if math.isfinite(v) and v > 0 else 0.0

    # Sources that contribute nothing (σ = 0 everywhere) are left out: they would be empty bars
    # on a log axis.
    sources = [src for src in dict.fromkeys(r["source"] for r in all_rows)
               if any(value(r, h) > 0 for r in all_rows if r["source"] == src for h in header)]
    fig, axes = plt.subplots(len(times), 4, figsize=(18, 3.6 * len(times)), squeeze=False)
    for row, t_b in enumerate(times):
        rows = [r for r in all_rows if number(r["t_s"]) == t_b and r["source"] in sources]
        for ax, (title, prefix, unit, scale) in zip(axes[row], BLOCKS):
            names = [h for h in header if h.startswith("sigma_" + prefix)]
            width = 0.8 / max(1, len(rows))
            for k, r in enumerate(rows):
                xs = [i + k * width for i in range(len(names))]
                ys = [value(r, n) * scale for n in names]
                ax.bar(xs, ys, width, label=r["source"])
            ax.set_xticks([i + 0.4 - width / 2 for i in range(len(names))])
            # Tick labels name the state and axis; the unit is the axis label's (the plotted one).
            ax.set_xticklabels([n.replace("sigma_", "").rsplit("_", 1)[0] for n in names],
                               fontsize=8)
            ax.set_yscale("log")
            ax.set_ylabel(f"1σ ({unit})")
            ax.set_title(f"{title} at t = {t_b:g} s", fontsize=9)
            ax.grid(True, axis="y", which="both", alpha=0.3)
            # Headroom above the tallest bar (a third of the log span) holds the legend in one
            # row, so it covers no bar (it sat on the z bars before).
            ys = [value(r, n) * scale for r in rows for n in names if value(r, n) > 0]
            if ys:
                lo, hi = min(ys) / 3, max(ys) * 3
                ax.set_ylim(lo, hi * (hi / lo) ** 0.45)
            note_nonfinite(ax, [(n, [number(r[n]) for r in rows]) for n in names])
            ax.legend(fontsize=6, loc="upper center", ncol=max(1, len(rows)), frameon=False)
    fig.suptitle(f"error budget by source: {fig_title}", fontsize=11)
    fig.tight_layout(rect=(0, 0, 1, 0.975))
    fig.savefig(os.path.join(out_dir, "budget.png"), dpi=90)
    plt.close(fig)


def main():
    if len(sys.argv) not in (2, 3):
        sys.exit(__doc__)
    title = sys.argv[2] if len(sys.argv) == 3 else os.path.basename(sys.argv[1].rstrip("/"))
    plot_envelopes(sys.argv[1], title)
    plot_budget(sys.argv[1], title)
    print(f"figures: {sys.argv[1]}/covariance.png, {sys.argv[1]}/budget.png")


if __name__ == "__main__":
    main()
