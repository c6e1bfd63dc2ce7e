#!/usr/bin/env python3
"""Figures of gfins-sim (docs/simulation.md). Called by gfins-sim itself:

    plot_sim.py run DIR          DIR/{uncompensated,compensated}.csv → DIR/*.png
    plot_sim.py paper63 DIR      DIR/<config>_{before,after}.csv → Figs. 7-10 and navigation errors
    plot_sim.py montecarlo DIR   DIR/montecarlo.csv → envelopes and log-log growth

Matplotlib with the Agg backend (no display needed); numpy comes with matplotlib.
"""
import sys

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


def load(path):
    return np.genfromtxt(path, delimiter=",", names=True)


def plot_vec(ax, d, prefix, scale=1.0, label_prefix=""):
    for i, a in enumerate(AXES):
        ax.plot(d["t_s"], d[prefix + a] * scale, color=COLORS[i], lw=1, label=label_prefix + a)
    ax.grid(True, alpha=0.3)
    ax.set_xlabel("t (s)")


def save(fig, path):
    fig.tight_layout()
    fig.savefig(path, dpi=80)
    plt.close(fig)
    print("  " + path)


def nav_errors(before, after, title, path):
    fig, axs = plt.subplots(3, 2, figsize=(10, 7), sharex=True)
    rows = [("err_att", 180 / np.pi, "attitude error (deg)"), ("err_v", 1, "velocity error (m/s)"),
            ("err_r", 1, "position error (m)")]
    for r, (pre, k, lab) in enumerate(rows):
        for c, (d, which) in enumerate([(before, "before"), (after, "after")]):
            plot_vec(axs[r][c], d, pre, k)
            axs[r][c].set_ylabel(lab)
            if r == 0:
                axs[r][c].set_title(which + " compensation")
    axs[0][0].legend(loc="best", fontsize=8)
    fig.suptitle(title, fontsize=10)
    save(fig, path)


def cmd_run(d):
    before = load(d + "/uncompensated.csv")
    after = load(d + "/compensated.csv")
    fig, axs = plt.subplots(2, 2, figsize=(10, 6), sharex=True)
    for c, (data, which) in enumerate([(before, "before"), (after, "after")]):
        plot_vec(axs[0][c], data, "err_a")
        axs[0][c].set_ylabel("linear accel. error (m/s²)")
        axs[0][c].set_title(which + " compensation")
        plot_vec(axs[1][c], data, "err_wdot")
        axs[1][c].set_ylabel("angular accel. error (rad/s²)")
    axs[0][0].legend(fontsize=8)
    save(fig, d + "/accel_errors.png")
    nav_errors(before, after, d, d + "/nav_errors.png")


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


def cmd_paper63(d):
    for cfg, assume in ASSUME.items():
        data = {"before": load(f"{d}/{cfg}_before.csv"), "after": load(f"{d}/{cfg}_after.csv")}
        for fig_name, which, pre, title, key in FIGS:
            fig, ax = plt.subplots(figsize=(6.4, 3.6))
            plot_vec(ax, data[which], pre)
            lo, hi = PAPER[key]
            ax.axhline(lo, color="k", ls="--", lw=0.8, label="paper's bounds")
            ax.axhline(hi, color="k", ls="--", lw=0.8)
            ax.set_title(title, fontsize=9)
            ax.legend(fontsize=7, loc="best")
            fig.text(0.01, 0.01, assume, fontsize=6)
            save(fig, f"{d}/{fig_name}_{cfg}.png")
        nav_errors(data["before"], data["after"], f"§6.3 navigation errors, {cfg}: {assume}",
                   f"{d}/nav_errors_{cfg}.png")


def cmd_montecarlo(d):
    m = load(d + "/montecarlo.csv")
    t = m["t_s"]
    qs = [("w_err_b_rps", 1, "ω error (rad/s)"), ("att_err_b_rad", 180 / np.pi, "attitude error (deg)"),
          ("v_err_n_mps", 1, "velocity error (m/s)"), ("r_err_n_m", 1, "position error (m)")]
    fig, axs = plt.subplots(2, 2, figsize=(10, 7), sharex=True)
    for ax, (q, k, lab) in zip(axs.flat, qs):
        mean = m[q + "_x_mean"] * k
        sd = m[q + "_x_std"] * k
        ax.fill_between(t, mean - 3 * sd, mean + 3 * sd, color="tab:blue", alpha=0.15, label="±3σ")
        ax.fill_between(t, mean - sd, mean + sd, color="tab:blue", alpha=0.35, label="±1σ")
        ax.plot(t, mean, color="k", lw=1, label="mean")
        ax.set_ylabel(lab + ", x axis")
        ax.grid(True, alpha=0.3)
    axs[0][0].legend(fontsize=8)
    for ax in axs[1]:
        ax.set_xlabel("t (s)")
    save(fig, d + "/montecarlo_envelopes.png")

    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    sel = t > 0
    for (q, k, lab), c, p in zip(qs[:2], ["tab:red", "tab:blue"], [1, 2]):
        y = m[q + "_norm_rms"][sel]
        ax.loglog(t[sel], y, color=c, label="RMS |" + lab.split(" (")[0] + "|")
        i = np.searchsorted(t[sel], t[-1] / 10)
        ref = y[-1] * (t[sel] / t[-1]) ** p
        ax.loglog(t[sel][i:], ref[i:], color=c, ls="--", lw=0.8, label=f"∝ t^{p} (kinematics)")
    ax.set_xlabel("t (s)")
    ax.set_ylabel("RMS over runs (rad/s, rad)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    save(fig, d + "/montecarlo_growth.png")


def main():
    if len(sys.argv) != 3 or sys.argv[1] not in ("run", "paper63", "montecarlo"):
        sys.exit(__doc__)
    {"run": cmd_run, "paper63": cmd_paper63, "montecarlo": cmd_montecarlo}[sys.argv[1]](sys.argv[2])


if __name__ == "__main__":
    main()
