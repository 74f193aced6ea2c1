"""The plant's generic E-series search (:func:`designer.plant.circuit.search`, written once against
the Topology) on every registered section, against the Sallen-Key low-pass's parallelogram search
(:func:`designer.plant.selection.joint_search`, its fast path) on the same bounds, in the same run.

Goal (issue 26): with E24 resistors and E12 capacitors, the generic search on each section within
2x the fast path's time (median of 5, the fast path measured between the sections so that the
machine's load is shared). Targets: fn 3.5 kHz, zeta 0.2 (0.1 for the band-pass, none for a
first-order section), the section's example gain; default bounds R 1k..1M, C 1n..10u.
"""

from __future__ import annotations

import statistics
import time

from designer.core.eseries import values
from designer.filters import registry
from designer.plant import circuit
from designer.plant.selection import joint_search

GOAL = 2.0
FC, ZETA = 3500.0, 0.2
BOUNDS = dict(r=(1e3, 1e6), c=(1e-9, 1e-5))


def median_time(fn, repeat: int = 5) -> float:
    """Median wall time of ``repeat`` calls."""
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return statistics.median(times)


def main():
    rv, cv = values("E24", *BOUNDS["r"]), values("E12", *BOUNDS["c"])
    fast = lambda: joint_search(FC, ZETA, rv, cv, 1.0, top=5)  # noqa: E731
    fast()
    print(f"E24 resistors {len(rv)}, E12 capacitors {len(cv)}; fn {FC:g} Hz; top 5.\n")
    print("| topology | generic search (s) | fast path, same run (s) | ratio | goal | best error | verdict |")
    print("|---|---|---|---|---|---|---|")
    for name in registry.names():
        topo = registry.get(name)
        zeta = None if topo.order == 1 else (0.1 if topo.kind == "bandpass" else ZETA)
        target = circuit.plant_target(topo, FC, zeta, topo.example.gain)
        run = lambda: circuit.search(topo, target, rv, cv, top=5)  # noqa: E731
        best = run()[0]
        t_gen, t_fast = median_time(run), median_time(fast)
        ratio = t_gen / t_fast
        print(f"| {name} | {t_gen:.4f} | {t_fast:.4f} | {ratio:.2f} | <= {GOAL:g} | {100 * best.worst:.3g} % | "
              f"{'ok' if ratio <= GOAL else 'MISSED'} |")


if __name__ == "__main__":
    main()
