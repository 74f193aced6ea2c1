"""design-pid: a full run and the optimiser, on the seed plant (fc 3500 Hz,
zeta 0.2) with LM741s.

Timed: ``design_pid`` with ZN tuning split into plant, tuning, sizing,
analytic, simulation and report; the same with ``--tuning optimize
--target-overshoot 10``; the ``design-pid`` console script end to end
(process start, imports, SPICE, files). Also: the joint part search against
the exhaustive brute force on a small set. Goal on the 2-core machine: every
end-to-end run under 10 s.
"""

from __future__ import annotations

import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

GOAL_S = 10.0


def _design(tuning, **kw):
    from designer.pid.design import PidSpec, design_pid
    from designer.pid.report import write_outputs
    tick = time.perf_counter()
    res = design_pid(PidSpec(plant_fc_hz=3500, plant_zeta=0.2, opamp="LM741", tuning=tuning, **kw))
    with tempfile.TemporaryDirectory() as tmp:
        write_outputs(res, tmp, "bench")
    total = time.perf_counter() - tick
    return res, total


def main():
    import designer.pid.design  # noqa: F401  (imports are timed by the CLI row)
    rows = []
    for label, tuning, kw in (("ZN", "zn", {}), ("optimize, overshoot <= 10 %", "optimize",
                                                 {"target_overshoot_pct": 10.0})):
        runs = [_design(tuning, **kw) for _ in range(3)]
        res = runs[-1][0]
        total = statistics.median(r[1] for r in runs)
        tm = {k: statistics.median(r[0].timings.get(k, 0.0) for r in runs)
              for k in ("plant_s", "tuning_s", "sizing_s", "analytic_s", "simulation_s", "report_s")}
        extra = ""
        if res.optimizer:
            extra = f"{res.optimizer['evaluations']} evaluations, {res.optimizer['rounds']} round(s)"
        rows.append((label, total, tm, extra, res))
    print("### design_pid in-process, seed plant, LM741, median of 3 (s)\n")
    print("| tuning | total | plant | tuning | sizing | analytic | SPICE | report | goal | notes |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for label, total, tm, extra, res in rows:
        ok = "ok" if total < GOAL_S else "MISSED"
        print(f"| {label} | {total:.2f} | {tm['plant_s']:.2f} | {tm['tuning_s']:.2f} | {tm['sizing_s']:.2f} | "
              f"{tm['analytic_s']:.2f} | {tm['simulation_s']:.2f} | {tm['report_s']:.2f} | < {GOAL_S:g} {ok} | "
              f"{extra} |")
    print()
    for label, total, tm, extra, res in rows:
        a, s = res.analytic, res.spice
        print(f"- {label}: Kp {res.parts.kp:.4g}, Ti {res.parts.ti_s * 1e6:.4g} us, Td {res.parts.td_s * 1e6:.4g} us; "
              f"analytic overshoot {a['overshoot_pct']:.3g} %, SPICE {s['overshoot_pct']:.3g} % "
              f"(nrms {s['nrms']:.3g}); failed checks: "
              f"{', '.join(c['name'] for c in res.checks if not c['ok']) or 'none'}")
    # console script end to end
    exe = Path(sys.executable).parent / "design-pid"
    times = []
    with tempfile.TemporaryDirectory() as tmp:
        for _ in range(2):
            tick = time.perf_counter()
            p = subprocess.run([str(exe), "--plant-fc", "3500", "--plant-zeta", "0.2", "--out", tmp],
                               capture_output=True, text=True)
            times.append(time.perf_counter() - tick)
            if p.returncode != 0:
                raise RuntimeError(p.stderr)
    cli = statistics.median(times)
    print(f"\n`design-pid --plant-fc 3500 --plant-zeta 0.2` end to end (new process, files written): "
          f"{cli:.2f} s (goal < {GOAL_S:g} s: {'ok' if cli < GOAL_S else 'MISSED'})\n")
    # sizing search vs brute force
    from designer.pid import blocks
    kw = dict(r_series="E3", c_series="E3", r_min=1e3, r_max=47e3, c_min=1e-9, c_max=47e-9, f_integrator_hz=140.0)
    tick = time.perf_counter()
    sel = blocks.select_parts(3.34, 43.215e-6, 10.8037e-6, 3500, **kw)
    t_s = time.perf_counter() - tick
    tick = time.perf_counter()
    best_err, best_obj = blocks.brute_force(3.34, 43.215e-6, 10.8037e-6, 3500, **kw)
    t_b = time.perf_counter() - tick
    got = blocks.objective(sel.parts, sel.targets, sel.best_possible_pct / 100, 0.01)
    tick = time.perf_counter()
    full = blocks.select_parts(3.34, 43.215e-6, 10.8037e-6, 3500)
    t_f = time.perf_counter() - tick
    print("| part search | candidates | time (s) | worst error | objective equals brute force |")
    print("|---|---|---|---|---|")
    print(f"| E3/E3 small set | {sel.candidates:,} | {t_s:.3f} (brute force {t_b:.2f}) | "
          f"{sel.best_possible_pct:.3g} % | {'yes' if abs(got[1] - best_obj[1]) < 1e-9 * best_obj[1] else 'NO'} |")
    print(f"| E24/E12, 1k-1M, 1n-10u | {full.candidates:,} | {t_f:.3f} | {full.worst_error_pct:.3g} % | "
          "(too large for brute force) |")


if __name__ == "__main__":
    main()
