"""Active filters (issue 27): the joint E-series choice, design-filter end to end, and the
analytic Monte Carlo of a cascade.

- Joint choice: an 8th-order Butterworth low-pass at 1 kHz, E24 resistors and E12
  capacitors (LM741), its branch and bound (:func:`designer.filters.joint.joint_search`)
  on the design's own candidate sets and objective grid; goals under 2 s and 200 MB
  (tracemalloc's peak). Brute force: the project's reference enumeration
  (:func:`designer.filters.joint.brute_force`, one combination at a time), and the floor,
  the exhaustive enumeration of the same product vectorised with numpy (every
  combination's worst deviation, in blocks), in the same run; the speed-ups are their
  times over the search's, and all three find the same J.
- design-filter end to end: the same filter designed and proven (candidates, search, the
  SPICE proof's ngspice run and its comparison, the deck) in one process, against the
  bare ``ngspice -b`` of the deck the command writes plus its own search time; goal:
  within 4x that (best of three each). The whole command (a new process: its imports)
  is shown beside it.
- Monte Carlo: 10^5 analytic builds of the 8th-order cascade (every part of its four
  stages, the mask's figures, no tightening); goal under 5 s. The floor: numpy drawing
  as many uniform samples (``rng.random((n, parts))``) in the same run.
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import time
import tracemalloc
from pathlib import Path

import numpy as np

JOINT_GOAL_S, JOINT_GOAL_MB = 2.0, 200.0
END_TO_END_FACTOR = 4.0
MC_BUILDS, MC_GOAL_S = 10 ** 5, 5.0
ARGS = ["--order", "8", "--fc", "1k", "--series", "E24", "--c-series", "E12"]


def exhaustive(errors: list) -> float:
    """min over every combination of max_f |sum_i e_i|, vectorised: the last stages' sums broadcast,
    the first stage's candidates one block at a time."""
    rest = np.zeros((1, errors[0].shape[1]))
    for e in errors[1:]:
        rest = (rest[:, None, :] + e[None, :, :]).reshape(-1, e.shape[1])
    best = np.inf
    for row in errors[0]:
        best = min(best, float(np.min(np.max(np.abs(rest + row[None, :]), axis=1))))
    return best


def joint_section(d):
    from designer.filters.joint import brute_force, joint_search
    errors = [st.errors for st in d.stages]
    joint_search(errors)                        # warm
    tracemalloc.start()
    t = time.perf_counter()
    choice, j, examined = joint_search(errors)
    took = time.perf_counter() - t
    peak = tracemalloc.get_traced_memory()[1] / 2 ** 20
    tracemalloc.stop()
    t = time.perf_counter()
    j_brute = exhaustive(errors)
    brute = time.perf_counter() - t
    t = time.perf_counter()
    _, j_python = brute_force(errors)
    python = time.perf_counter() - t
    combos = int(np.prod([len(e) for e in errors], dtype=float))
    ok = took <= JOINT_GOAL_S and peak <= JOINT_GOAL_MB
    print("### The joint E-series choice: 8th-order Butterworth low-pass, 1 kHz, E24/E12, LM741\n")
    print("| stages | candidates per stage | combinations | partial choices examined | search (s) | peak MB | "
          "goal | brute force, joint.brute_force (s) | speed-up | exhaustive, numpy-vectorised (s) | speed-up | "
          "same J | verdict |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    same = abs(j - j_brute) < 1e-12 and abs(j - j_python) < 1e-12
    print(f"| {len(errors)} | {', '.join(str(len(e)) for e in errors)} | {combos} | {examined} | {took:.4f} | "
          f"{peak:.1f} | {JOINT_GOAL_S:g} s, {JOINT_GOAL_MB:g} MB | {python:.3f} | {python / took:.0f}x | "
          f"{brute:.3f} | {brute / took:.1f}x | {'yes' if same else 'NO'} ({j:.4f} dB) | {'ok' if ok else 'MISSED'} |")
    print("\nAt this size (four stages of 12 candidates) a vectorised exhaustive enumeration is faster than the "
          "branch and bound.")
    print(f"\nPer-stage rounding gives {d.figures['error_per_stage_db']:.4f} dB, the nearest values "
          f"{d.figures['error_nearest_db']:.4f} dB, the joint choice {j:.4f} dB.")


def _best(times: int, fn) -> float:
    out = []
    for _ in range(times):
        t = time.perf_counter()
        fn()
        out.append(time.perf_counter() - t)
    return min(out)


def end_to_end_section():
    from designer.filters import FilterSpec
    from designer.filters.design import design
    spec = FilterSpec(order=8, fc_hz=1e3, r_series="E24", c_series="E12")
    exe = Path(sys.executable).parent / "design-filter"
    with tempfile.TemporaryDirectory(prefix="bench-filter-") as tmp:
        cmd = [str(exe), *ARGS, "--json", "--out", tmp]
        run = lambda: subprocess.run(cmd, capture_output=True, text=True, check=True, timeout=300)  # noqa: E731
        out = run()
        import json
        search = json.loads(out.stdout)["figures"]["search_s"]
        command = _best(3, run)
        deck = str(Path(tmp) / "filter.cir")
        bare = _best(3, lambda: subprocess.run(["ngspice", "-b", deck], capture_output=True, check=True,
                                               timeout=300, cwd=tmp))

        def in_process():
            result = design(spec, simulate=True)
            (Path(tmp) / "again.cir").write_text(result.deck())
        whole = _best(3, in_process)
    goal = END_TO_END_FACTOR * (bare + search)
    print("\n### design-filter end to end (8th order, E24/E12, the SPICE proof: .ac and .tran), best of three\n")
    print("The design (candidates, joint search, the proof's ngspice run and its comparison, the deck) in one "
          "process, against the bare `ngspice -b` of the deck it writes plus its search; the whole command "
          "(a new Python process: its imports) beside it.\n")
    print("| design and proof (s) | bare ngspice -b of its deck (s) | its search (s) | goal: 4 x (bare + search) (s) | "
          "ratio to bare + search | verdict | the command, imports included (s) |")
    print("|---|---|---|---|---|---|---|")
    print(f"| {whole:.2f} | {bare:.3f} | {search:.4f} | {goal:.2f} | {whole / (bare + search):.1f}x | "
          f"{'ok' if whole <= goal else 'MISSED'} | {command:.2f} |")


def monte_carlo_section(d):
    from designer.tolerance.filter import filter_monte_carlo, nominal_parts
    filter_monte_carlo(d, 1000, tighten=False, limit_items=["f3_hz=950:1050"])      # warm
    parts = len(nominal_parts(d))
    t = time.perf_counter()
    np.random.default_rng(0).random((MC_BUILDS, parts))
    floor = time.perf_counter() - t
    tracemalloc.start()
    t = time.perf_counter()
    mc = filter_monte_carlo(d, MC_BUILDS, seed=1, tighten=False, limit_items=["f3_hz=950:1050"])
    took = time.perf_counter() - t
    peak = tracemalloc.get_traced_memory()[1] / 2 ** 20
    tracemalloc.stop()
    lo, hi = mc.yield_interval()
    print(f"\n### Analytic Monte Carlo: {MC_BUILDS:.0e} builds of the 8th-order cascade ({parts} parts, "
          "5 figures each)\n")
    print("| builds | seconds | goal | numpy floor (s) | ratio to floor | peak MB | verdict |")
    print("|---|---|---|---|---|---|---|")
    print(f"| {MC_BUILDS:.0e} | {took:.2f} | {MC_GOAL_S:g} s | {floor:.4f} | {took / floor:.0f}x | {peak:.0f} | "
          f"{'ok' if took <= MC_GOAL_S else 'MISSED'} |")
    print(f"\nYield within f3_hz 950 Hz to 1.05 kHz: {100 * mc.yield_count / mc.n:.2f} % (95 % Wilson "
          f"{100 * lo:.2f} to {100 * hi:.2f} %).")


def main():
    from designer.filters import FilterSpec
    from designer.filters.design import design
    d = design(FilterSpec(order=8, fc_hz=1e3, r_series="E24", c_series="E12"))
    joint_section(d)
    end_to_end_section()
    monte_carlo_section(d)
    print(f"\nLoad average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores when it ended.")


if __name__ == "__main__":
    main()
