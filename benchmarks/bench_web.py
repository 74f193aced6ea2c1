"""designer-web: a warm plant design answered over HTTP, and twenty at once.

Goals (issue 19, 2-core machine): a warm plant design (design, SPICE, the
page's plots and schematic: ``POST /api/plant?view=page``) answered in under
0.4 s median and within 2x the same work called in-process
(:func:`designer.web.jobs.run` in this process: the floor, measured in the
same run); twenty concurrent plant requests all answered correctly (each its
own fc), the p95 latency recorded.

Each request asks for a different fc (3000 Hz up in 37 Hz steps), so no answer
is the last one's: the parts, the simulation and the schematic are new each
time (the worker keeps the last schematics drawn by their parts; a new fc
often lands on new parts). Each HTTP request is followed by the same design
in-process, so the load of the (shared) machine falls on both alike. The
server runs with its default two workers, one per core.
"""

from __future__ import annotations

import json
import signal
import statistics
import subprocess
import sys
import time
import urllib.request
from concurrent.futures import ThreadPoolExecutor

GOAL_MEDIAN_S = 0.4
GOAL_RATIO = 2.0
N_SEQ = 15
N_CONCURRENT = 20


def fcs(n: int, start: float = 3000.0) -> list:
    return [start + 37.0 * i for i in range(n)]


def post(url: str, body: dict) -> tuple:
    req = urllib.request.Request(url, data=json.dumps(body).encode(), method="POST",
                                 headers={"Content-Type": "application/json"})
    t = time.perf_counter()
    with urllib.request.urlopen(req, timeout=300) as r:
        data = json.loads(r.read())
    return time.perf_counter() - t, data


def correct(data: dict, fc: float) -> bool:
    """An answer is this request's: its spec's fc, parts landing within 5 % of it, a SPICE run."""
    r = data["result"]
    return (r["spec"]["fc_hz"] == fc and abs(r["built"]["fn_hz"] / fc - 1) < 0.05 and r["spice"] is not None
            and "<svg" in data["page"]["schematic_svg"])


def in_process(fc: float) -> float:
    """The same work in this process: the worker's own function (warmed up as a worker is)."""
    from designer.web import jobs
    t = time.perf_counter()
    out = jobs.run({"prog": "design-plant", "argv": ["--fc", repr(fc), "--zeta", "0.2", "--json", "--no-files"],
                    "want": "page"})
    json.dumps({"result": out["json"], "page": out["page"]})   # the server serialises it too
    dt = time.perf_counter() - t
    assert out["status"] == 0
    return dt


def p95(values) -> float:
    s = sorted(values)
    return s[min(len(s) - 1, int(round(0.95 * (len(s) - 1))))]


def main() -> None:
    from designer.web import jobs
    server = subprocess.Popen([sys.executable, "-m", "designer.web.server", "--port", "0"], stdout=subprocess.PIPE,
                              stderr=subprocess.DEVNULL, text=True)
    try:
        url = server.stdout.readline().split("serving on ")[1].split()[0].rstrip("/")
        api = url + "/api/plant?view=page"
        post(api, {"fc": 1000, "zeta": 0.5})   # the workers have warmed up (their first task)
        jobs.warm_up()                          # and so has this process, the same way
        # one over HTTP, then the same in-process, in turn: the machine's load (shared) falls on both alike
        seq, floor = [], []
        for fc in fcs(N_SEQ):
            dt, data = post(api, {"fc": fc, "zeta": 0.2})
            assert correct(data, fc)
            seq.append(dt)
            floor.append(in_process(fc))
        conc_fcs = fcs(N_CONCURRENT, 5000.0)
        tick = time.perf_counter()
        with ThreadPoolExecutor(N_CONCURRENT) as ex:
            answers = list(ex.map(lambda fc: (fc, *post(api, {"fc": fc, "zeta": 0.2})), conc_fcs))
        wall = time.perf_counter() - tick
    finally:
        server.send_signal(signal.SIGINT)
        server.wait(60)
        server.stdout.close()
    med, med_floor = statistics.median(seq), statistics.median(floor)
    ratio = med / med_floor
    ok_seq = med < GOAL_MEDIAN_S and ratio <= GOAL_RATIO
    good = sum(correct(data, fc) for fc, _, data in answers)
    lat = [dt for _, dt, _ in answers]
    ok_conc = good == N_CONCURRENT
    print("A warm plant design over HTTP (`POST /api/plant?view=page`: design, SPICE, plot traces, schematic SVG, "
          "BOM), against the same work in-process (`designer.web.jobs.run`).\n")
    print("| measure | value | goal | verdict |\n|---|---|---|---|")
    print(f"| HTTP median of {N_SEQ} (min {min(seq):.3f} s, max {max(seq):.3f} s) | {med:.3f} s | < {GOAL_MEDIAN_S} s "
          f"| {'ok' if med < GOAL_MEDIAN_S else 'MISSED'} |")
    print(f"| in-process median of {N_SEQ} (min {min(floor):.3f} s) | {med_floor:.3f} s | floor | |")
    print(f"| HTTP / in-process | {ratio:.2f}x | <= {GOAL_RATIO:g}x | {'ok' if ratio <= GOAL_RATIO else 'MISSED'} |")
    print(f"| {N_CONCURRENT} concurrent requests answered correctly | {good} / {N_CONCURRENT} | all | "
          f"{'ok' if ok_conc else 'MISSED'} |")
    print(f"| ... their latency p50 / p95 / max | {statistics.median(lat):.2f} / {p95(lat):.2f} / {max(lat):.2f} s "
          f"| recorded | |")
    print(f"| ... all {N_CONCURRENT} answered in (2 workers) | {wall:.2f} s | recorded | |")
    print(f"\nVerdict: {'ok' if ok_seq and ok_conc else 'MISSED'}.")
