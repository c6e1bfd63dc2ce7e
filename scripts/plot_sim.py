#!/usr/bin/env python3
"""Figures of gfins-sim (docs/simulation.md). Called by gfins-sim itself:

    plot_sim.py run DIR [TITLE]         DIR/{uncompensated,compensated}.csv → DIR/*.png
    plot_sim.py paper63 DIR [CORE]      DIR/<config>_{before,after}.csv → Figs. 7-10, nav errors
    plot_sim.py montecarlo DIR [TITLE]  DIR/montecarlo.csv → envelopes and log-log growth
    plot_sim.py replay DIR [TITLE]      DIR/navigation.csv (gfins-replay) → DIR/replay.png
    plot_sim.py aided DIR [TITLE]       DIR/{unaided,aided}.csv → DIR/accuracy.png, the errors
                                        with the filter's ±3σ (gfins-sim aided)
    plot_sim.py consistency DIR [TITLE] DIR/{nees,nis}.csv → DIR/consistency.png, NEES and NIS
                                        with their χ² bounds (gfins-sim consistency)

TITLE names the scenario (or recording), the compensator and the core; every figure carries it.
Column names carry units and frames (docs/simulation.md, "Output files"): err_v_n_x_mps is the
velocity error along north, m/s; err_att_b_x_rad the attitude error about body x, rad.

Matplotlib with the Agg backend (no display needed); numpy comes with matplotlib.
"""
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
import numpy as np  # noqa: E402

AXES = "xyz"
COLORS = ["tab:red", "tab:green", "tab:blue"]
GROUP_COLORS = COLORS + ["tab:purple"]  # gfins-sim consistency: tilt, heading, velocity, position
# Angles and angular rates are plotted in deg and deg/s in every figure (the CSV files hold rad,
# rad/s); angular accelerations stay in rad/s², the unit of the paper's Figs. 8 and 10.
RAD2DEG = 180 / np.pi


# Rows of one CSV file kept for a figure: more points than a PNG has pixels across (every
# built-in scenario, 20,001 rows at most, is plotted whole), and bounded memory for a run of any
# length, whose CSV gfins-sim streams to disk: genfromtxt takes about 3 kB per row of 94 columns
# (measured: 925 MB peak for two files of 150,000 rows), so two files stay near 150 MB. Longer
# files are read every k-th row (and the last).
MAX_PLOT_ROWS = 25_000


def warn(text):
    print(f"plot_sim.py: warning: {text}", file=sys.stderr)


class Table:
    """The columns of one CSV file by name. Reading a column for a figure checks its values:
    a column with no finite value (all NaN or inf, e.g. an edited or truncated file), or with
    some, is reported once on stderr naming the file and the column (note_nonfinite then says it
    on the panel). gaps_ok: NaN rows are part of the format (σ before the filter starts, NEES
    where no run published one); only a column with no finite value at all is reported."""

    def __init__(self, path, data):
        self.path = path
        self.data = np.atleast_1d(data)  # one data row: a 0-d array otherwise
        self.reported = set()

    @property
    def size(self):
        return self.data.size

    def __getitem__(self, name):
        return self.col(name)

    def col(self, name, gaps_ok=False):
        v = self.data[name]
        if name in self.reported:
            return v
        finite = np.isfinite(v)
        if not finite.any():
            self.reported.add(name)
            rows = f"NaN or inf in all {v.size} rows" if v.size else "the file has no data row"
            warn(f"{self.path}: column {name} has no finite value ({rows}): its panel says so "
                 "and draws nothing for it")
        elif not gaps_ok and not finite.all():
            self.reported.add(name)
            warn(f"{self.path}: column {name}: {v.size - finite.sum()} of {v.size} values are "
                 f"not finite (NaN or inf): left out of its panel")
        return v


def load(path):
    with open(path) as f:
        rows = sum(1 for _ in f) - 1
    step = max(1, -(-rows // MAX_PLOT_ROWS))
    if step == 1:
        return Table(path, np.genfromtxt(path, delimiter=",", names=True))

    def decimated():
        with open(path) as f:
            yield next(f)  # the header
            last = None
            for i, line in enumerate(f):
                if i % step == 0:
                    yield line
                    last = None
                else:
                    last = line
            if last is not None:
                yield last

    return Table(path, np.genfromtxt(decimated(), delimiter=",", names=True))


# Column prefix and unit suffix of each quantity in the CSV files, and the axis names of its
# frame: body FRD (x forward, y right, z down) or NED (north, east, down).
BODY = ["body x", "body y", "body z"]
NED = ["north", "east", "down"]
Q = {"err_a": ("err_a_n", "mps2", NED), "err_wdot": ("err_wdot_b", "rps2", BODY),
     "err_att": ("err_att_b", "rad", BODY), "err_v": ("err_v_n", "mps", NED),
     "err_r": ("err_r_n", "m", NED), "est_w": ("est_w_b", "rps", BODY),
     "est_v": ("est_v_n", "mps", NED), "est_r": ("est_r_n", "m", NED),
     "est_a": ("est_a_n", "mps2", NED)}


def column(d, key, i):
    pre, unit, _ = Q[key]
    return d[f"{pre}_{AXES[i]}_{unit}"]


# The paper's §6.3 navigation frame is not NED: gravity along its −z (docs/simulation.md).
PAPER_NAV = ["nav x", "nav y", "nav z"]


def plot_vec(ax, d, key, scale=1.0, label_prefix="", names=None, legend_size=7):
    if names is None or Q[key][2] is BODY:
        names = Q[key][2]
    t = d["t_s"]
    series = []
    for i in range(3):
        y = column(d, key, i) * scale
        series.append((f"{Q[key][0]}_{AXES[i]}_{Q[key][1]}", y))
        ax.plot(t, y, color=COLORS[i], lw=1, label=label_prefix + names[i])
    note_nonfinite(ax, series)
    ax.grid(True, alpha=0.3)
    # Only the bottom row names the time axis: in a column sharing it, a label on every row sits
    # between the panels, over the title or tick labels of the one below.
    spec = ax.get_subplotspec()
    if spec is None or spec.is_last_row():
        ax.set_xlabel("t (s)")
    ax.legend(loc="best", fontsize=legend_size)


def save(fig, path, dpi=80, rect=None):
    """rect: the part of the figure tight_layout fills (room left for a footnote)."""
    if rect is None:
        fig.tight_layout()
    else:
        fig.tight_layout(rect=rect)
    fig.savefig(path, dpi=dpi)
    plt.close(fig)
    print("  " + path)


def nav_errors(before, after, title, path, nav_names=None, dpi=80):
    fig, axs = plt.subplots(3, 2, figsize=(10, 7), sharex=True)
    rows = [("err_att", RAD2DEG, "attitude error, body (deg)"),
            ("err_v", 1, "velocity error, NED (m/s)"), ("err_r", 1, "position error, NED (m)")]
    for r, (pre, k, lab) in enumerate(rows):
        for c, (d, which) in enumerate([(before, "before"), (after, "after")]):
            plot_vec(axs[r][c], d, pre, k, names=nav_names, legend_size=8)
            axs[r][c].set_ylabel(lab if nav_names is None else lab.replace("NED", "nav frame"),
                                 fontsize=9)
            if r == 0:
                axs[r][c].set_title(which + " compensation")
    fig.suptitle(title, fontsize=11)
    save(fig, path, dpi=dpi)


def cmd_run(d, title):
    before = load(d + "/uncompensated.csv")
    after = load(d + "/compensated.csv")
    fig, axs = plt.subplots(2, 2, figsize=(10, 6), sharex=True)
    for c, (data, which) in enumerate([(before, "before"), (after, "after")]):
        plot_vec(axs[0][c], data, "err_a")
        axs[0][c].set_ylabel("linear accel. error, NED (m/s²)")
        axs[0][c].set_title(which + " compensation")
        plot_vec(axs[1][c], data, "err_wdot")
        axs[1][c].set_ylabel("angular accel. error, body (rad/s²)")
    fig.suptitle(f"acceleration errors: {title}", fontsize=10)
    save(fig, d + "/accel_errors.png")
    nav_errors(before, after, f"navigation errors: {title}", d + "/nav_errors.png")


def unwrap_deg(rad):
    """An angle in rad as deg without the 360° jump where it crosses ±180° (numpy.unwrap over
    the finite samples; the others stay NaN). The plotted rows must turn less than 180° from one
    to the next (at 1 kHz: under 180,000 °/s)."""
    out = np.full(rad.shape, np.nan)
    ok = np.isfinite(rad)
    out[ok] = np.degrees(np.unwrap(rad[ok]))
    return out


def cmd_replay(d, title):
    n = load(d + "/navigation.csv")
    q = np.stack([n["est_q_nb_" + c] for c in "wxyz"])
    w, x, y, z = q
    # Roll and yaw (±180°) are unwrapped: a turn through 180° is a continuous line, not a
    # vertical stroke across the panel. Pitch (±90°) does not wrap.
    roll = unwrap_deg(np.arctan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y)))
    pitch = np.degrees(np.arcsin(np.clip(2 * (w * y - z * x), -1, 1)))
    yaw = unwrap_deg(np.arctan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z)))
    fig, axs = plt.subplots(2, 2, figsize=(10, 7), sharex=True)
    for v, lab, c in zip((roll, pitch, yaw), ("roll", "pitch", "yaw"), COLORS):
        axs[0][0].plot(n["t_s"], v, color=c, lw=1, label=lab)
    note_nonfinite(axs[0][0], [("roll (est_q_nb_*)", roll), ("pitch (est_q_nb_*)", pitch),
                               ("yaw (est_q_nb_*)", yaw)])
    axs[0][0].set_ylabel("attitude, Z-Y-X Euler, body to NED (deg)\nroll and yaw unwrapped "
                         "(not kept in ±180°)", fontsize=9)
    axs[0][0].grid(True, alpha=0.3)
    axs[0][0].legend(loc="best", fontsize=7)
    plot_vec(axs[0][1], n, "est_w", RAD2DEG)
    axs[0][1].set_ylabel("angular rate, body (deg/s)")
    plot_vec(axs[1][0], n, "est_v")
    axs[1][0].set_ylabel("velocity, NED (m/s)")
    plot_vec(axs[1][1], n, "est_r")
    axs[1][1].set_ylabel("position from the alignment point, NED (m)")
    fig.suptitle(f"replay: {title}\n(t from the end of the alignment)", fontsize=10)
    save(fig, d + "/replay.png")


PAPER = {"before_lin": (-8, 2), "before_ang": (-0.1, 0.5), "after_lin": (-0.002, 0.003),
         "after_ang": (-0.003, 0.003)}
FIGS = [("fig7", "before", "err_a", "linear acceleration error before compensation (m/s²)",
         "before_lin"),
        ("fig8", "before", "err_wdot", "angular acceleration error before compensation (rad/s²)",
         "before_ang"),
        ("fig9", "after", "err_a", "linear acceleration error after compensation (m/s²)",
         "after_lin"),
        ("fig10", "after", "err_wdot", "angular acceleration error after compensation (rad/s²)",
         "after_ang")]
ASSUME = {"matching": "ρ=0.35 m, g along −z, 2 s at 100 Hz, σ=5e-4 m/s² Gaussian, true misalignment",
          "1mg": "ρ=0.35 m, g along −z, 2 s at 100 Hz, σ=1 mg=9.8e-3 m/s², true misalignment",
          "calibrated": "as matching, compensator from a simulated calibration (1 mg per pose mean)",
          "1mg-calibrated": "as 1mg, compensator from a simulated calibration (1 mg per pose mean)"}
# The §6.3 figures stand in for the paper's Figs. 7-10 in docs/simulation.md: 1200 × 720 px,
# with text of 9 pt and more (a 512 px figure with 6-8 pt text was not legible once shown).
PAPER_FIGSIZE, PAPER_DPI = (8, 4.8), 150


def cmd_paper63(d, core):
    for cfg, assume in ASSUME.items():
        data = {"before": load(f"{d}/{cfg}_before.csv"), "after": load(f"{d}/{cfg}_after.csv")}
        for fig_name, which, pre, title, key in FIGS:
            fig, ax = plt.subplots(figsize=PAPER_FIGSIZE)
            plot_vec(ax, data[which], pre, names=PAPER_NAV, legend_size=9)
            lo, hi = PAPER[key]
            ax.axhline(lo, color="k", ls="--", lw=0.8, label=f"paper's bounds [{lo:g}, {hi:g}]")
            ax.axhline(hi, color="k", ls="--", lw=0.8)
            # With 1 mg of noise the errors dwarf the paper's band (±0.003 in a ±0.1 plot looks
            # like one line at 0): say so on the figure, and show the band shaded.
            ymin, ymax = ax.get_ylim()
            if (hi - lo) < 0.05 * (ymax - ymin):
                ax.axhspan(lo, hi, color="k", alpha=0.15, lw=0)
                ax.text(0.99, 0.02, f"the paper's bounds [{lo:g}, {hi:g}] are the thin grey band "
                        f"at 0: this run's errors are {(ymax - ymin) / (hi - lo):.0f}× wider",
                        transform=ax.transAxes, ha="right", va="bottom", fontsize=9)
            ax.set_title(f"§6.3 {cfg} ({core} core):\n{title}", fontsize=11)
            unit = title[title.rindex("(") + 1:-1]
            frame = "nav frame" if pre == "err_a" else "body"
            ax.set_ylabel(f"{title.split(' error')[0]} error,\n{frame} ({unit})", fontsize=10)
            ax.tick_params(labelsize=9)
            ax.legend(fontsize=9, loc="best")
            fig.text(0.01, 0.015, assume, fontsize=9)
            save(fig, f"{d}/{fig_name}_{cfg}.png", dpi=PAPER_DPI, rect=(0, 0.05, 1, 1))
        nav_errors(data["before"], data["after"],
                   f"§6.3 navigation errors, {cfg} ({core} core)\n{assume}",
                   f"{d}/nav_errors_{cfg}.png", nav_names=PAPER_NAV, dpi=120)


# Log-log growth of the RMS norms: the kinematic exponents (docs/math.md, "Error growth without
# a gyroscope") of a residual constant over a run (calibration error: δω = c t, δθ = c t²/2) and
# of white noise alone (a random walk: √t and t^1.5). Both are drawn as slope references through the
# data at the start of the fit window, the last decade of the run (slopes.txt's), and only over
# it: which of them the curve follows is the statement, and the legend gives the fitted slope.
# Each quantity: its colour and a darker one for its references.
GROWTH = [("w_err_b_rps", "|ω error|", "deg/s", ("tab:red", "darkred"),
           [(1, "constant residual, δω = c t"), (0.5, "white noise, random walk")]),
          ("att_err_b_rad", "|attitude error|", "deg", ("tab:blue", "navy"),
           [(2, "constant residual, δθ = c t²/2"), (1.5, "white noise, integrated walk")])]


def loglog_slope(t, y, lo, hi):
    """Least-squares slope of log y against log t over [lo, hi], positive finite samples only
    (the fit of slopes.txt); NaN with fewer than two."""
    ok = np.isfinite(t) & np.isfinite(y) & (t > 0) & (y > 0) & (t >= lo) & (t <= hi)
    if ok.sum() < 2:
        return np.nan, ok
    return np.polyfit(np.log(t[ok]), np.log(y[ok]), 1)[0], ok


def cmd_montecarlo(d, title):
    m = load(d + "/montecarlo.csv")
    t = m["t_s"]
    qs = [("w_err_b_rps", RAD2DEG, "ω error (deg/s)"),
          ("att_err_b_rad", RAD2DEG, "attitude error (deg)"),
          ("v_err_n_mps", 1, "velocity error (m/s)"), ("r_err_n_m", 1, "position error (m)")]
    frames = [BODY, BODY, NED, NED]
    fig, axs = plt.subplots(4, 3, figsize=(13, 11), sharex=True)
    for r, ((q, k, lab), names) in enumerate(zip(qs, frames)):
        for a in range(3):
            ax = axs[r][a]
            mean = m[f"{q}_{AXES[a]}_mean"] * k
            sd = m[f"{q}_{AXES[a]}_std"] * k
            ax.fill_between(t, mean - 3 * sd, mean + 3 * sd, color=COLORS[a], alpha=0.15,
                            label="mean ± 3σ")
            ax.fill_between(t, mean - sd, mean + sd, color=COLORS[a], alpha=0.35,
                            label="mean ± 1σ")
            ax.plot(t, mean, color="k", lw=1, label="mean")
            note_nonfinite(ax, [(f"{q}_{AXES[a]}_mean", mean), (f"{q}_{AXES[a]}_std", sd)])
            ax.set_ylabel(f"{lab}, {names[a]}", fontsize=8)
            ax.grid(True, alpha=0.3)
            ax.legend(fontsize=6, loc="upper left")
    for ax in axs[-1]:
        ax.set_xlabel("t (s)")
    fig.suptitle(f"Monte-Carlo error envelopes over the runs: {title}", fontsize=10)
    save(fig, d + "/montecarlo_envelopes.png")

    fig, ax = plt.subplots(figsize=(8, 5.2))
    finite_t = t[np.isfinite(t) & (t > 0)]
    t_end = finite_t[-1] if finite_t.size else np.nan
    lo = 0.1 * t_end
    series = []
    for q, name, unit, (c, c_ref), refs in GROWTH:
        y = m[q + "_norm_rms"] * RAD2DEG
        series.append((q + "_norm_rms", y))
        pos = np.isfinite(t) & np.isfinite(y) & (t > 0) & (y > 0)
        slope, win = loglog_slope(t, y, lo, t_end)
        fit = f"{slope:.2f}" if np.isfinite(slope) else "none (fewer than 2 positive values)"
        ax.loglog(t[pos], y[pos], color=c, lw=1.8,
                  label=f"RMS {name} ({unit}): fitted slope {fit} over [{lo:.3g}, {t_end:.3g}] s")
        if not np.isfinite(slope):
            continue
        tw, i0 = t[win], np.flatnonzero(win)[0]
        for (p, why), ls in zip(refs, ["--", ":"]):
            ax.loglog(tw, y[i0] * (tw / t[i0]) ** p, color=c_ref, ls=ls, lw=1.2,
                      label=f"slope {p:g} reference: {why}")
    note_nonfinite(ax, series)
    if np.isfinite(t_end):
        ax.text(0.99, 0.02, f"slope references: through the data at t = {lo:.3g} s, drawn over the "
                f"fit window [{lo:.3g}, {t_end:.3g}] s\n(the last decade of the run)",
                transform=ax.transAxes, ha="right", va="bottom", fontsize=8)
    ax.set_xlabel("t (s)")
    ax.set_ylabel("RMS over the runs (|ω error|: deg/s, |attitude error|: deg)")
    ax.set_title(f"error growth: {title}", fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8, loc="upper left")
    save(fig, d + "/montecarlo_growth.png", dpi=100)


# gfins-sim aided: each row one quantity, unaided (left, symmetric-log scale: it grows by orders
# of magnitude, and a diverged run ends where its values stop being finite) and aided (right,
# linear, with the filter's ±3σ as dashed lines of the same colour).
AIDED_ROWS = [
    ("roll / pitch error (deg)", [("err_euler_roll_rad", "sigma_euler_roll_rad", "roll"),
                                  ("err_euler_pitch_rad", "sigma_euler_pitch_rad", "pitch")],
     RAD2DEG),
    ("heading error (deg)", [("err_euler_heading_rad", "sigma_euler_heading_rad", "heading")],
     RAD2DEG),
    ("velocity error, NED (m/s)", [(f"err_v_n_{a}_mps", f"sigma_v_n_{a}_mps", n)
                                   for a, n in zip(AXES, NED)], 1.0),
    ("position error, NED (m)", [(f"err_r_n_{a}_m", f"sigma_r_n_{a}_m", n)
                                 for a, n in zip(AXES, NED)], 1.0),
]


def shade_unavailable(ax, t, sigma):
    """Grey spans where the filter publishes no σ (before it starts, and after a divergence
    restart until the fixes set the quantity again): the values are marked not available."""
    missing = ~np.isfinite(sigma)
    if not missing.any():
        return
    edges = np.flatnonzero(np.diff(np.concatenate(([0], missing.astype(int), [0]))))
    for n, (a, b) in enumerate(zip(edges[::2], edges[1::2])):
        ax.axvspan(t[a], t[b - 1], color="0.88", lw=0,
                   label="σ not available" if n == 0 else None)


def cmd_aided(d, title):
    runs = [(load(d + "/unaided.csv"), "unaided"),
            (load(d + "/aided.csv"), "aided, ±3σ dashed (grey: σ not available)")]
    fig, axs = plt.subplots(len(AIDED_ROWS), 2, figsize=(12, 10), sharex=True)
    for r, (label, cols, k) in enumerate(AIDED_ROWS):
        for c, (data, which) in enumerate(runs):
            ax = axs[r][c]
            t = data["t_s"]
            series = []
            for i, (err, sig, name) in enumerate(cols):
                # The unaided run may diverge: its values end where they stop being finite.
                e = data.col(err, gaps_ok=c == 0) * k
                series.append((err, e))
                ax.plot(t, e, color=COLORS[i], lw=1, label=name)
                if c == 1:
                    # σ is NaN before the filter starts and where it is not available.
                    sigma = data.col(sig, gaps_ok=True)
                    if i == 0:
                        shade_unavailable(ax, t, sigma)
                    s3 = 3 * sigma * k
                    ax.plot(t, s3, color=COLORS[i], lw=0.8, ls="--")
                    ax.plot(t, -s3, color=COLORS[i], lw=0.8, ls="--")
            note_nonfinite(ax, series, gaps_ok=c == 0)
            if c == 0:
                finite = np.concatenate([np.abs(v[np.isfinite(v)]) for _, v in series])
                small = np.percentile(finite, 5) if finite.size else 1.0
                ax.set_yscale("symlog", linthresh=max(small, 1e-6))
            ax.grid(True, alpha=0.3)
            ax.set_ylabel(label, fontsize=8)
            ax.legend(loc="best", fontsize=7)
            if r == 0:
                ax.set_title(which)
            if r == len(AIDED_ROWS) - 1:
                ax.set_xlabel("t (s)")
    fig.suptitle(f"navigation errors, unaided and aided: {title}", fontsize=10)
    save(fig, d + "/accuracy.png")


def cmd_consistency(d, title):
    """Run-averaged NEES per epoch and NIS per GNSS fix, each divided by its degrees of freedom
    (1 expected), with the χ² 95 % bounds of the runs' total (gfins-sim consistency)."""
    # NaN rows are part of both files (no run published a σ, no run gated a fix): only a column
    # with no finite value is reported.
    nees = Table(d + "/nees.csv", np.genfromtxt(d + "/nees.csv", delimiter=",", names=True))
    nis = Table(d + "/nis.csv", np.genfromtxt(d + "/nis.csv", delimiter=",", names=True))
    panels = [(nees, "t_s", "", "NEES / dof (published states)"),
              (nis, "t_valid_s", "", "NIS / 3, GNSS position fixes"),
              (nis, "t_valid_s", "_b", "NIS / 3, GNSS velocity fixes")]
    fig, axs = plt.subplots(len(panels) + 1, 1, figsize=(11, 10), sharex=True)
    for ax, (data, tcol, sfx, label) in zip(axs, panels):
        if data.size == 0:
            ax.text(0.5, 0.5, "none", transform=ax.transAxes, ha="center")
            continue
        t = data[tcol]
        v, lo, hi = (data.col(c + sfx, gaps_ok=True) for c in ("value", "lo", "hi"))
        note_nonfinite(ax, [("value" + sfx, v), ("lo" + sfx, lo), ("hi" + sfx, hi)],
                       gaps_ok=True)
        ax.plot(t, v, color=COLORS[0], lw=0.8, marker=".", ms=2, label="run-averaged")
        ax.plot(t, lo, color="k", lw=0.8, ls="--", label="χ² 95 % bounds")
        ax.plot(t, hi, color="k", lw=0.8, ls="--")
        out = np.isfinite(v) & ((v < lo) | (v > hi))
        ax.plot(t[out], v[out], "x", color=COLORS[1], ms=4, label="outside")
        ax.set_yscale("log")
        ax.grid(True, alpha=0.3, which="both")
        ax.set_ylabel(label, fontsize=8)
        ax.legend(loc="best", fontsize=7)
    ax = axs[-1]
    groups = [(g, nees.col(g, gaps_ok=True)) for g in ["tilt", "heading", "velocity", "position"]]
    for i, (g, v) in enumerate(groups):
        ax.plot(nees["t_s"], v, color=GROUP_COLORS[i], lw=0.8, label=g)
    note_nonfinite(ax, groups, gaps_ok=True)
    ax.axhline(1.0, color="k", lw=0.8, ls=":", label="1 (consistent)")
    ax.set_yscale("log")
    ax.grid(True, alpha=0.3, which="both")
    ax.set_ylabel("NEES / dof by group", fontsize=8)
    ax.legend(loc="best", fontsize=7, ncol=5)
    axs[-1].set_xlabel("t (s)")
    fig.suptitle(f"filter consistency: {title}", fontsize=10)
    save(fig, d + "/consistency.png")


def main():
    cmds = {"run": cmd_run, "paper63": cmd_paper63, "montecarlo": cmd_montecarlo,
            "replay": cmd_replay, "aided": cmd_aided, "consistency": cmd_consistency}
    if len(sys.argv) not in (3, 4) or sys.argv[1] not in cmds:
        sys.exit(__doc__)
    default = "float32" if sys.argv[1] == "paper63" else sys.argv[2]
    cmds[sys.argv[1]](sys.argv[2], sys.argv[3] if len(sys.argv) == 4 else default)


if __name__ == "__main__":
    main()
