"""identify-freq and the second-order step methods: how long they take.

1. ``identify_freq`` (asymptotes, resonant peak, three least-squares fits)
   on seed 000 Table IV (14 points) and on a 200-point synthetic table of an
   underdamped plant with dead time and 1 % noise.
2. Every second-order step method (``second_order.STEP_METHODS``) on a
   1,000,000-sample noisy step response of the seed 001 plant
   (fn 3500 Hz, zeta 0.2, 1 % noise): each method alone and all of them.

Goal on the 2-core machine: all second-order methods together on 1e6 samples
well under the issue's 2 s budget for every method; a frequency table in
under 0.5 s.
"""

from __future__ import annotations

import math
import statistics
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from designer.identify import bode_readings as br
from designer.identify import frequency as fr
from designer.identify import io as tio
from designer.identify import second_order as so
from designer.identify.structures import model_step

N = 1_000_000
FIX = Path(__file__).resolve().parent.parent / "tests" / "fixtures" / "identify_freq"


def _median_time(fn, repeat=3):
    times = []
    out = None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), out


def step_capture(n=N, seed=0):
    a, b = 2.0677e-9, 1.8189e-5
    wn = 1 / math.sqrt(a)
    p = {"K": 1.0, "wn_rad_s": wn, "zeta": b * wn / 2, "theta_s": 0.0}
    t = np.linspace(0.0, 2e-3, n)
    y = model_step("underdamped", p, t) + 0.01 * np.random.default_rng(seed).standard_normal(n)
    return t, y, p


def noisy_table(n=200, seed=1):
    rng = np.random.default_rng(seed)
    p = {"K": 1.0, "wn_rad_s": 2 * math.pi * 3500, "zeta": 0.2, "theta_s": 2e-6}
    w = np.geomspace(0.01, 30, n) * p["wn_rad_s"]
    g = br.model_response("underdamped", p, w) * (1 + 0.01 * rng.standard_normal(n))
    ph = br.model_phase("underdamped", p, w) + np.deg2rad(0.5) * rng.standard_normal(n)
    return tio.freq_data(w, np.abs(g), ph, gain_units="ratio", phase_units="rad",
                        freq_units="rad/s"), p


def main():
    print("### identify-freq: frequency-response fits (median of 3)\n")
    print("| table | points | time (ms) | best | parameters |")
    print("|---|---:|---:|---|---|")
    fr.identify_freq(tio.read_freq_table(FIX / "seed000_table4_deg.csv"))     # warm imports
    cases = [("seed 000 Table IV", tio.read_freq_table(FIX / "seed000_table4_deg.csv")),
             ("seed 003 Table 3.1", tio.read_freq_table(FIX / "seed003_table31.csv")),
             ("synthetic, 1 % noise (wn 21991 rad/s, zeta 0.2, theta 2 us)", noisy_table()[0])]
    for label, d in cases:
        dt, res = _median_time(lambda d=d: fr.identify_freq(d))
        b = res.best
        params = ", ".join(f"{k} {v:.4g}" for k, v in b.params.items()) if b else "none"
        print(f"| {label} | {d.w.size} | {1e3 * dt:.1f} | {b.name} ({b.model}) | {params} |")

    exe = Path(sys.executable).with_name("identify-freq")
    if exe.exists():
        dt, _ = _median_time(lambda: subprocess.run(
            [str(exe), str(FIX / "seed000_table4_deg.csv"), "--json"], capture_output=True,
            check=True))
        print(f"| `identify-freq seed000_table4_deg.csv --json` end to end (new process) | 14 "
              f"| {1e3 * dt:.0f} | | |")

    t, y, p = step_capture()
    print(f"\n### second-order step methods on {N:,} samples (seed 001 plant, 1 % noise; "
          f"true wn {p['wn_rad_s']:.0f} rad/s, zeta {p['zeta']:.4f}), median of 3\n")
    print("| method | time (ms) | valid | wn (rad/s) or tau1, tau2 (s) | zeta |")
    print("|---|---:|---|---|---:|")
    total = 0.0
    for m in so.STEP_METHODS:
        dt, r = _median_time(lambda m=m: m(t, y, 1.0))
        total += dt
        if r.model == "underdamped":
            a, z = f"{r.params['wn_rad_s']:.5g}", f"{r.params['zeta']:.4f}"
        elif r.model == "overdamped":
            a, z = f"{r.params['tau1_s']:.3g}, {r.params['tau2_s']:.3g}", ""
        else:
            a, z = f"tau {r.params.get('tau_s', math.nan):.3g}", ""
        print(f"| {r.name} | {1e3 * dt:.1f} | {'yes' if r.valid else 'no'} | {a} | {z} |")
    print(f"| **all {len(so.STEP_METHODS)}** | **{1e3 * total:.0f}** | | | |")


if __name__ == "__main__":
    main()
