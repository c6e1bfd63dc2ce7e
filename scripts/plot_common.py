"""What the plot scripts share (imported from the scripts' own folder, where it is installed too).

note_nonfinite: the on-panel note for series that hold non-finite values, so that a plot of
mutated or partial data says so instead of drawing empty or meaningless axes.
"""
import math


def note_nonfinite(ax, series, gaps_ok=False):
    """Say on the panel which of its series, (name, values) pairs, hold no finite value (in the
    middle, the panel's axes being otherwise meaningless) or, unless gaps_ok, some non-finite
    ones (a corner note: the line has gaps there). The warning on stderr names the file."""
    def finite(values):
        return [math.isfinite(float(x)) for x in values]

    empty = [n for n, v in series if not any(finite(v))]
    gaps = [] if gaps_ok else [n for n, v in series if n not in empty and not all(finite(v))]
    if empty:
        ax.text(0.5, 0.5, "no finite values:\n" + "\n".join(empty), transform=ax.transAxes,
                ha="center", va="center", fontsize=9, color="tab:red",
                bbox={"facecolor": "white", "edgecolor": "tab:red", "alpha": 0.9})
    if gaps:
        ax.text(0.99, 0.02, "non-finite values left out: " + ", ".join(gaps),
                transform=ax.transAxes, ha="right", va="bottom", fontsize=7, color="tab:red")
