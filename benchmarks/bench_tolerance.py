"""The analytic plant Monte Carlo (issue 17): the seed's plant as built
(1k6 / 3k9 / 3n3 / 100n, E24/E12 tolerances) with LM741s, 10^5 and 10^6 builds
with two limits and no tightening search. Goals: 10^5 under 1 s, 10^6 under 10 s
within 1 GiB (tracemalloc's peak: numpy's allocations). The floor: numpy drawing
the same number of uniform samples (``rng.random((n, 4))``) in the same run.

The loop's Monte Carlo (one state-space model per build, not vectorised): the
optimised LM741 loop for the seed's plant, 1000 builds, its time per build (no goal
in the issue for it; the README states it).
"""

from __future__ import annotations

import time
import tracemalloc

import numpy as np

GOALS = {10 ** 5: 1.0, 10 ** 6: 10.0}
MEMORY_GOAL_MB = 1024.0


def main():
    from designer.core import opamps
    from designer.plant.sallenkey import SallenKeyParts
    from designer.tolerance.montecarlo import plant_monte_carlo
    parts, amp = SallenKeyParts(1.6e3, 3.9e3, 3.3e-9, 100e-9), opamps.get("LM741")
    plant_monte_carlo(parts, {"R": "E24", "C": "E12"}, amp, 1000, tighten=False)   # warm: imports, first calls
    print("| builds | seconds | goal | numpy floor (s) | peak MB | verdict |")
    print("|---|---|---|---|---|---|")
    for n, goal in GOALS.items():
        t = time.perf_counter()
        np.random.default_rng(0).random((n, 4))
        floor = time.perf_counter() - t
        tracemalloc.start()
        t = time.perf_counter()
        mc = plant_monte_carlo(parts, {"R": "E24", "C": "E12"}, amp, n, seed=1,
                               limit_items=["fn_hz=3.3k:3.7k", "overshoot_pct=0:55"], tighten=False)
        took = time.perf_counter() - t
        peak = tracemalloc.get_traced_memory()[1] / 2 ** 20
        tracemalloc.stop()
        ok = took <= goal and peak <= MEMORY_GOAL_MB
        print(f"| {n:.0e} | {took:.3f} | {goal:g} s, {MEMORY_GOAL_MB:g} MB | {floor:.4f} | {peak:.0f} | "
              f"{'ok' if ok else 'MISSED'} |")
        assert mc.n == n
    from designer.pid.design import design_pid
    from designer.pid.spec import PidSpec
    from designer.tolerance.loop import loop_monte_carlo
    res = design_pid(PidSpec(plant_fc_hz=3500, plant_zeta=0.2, tuning="optimize", target_overshoot_pct=10),
                     simulate=False)
    loop_monte_carlo(res, {"R": "E24", "C": "E12"}, 20)     # warm
    t = time.perf_counter()
    loop = loop_monte_carlo(res, {"R": "E24", "C": "E12"}, 1000, seed=1)
    took = time.perf_counter() - t
    print(f"\nThe loop's Monte Carlo (22 parts, the optimised LM741 loop): 1000 builds in {took:.2f} s, "
          f"{1e3 * took / 1000:.1f} ms a build; unstable {loop.to_dict()['p_unstable']['count']} of 1000.")
    print("\nThe yield of the 10^6 run: "
          f"{100 * mc.yield_count / mc.n:.2f} % (95 % Wilson {', '.join(f'{100 * x:.2f}' for x in mc.yield_interval())} %).")


if __name__ == "__main__":
    main()
