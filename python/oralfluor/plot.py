"""matplotlib helpers for chromaticity plots (imported on demand: matplotlib is optional)."""
import numpy as np

# One colour per library fluorophore, stable across plots.
_COLOURS = {"FAD": "#2ca02c", "NADH": "#1f77b4", "collagen": "#17becf", "elastin": "#9467bd", "keratin": "#8c564b",
            "protoporphyrin": "#d62728", "chlorophyll_a": "#bcbd22", "teeth": "#7f7f7f"}


def plot_reference_lines(ax, ref, labels=True):
    """Draws the fluorophore reference lines of ``oralfluor.reference_lines`` on a matplotlib axis:
    each line from the tongue-reflectance point (black dot) toward the pure fluorophore (open circle)."""
    for i, line in enumerate(ref["lines"]):
        rg = np.asarray(line["rg"])
        colour = _COLOURS.get(line["fluorophore"], f"C{i}")
        ax.plot(rg[:, 0], rg[:, 1], "-", color=colour, lw=1.5, label=line["fluorophore"] if labels else None)
        ax.plot(*line["pure_rg"], "o", mfc="none", color=colour, ms=6)
    ax.plot(*ref["tongue_rg"], "ko", ms=5, label="tongue reflectance" if labels else None)
    ax.set_xlabel("r = R / (R + G + B)")
    ax.set_ylabel("g = G / (R + G + B)")
    ax.set_aspect("equal", adjustable="datalim")
    ax.grid(True, lw=0.3)


def plot_ellipse(ax, stats, colour="k", label=None):
    """The 95 % ellipse and mean of ``oralfluor.chromaticity`` statistics."""
    e = stats["ellipse95"]
    t = np.linspace(0, 2 * np.pi, 100)
    ang = np.radians(e["angle_deg"])
    ca, sa = np.cos(ang), np.sin(ang)
    x = e["semi_axes"][0] * np.cos(t)
    y = e["semi_axes"][1] * np.sin(t)
    ax.plot(e["center"][0] + ca * x - sa * y, e["center"][1] + sa * x + ca * y, "-", color=colour, lw=1, label=label)
    ax.plot(stats["mean"]["r"], stats["mean"]["g"], "+", color=colour, ms=8)
