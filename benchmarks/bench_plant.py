"""design-plant: joint E-series search time and optimality against brute force,
and end-to-end wall time split by phase.

Goals (2-core machine): E24/E12 search < 0.2 s, E96/E24 < 1 s, design-plant
end to end < 3 s.
"""

from __future__ import annotations

import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from designer.eseries import values
from designer.selection import joint_search

SPECS = [(3500, 0.2), (1000, 0.707), (50, 0.05), (20e3, 1.5)]


def best_brute_force(fn0, zeta0, rv, cv):
    """Exhaustive minimum of max(|fn err|, |zeta err|), one C1 at a time to bound memory."""
    best = np.inf
    r1, r2 = np.meshgrid(rv, rv, indexing="ij")
    for c1 in cv:
        for c2 in cv:
            a = r1 * r2 * c1 * c2
            sa = np.sqrt(a)
            fn = 1 / (2 * np.pi * sa)
            z = c1 * (r1 + r2) / (2 * sa)
            best = min(best, float(np.maximum(np.abs(fn / fn0 - 1), np.abs(z / zeta0 - 1)).min()))
    return best


def timed(fn, repeat=5):
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t)
    return statistics.median(times), out


def main():
    print("### Joint search against brute force\n")
    print("| series R/C | spec (fn, zeta) | combinations | search median (s) | goal (s) | best worst-error | "
          "brute force | same optimum |")
    print("|---|---|---|---|---|---|---|---|")
    for rs, cs, goal in (("E24", "E12", 0.2), ("E96", "E24", 1.0)):
        rv, cv = values(rs, 1e3, 1e6), values(cs, 1e-9, 1e-5)
        for fn0, z0 in SPECS:
            t, res = timed(lambda: joint_search(fn0, z0, rv, cv, top=5))
            bf = best_brute_force(fn0, z0, rv, cv)
            print(f"| {rs}/{cs} | {fn0:g} Hz, {z0:g} | {rv.size ** 2 * cv.size ** 2:,} | {t:.3f} | {goal} | "
                  f"{100 * res[0].worst:.4f} % | {100 * bf:.4f} % | {'yes' if abs(res[0].worst - bf) < 1e-12 else 'NO'} |")

    print("\n### design-plant --fc 3500 --zeta 0.2, in process (median of 3)\n")
    from designer.plant import PlantSpec, design_plant
    from designer.plant_report import write_outputs
    rows = []
    for _ in range(3):
        with tempfile.TemporaryDirectory() as tmp:
            r = design_plant(PlantSpec(3500, 0.2))
            write_outputs(r, tmp, "bench")
            rows.append(r.timings)
    print("| phase | seconds |")
    print("|---|---|")
    for key in ("search_s", "analytic_s", "netlist_s", "simulation_s", "report_s"):
        print(f"| {key[:-2]} | {statistics.median(t[key] for t in rows):.3f} |")

    print("\n### design-plant end to end (new process each run, median of 3; goal < 3 s)\n")
    exe = Path(sys.executable).parent / "design-plant"
    imp = []
    walls = []
    for _ in range(3):
        t = time.perf_counter()
        subprocess.run([sys.executable, "-c", "import designer.cli, designer.plant, designer.plant_report"],
                       check=True)
        imp.append(time.perf_counter() - t)
        with tempfile.TemporaryDirectory() as tmp:
            t = time.perf_counter()
            subprocess.run([str(exe), "--fc", "3500", "--zeta", "0.2", "--out", tmp, "--json"], check=True,
                           capture_output=True)
            walls.append(time.perf_counter() - t)
    print("| measure | seconds |")
    print("|---|---|")
    print(f"| interpreter start + imports | {statistics.median(imp):.3f} |")
    print(f"| whole command (pyspice backend, files written) | {statistics.median(walls):.3f} |")


if __name__ == "__main__":
    main()
