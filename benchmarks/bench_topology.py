"""The plant's generic E-series search (:func:`designer.plant.circuit.search`, written once against
the Topology) on every registered section, against the Sallen-Key low-pass's parallelogram search, its
fast path (:meth:`designer.filters.topology.Topology.fast_search`, which the same entry takes on the
Sallen-Key low-pass), on the same bounds, in the same run.

Goal (issue 26): with E24 resistors and E12 capacitors, the generic search (its candidate set,
``fast=False``) on each section within 2x the fast path's time through the search entry (median of 5,
the fast path measured between the sections so that the machine's load is shared). The entry's own time
on each section is shown beside (the fast path on the Sallen-Key low-pass, the candidate set elsewhere),
and the fast path called directly (:func:`designer.plant.selection.joint_search`), what the hook adds.
Targets: fn 3.5 kHz, zeta 0.2 (0.1 for the band-pass, none for a first-order section), the section's
example gain; default bounds R 1k..1M, C 1n..10u. ``python benchmarks/bench_topology.py NAME ...`` times
only those sections.
"""

from __future__ import annotations

import statistics
import sys
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


def main(names=None):
    rv, cv = values("E24", *BOUNDS["r"]), values("E12", *BOUNDS["c"])
    sk = registry.get(circuit.DEFAULT_TOPOLOGY)
    sk_target = circuit.plant_target(sk, FC, ZETA)
    fast = lambda: circuit.search(sk, sk_target, rv, cv, top=5)  # noqa: E731
    direct = lambda: joint_search(FC, ZETA, rv, cv, 1.0, top=5)  # noqa: E731
    fast(), direct()
    # interleaved, so that the machine's load falls on both alike
    pairs = [(median_time(fast, 3), median_time(direct, 3)) for _ in range(5)]
    t_fast, t_direct = (statistics.median(p[i] for p in pairs) for i in (0, 1))
    print(f"E24 resistors {len(rv)}, E12 capacitors {len(cv)}; fn {FC:g} Hz; top 5. The Sallen-Key fast path "
          f"through the search entry {t_fast:.4f} s, called directly {t_direct:.4f} s ({t_fast / t_direct:.2f}x: "
          "the hook's conversion to candidates).\n")
    print("| topology | generic search (s) | search entry (s) | fast path, same run (s) | ratio | goal | best error "
          "| entry's best error | verdict |")
    print("|---|---|---|---|---|---|---|---|---|")
    for name in names or registry.names():
        topo = registry.get(name)
        zeta = None if topo.order == 1 else (0.1 if topo.kind == "bandpass" else ZETA)
        target = circuit.plant_target(topo, FC, zeta, topo.example.gain)
        run = lambda: circuit.search(topo, target, rv, cv, top=5, fast=False)  # noqa: E731
        entry = lambda: circuit.search(topo, target, rv, cv, top=5)  # noqa: E731
        best, best_entry = run()[0], entry()[0]
        t_gen, t_entry, t_fast = median_time(run), median_time(entry), median_time(fast)
        ratio = t_gen / t_fast
        print(f"| {name} | {t_gen:.4f} | {t_entry:.4f} | {t_fast:.4f} | {ratio:.2f} | <= {GOAL:g} | "
              f"{100 * best.worst:.3g} % | {100 * best_entry.worst:.3g} % | {'ok' if ratio <= GOAL else 'MISSED'} |")


if __name__ == "__main__":
    main(sys.argv[1:] or None)
