"""identify: every step method on a 1,000,000-sample capture.

The capture is the seed 001 plant (fn 3500 Hz, zeta 0.2) driven by a 2 V step,
with 1 % white noise and an input column, as a long-memory scope would record
it. Goal on the 2-core machine: identify_step (all classical methods, the
three least-squares fits, IAE/ISE of every model on all samples) under 2 s.
Also timed: reading the 1M-row CSV, and the ``identify`` command end to end.

Memory (issue 7, item 8: a 5M-row capture took 977 MB, 8x the file, and
``/dev/zero`` was read until the kernel killed it): the peak resident memory
of the ``identify`` command on the 1M-row and on a 5M-row capture. Goal: at
most 1.5x the file's size plus 150 MB for the interpreter and libraries.
"""

from __future__ import annotations

import math
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from designer.identify.against import model_fn_zeta
from designer.identify.io import read_capture
from designer.identify.step import identify_step
from designer.identify.structures import model_step

N = 1_000_000
GOAL_S = 2.0
N_BIG = 5_000_000
MEM_FACTOR, MEM_BASE_MB = 1.5, 150.0


def write_capture(path, t, u, y) -> float:
    """The t,u,y capture as a scope would export it; returns its size in MB."""
    with open(path, "w") as fh:
        fh.write("time_s,vin,vout\n")
        np.savetxt(fh, np.column_stack([t, u, y]), delimiter=",", fmt="%.9e")
    return path.stat().st_size / 1e6


#: ``identify`` in a fresh interpreter that reports its own peak memory. The
#: kernel's ru_maxrss of a child counts the parent's pages at fork time, so a
#: large benchmark process would inflate it; VmHWM is the new image's own.
_PEAK = ("import sys\n"
         "from designer.cli.identify import identify_main\n"
         "rc = identify_main(sys.argv[1:])\n"
         "hwm = [ln for ln in open('/proc/self/status') if ln.startswith('VmHWM')][0]\n"
         "print(int(hwm.split()[1]) / 1024.0, file=sys.stderr)\n"
         "sys.exit(rc)\n")


def peak_rss_mb(args, expect: int = 0) -> tuple:
    """(wall seconds, peak resident MB) of ``identify args`` in its own process."""
    t0 = time.perf_counter()
    proc = subprocess.run([sys.executable, "-c", _PEAK, *args], stdout=subprocess.DEVNULL,
                          stderr=subprocess.PIPE, text=True)
    wall = time.perf_counter() - t0
    if proc.returncode != expect:
        raise RuntimeError(f"identify {args} exited {proc.returncode}: {proc.stderr.strip()}")
    return wall, float(proc.stderr.strip().splitlines()[-1])


def capture(n=N, seed=0):
    a, b = 2.0677e-9, 1.8189e-5
    wn = 1 / math.sqrt(a)
    p = {"K": 1.0, "wn_rad_s": wn, "zeta": b * wn / 2, "theta_s": 0.0}
    t = np.linspace(-0.2e-3, 2e-3, n)
    u = np.where(t >= 0, 2.0, 0.0)
    y = 2.0 * model_step("underdamped", p, t) + 0.02 * np.random.default_rng(seed).standard_normal(n)
    return t, u, y, p


def main():
    t, u, y, p = capture()
    runs = []
    for _ in range(3):
        r = identify_step(t, y, u)
        runs.append(r.timings)
    med = {k: statistics.median(x[k] for x in runs) for k in runs[0]}
    fn, z = model_fn_zeta(r.best)
    fn0, z0 = p["wn_rad_s"] / (2 * math.pi), p["zeta"]
    print(f"### identify_step on {N:,} samples (seed 001 plant, 1 % noise), median of 3\n")
    print(f"{len(r.methods)} method results ({sum(m.valid for m in r.methods)} valid); best "
          f"{r.best.name} ({r.best.model}): fn {fn:.1f} Hz (truth {fn0:.1f}, "
          f"{100 * (fn / fn0 - 1):+.3f} %), zeta {z:.5f} (truth {z0:.5f}, "
          f"{100 * (z / z0 - 1):+.3f} %)\n")
    print("| phase | seconds |")
    print("|---|---|")
    for k in ("prepare", "methods", "score", "refine", "measure"):
        print(f"| {k} | {med[k]:.3f} |")
    print(f"| **total** (goal < {GOAL_S:g} s) | **{med['total']:.3f}** "
          f"{'ok' if med['total'] < GOAL_S else 'OVER GOAL'} |")

    exe = Path(sys.executable).parent / "identify"
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "capture.csv"
        size_mb = write_capture(path, t, u, y)
        reads = []
        for _ in range(3):
            t0 = time.perf_counter()
            read_capture(path)
            reads.append(time.perf_counter() - t0)
        walls = []
        for _ in range(3):
            t0 = time.perf_counter()
            proc = subprocess.run([str(exe), str(path), "--json"], capture_output=True, text=True)
            walls.append(time.perf_counter() - t0)
            if proc.returncode != 0:
                raise RuntimeError(proc.stderr.strip())
    print(f"\n### 1M-row CSV ({size_mb:.0f} MB), median of 3\n")
    print("| step | seconds |")
    print("|---|---|")
    print(f"| read_capture | {statistics.median(reads):.3f} |")
    print(f"| `identify capture.csv --json` end to end (new process) | {statistics.median(walls):.3f} |")

    print("\n### Peak memory of `identify capture.csv --json` (new process)\n")
    print(f"Goal: at most {MEM_FACTOR:g} x the file + {MEM_BASE_MB:g} MB.\n")
    print("| capture | file MB | seconds | peak MB | goal MB | |")
    print("|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        for n in (N, N_BIG):
            tb, ub, yb, _ = capture(n)
            path = Path(tmp) / f"capture_{n}.csv"
            size_mb = write_capture(path, tb, ub, yb)
            del tb, ub, yb
            wall, peak = peak_rss_mb([str(path), "--json"])
            goal = MEM_FACTOR * size_mb + MEM_BASE_MB
            print(f"| {n:,} rows | {size_mb:.0f} | {wall:.2f} | {peak:.0f} | {goal:.0f} | "
                  f"{'ok' if peak <= goal else 'OVER GOAL'} |")
            path.unlink()
        wall, peak = peak_rss_mb(["/dev/zero"], expect=2)
        print(f"| `/dev/zero` (refused: not a text file) | - | {wall:.2f} | {peak:.0f} | "
              f"{MEM_BASE_MB:g} | {'ok' if peak <= MEM_BASE_MB else 'OVER GOAL'} |")


if __name__ == "__main__":
    main()
