"""Plots for the build sheets and the identification results: matplotlib
figures rendered to PNG bytes (imported only when a plot is drawn)."""

from __future__ import annotations

import io

import numpy as np


def png_bytes(fig) -> bytes:
    """A matplotlib figure as PNG bytes (the figure is closed)."""
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110, bbox_inches="tight")
    import matplotlib.pyplot as plt
    plt.close(fig)
    return buf.getvalue()


def step_plot(t, curves: dict, title: str, ylabel: str = "output (V)") -> bytes:
    """Overlaid step responses; ``curves`` maps a label to an array on ``t``."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7.5, 4))
    styles = ["-", "--", ":", "-."]
    for i, (label, y) in enumerate(curves.items()):
        if y is not None:
            ax.plot(np.asarray(t) * 1e6, y, styles[i % 4], label=label, lw=1.6 if i == 0 else 1.3)
    ax.set_xlabel("time after the step (us)")
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.grid(True, alpha=0.3)
    ax.legend()
    return png_bytes(fig)


def bode_plot(systems: dict, f_lo: float, f_hi: float, title: str) -> bytes:
    """Magnitude (dB) and phase (deg) of transfer functions ``{label: (num, den)}``."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from ..core.lti import freq_response
    f = np.logspace(np.log10(f_lo), np.log10(f_hi), 600)
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(7.5, 5.5), sharex=True)
    for i, (label, (num, den)) in enumerate(systems.items()):
        h = freq_response(num, den, f)
        a1.semilogx(f, 20 * np.log10(np.abs(h)), ["-", "--", ":"][i % 3], label=label)
        a2.semilogx(f, np.degrees(np.unwrap(np.angle(h))), ["-", "--", ":"][i % 3], label=label)
    a1.set_ylabel("gain (dB)")
    a2.set_ylabel("phase (deg)")
    a2.set_xlabel("frequency (Hz)")
    a1.set_title(title)
    for a in (a1, a2):
        a.grid(True, which="both", alpha=0.3)
    a1.legend()
    return png_bytes(fig)
