"""What a worker does for one request (designer.web.jobs), in this process: the
command's own output, and traces that are the result's own arrays."""

import json

import numpy as np
import pytest

from designer.web import jobs


def test_measured_points_land_on_their_nearest_grid_frequency():
    grid = np.geomspace(10, 1e5, 41)   # 10 points a decade
    f = np.array([10.0, 99.0, 1010.0, 1e5])
    got = jobs._on_grid(f, np.array([1.0, 2.0, 3.0, 4.0]), grid)
    assert np.count_nonzero(np.isfinite(got)) == 4
    for fi, v in zip(f, [1.0, 2.0, 3.0, 4.0]):
        assert got[np.argmin(np.abs(np.log(grid / fi)))] == v
    h = jobs._complex_on_grid(np.array([5.0, 100.0, 2e5]), np.array([1 + 1j, 2j, 3.0]), grid)
    assert np.count_nonzero(np.isfinite(h)) == 1 and h[10] == 2j   # 100 Hz; outside the grid: left out


def test_a_trace_is_json_with_nan_as_null_and_at_most_its_points():
    x = np.linspace(0, 1, 10_000)
    y = np.where(x > 0.5, np.nan, x)
    t = jobs._trace(x, {"y": y}, "time (s)")
    assert len(t["x"]) <= jobs.TRACE_POINTS and t["x"][0] == 0.0 and t["x"][-1] == 1.0
    assert None in t["series"][0]["y"] and json.dumps(t)


@pytest.mark.spice
def test_a_plant_page_is_the_commands_json_and_its_own_arrays():
    """design-plant through the library (the page's fields, issue 26): its JSON records the command line it
    stands for."""
    out = jobs.run({"prog": "design-plant", "fields": {"fc": 3500, "zeta": 0.2}, "want": "page"})
    assert out["status"] == 0 and out["error"] is None
    assert out["json"]["tool"]["argv"] == ["design-plant", "--fc=3500", "--zeta=0.2"]
    step = out["page"]["step"]
    labels = [s["label"] for s in step["series"]]
    assert labels[:3] == ["SPICE (ngspice)", "analytic (LM741 model)", "analytic (ideal op-amp)"]
    spice = np.array(step["series"][0]["y"], float)
    # the SPICE output settles on the amplitude (2 V) and peaks at the overshoot the JSON gives
    assert spice[-1] == pytest.approx(2.0, abs=0.01)
    assert spice.max() / 2 - 1 == pytest.approx(out["json"]["spice"]["overshoot_pct"] / 100, abs=0.01)
    assert "<svg" in out["page"]["schematic_svg"] and out["page"]["bom"]["rows"][0][:3] == ["R1", "1.6 kOhm", "1k6"]


def test_a_refusal_is_the_commands_one_line():
    """A library task refuses in the page's words: the field's label, in the request's language."""
    out = jobs.run({"prog": "analyze-plant", "fields": {"r1": "1k6", "r2": "3k9", "c1": "3n3", "c2": "-1"},
                    "want": "page"})
    assert out["status"] == 2 and out["error"] == "analyze-plant: error: \"C2\" must be 100 fF to 1 F, got '-1'"
    assert (out["field"], out["label"]) == ("c2", "C2")
    out = jobs.run({"prog": "design-plant", "fields": {"fc": 3500, "zeta": -1}, "want": "page"})
    assert out["status"] == 2 and out["error"] == "design-plant: error: \"zeta\" must be 0.01 to 10, got '-1'"
    assert out["field"] == "zeta"


def test_a_broadband_capture_gives_its_step_and_spectrum_traces(tmp_path):
    """A PRBS (a 7-bit m-sequence, 4 periods) through a first-order lag, as identify reads it (t,u,y)."""
    from scipy.signal import lfilter

    from designer.core.prbs import mls
    ts, tau = 1e-4, 2e-3
    u = np.repeat(np.tile(mls(7).astype(float), 4), 10)
    a = np.exp(-ts / tau)
    y = lfilter([1 - a], [1, -a], u)
    path = tmp_path / "prbs.csv"
    np.savetxt(path, np.column_stack([np.arange(u.size) * ts, u, y]), delimiter=",", header="t,u,y", comments="")
    out = jobs.run({"prog": "identify", "fields": {}, "capture": str(path), "want": "page"})
    assert out["status"] == 0, out["error"]
    assert out["json"]["format"] == "broadband" and out["json"]["best"]["model"] in ("fopdt", "overdamped")
    page = out["page"]
    assert page["kind"] == "broadband" and page["plot"]["series"][0]["y"]
    traces = [page["plot"]] + ([page["second"]] if "second" in page else [])
    assert any(t["log_x"] for t in traces) or out["json"]["method"] == "correlation"
    json.dumps(page)


def test_a_runs_temporaries_are_made_in_its_requests_folder(tmp_path):
    """Issue 25: a run killed at its deadline left its simulator's designer-sim-* folder behind; made in the
    request's folder, they go with it (ngspice -b through TMPDIR, the shared library through tempfile)."""
    import os
    import tempfile

    from designer.spice.simulate import private_env
    before, env = tempfile.gettempdir(), os.environ.get("TMPDIR")
    with jobs.temporaries_in(str(tmp_path)):
        made = tempfile.mkdtemp(prefix="designer-sim-")
        assert os.path.dirname(made) == str(tmp_path) and private_env(made)["TMPDIR"] == str(tmp_path)
    assert tempfile.gettempdir() == before and os.environ.get("TMPDIR") == env
    with jobs.temporaries_in(None):
        assert tempfile.gettempdir() == before


def test_a_cancel_landing_in_an_at_fork_hook_waits_until_it_returns(monkeypatch):
    """A superseded filter request (its proof runs ``ngspice -b``: a fork) was cancelled inside logging's at-fork
    hook, where the interpreter prints and swallows the exception: a traceback on the server's stderr, the run going
    on. The cancel now comes again 5 ms later, outside it; anywhere else it is raised at once."""
    import signal
    import sys
    hook = {"__name__": "logging", "sys": sys}
    exec("def _releaseLock():\n    return sys._getframe()", hook)   # a frame of logging's, as the hook's
    monkeypatch.setattr(jobs, "_RUNNING", True)
    before = signal.getsignal(signal.SIGALRM)
    try:
        jobs._cancel(signal.SIGUSR1, hook["_releaseLock"]())        # not raised there
        assert signal.getitimer(signal.ITIMER_REAL)[0] > 0 and signal.getsignal(signal.SIGALRM) is jobs._cancel
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, before)
    with pytest.raises(jobs.Superseded):
        jobs._cancel(signal.SIGUSR1, sys._getframe())


@pytest.mark.parametrize("where", ["__init__", "_execute_child"])
def test_a_cancel_landing_in_popens_start_waits_until_the_child_is_its(monkeypatch, where):
    """A cancel raised inside subprocess.Popen's constructor leaves the ``ngspice -b`` it forked running with no
    Popen to kill and reap it (the server's stderr said "ResourceWarning: subprocess N is still running" at its
    stop, after a run of the web tests): it comes again 5 ms later; a frame called from there counts too."""
    import signal
    import sys
    start = {"__name__": "subprocess", "sys": sys}
    exec(f"def {where}(inner):\n    return inner()", start)   # a frame of subprocess's, as Popen's own
    monkeypatch.setattr(jobs, "_RUNNING", True)
    before = signal.getsignal(signal.SIGALRM)
    try:
        jobs._cancel(signal.SIGUSR1, start[where](lambda: sys._getframe()))   # deeper than Popen: not raised
        assert signal.getitimer(signal.ITIMER_REAL)[0] > 0 and signal.getsignal(signal.SIGALRM) is jobs._cancel
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, before)
    other = {"__name__": "subprocess", "sys": sys}
    exec("def communicate():\n    return sys._getframe()", other)   # waiting on a started child: run() kills it
    with pytest.raises(jobs.Superseded):
        jobs._cancel(signal.SIGUSR1, other["communicate"]())


@pytest.mark.spice
def test_a_cancel_inside_ngspices_shared_library_stops_a_spice_monte_carlo_as_its_command_returns():
    """Issue 29: a SPICE Monte Carlo on ngspice's shared library spends its time inside the library, the cancel's
    handler running only in ngspice's callbacks (where cffi swallows what it raises): it was put off 5 ms at a
    time, unwinding only when the whole loop ended (7.5 s here), its worker killed meanwhile. It is now raised as
    the library's current command returns; the library serves the next run."""
    import os
    import signal
    import threading
    import time
    jobs.run({"prog": "warm-up"})
    sent = []

    def cancel():
        time.sleep(1.0)
        sent.append(time.monotonic())
        os.kill(os.getpid(), signal.SIGUSR1)
    threading.Thread(target=cancel, daemon=True).start()
    mc = {"fc": 3500, "zeta": 0.2, "monte-carlo": 2000, "engine": "spice", "simulator": "pyspice", "no-sim": True}
    out = jobs.run({"prog": "design-plant", "fields": mc, "want": "json"})
    took = time.monotonic() - sent[0]
    assert out["status"] == "superseded" and took < 1.0, took
    out = jobs.run({"prog": "design-plant", "fields": {**mc, "monte-carlo": 20}, "want": "json"})
    assert out["status"] == 0 and out["json"]["monte_carlo"]["spice"]


@pytest.mark.spice
def test_the_filter_and_circuit_plant_pages_speak_the_requests_language():
    """Issue 29: /api/filter and a plant on a menu's section answer in the request's language: the BOM's columns
    and packages (bom.csv keeps its English), the Bode traces (their English label kept), the checks' titles;
    English without a language."""
    from designer.core.i18n import catalogue, language, localise
    from designer.report.wiring import BOM_HEADER
    es = catalogue("es")
    for lang, words in (("es", es), (None, {})):
        ask = {"lang": lang} if lang else {}
        f = jobs.design_filter_task({"order": 3, "fc": 1000, "no-sim": True, **ask}, "page")
        c = jobs.design_plant_task({"fc": 3500, "zeta": 0.2, "topology": "mfb-lowpass", **ask}, "page")   # SPICE checks
        assert f["status"] == 0 and c["status"] == 0, (f["error"], c["error"])
        for page in (f["page"], c["page"]):
            assert page["bom"]["header"] == list(BOM_HEADER) and page["bom_csv"].startswith(",".join(BOM_HEADER[:3]))
            assert page["bom_header"] == [words.get(h, h) for h in BOM_HEADER]
            packages = {row[6] for row in page["bom"]["rows"]}
            with language(lang or "en"):   # the numbers as the language writes them: 0,25 W
                assert {localise(words.get(p, p)) for p in packages} == {row[6] for row in page["bom_text"]}
        trace = f["page"]["bode"]["gain"]["series"][0]
        assert trace["label"] == "chosen parts, LM741 model"
        assert trace["text"] == words.get("chosen parts, {name} model", "chosen parts, {name} model").format(name="LM741")
        shown = {ch["id"]: ch["title"] for ch in c["page"]["checks"]}
        # the op-amp's checks under the square wave (the seed plant's ids) and the SPICE agreement
        assert shown == {i: words.get(t, t) for i, t in (("slew_rate", "slew rate"), ("output_swing", "output swing"),
                                                          ("spice_agreement", "SPICE agreement"))}
        # the section's title and notes (its parts' roles) in the request's language, result.json's in English
        section = words.get("MFB low-pass (inverting)", "MFB low-pass (inverting)")
        assert section in c["page"]["title"] and c["page"]["notes"][0].startswith(section + ": ")
        assert words.get("input resistor", "input resistor") in c["page"]["notes"][0]


@pytest.mark.spice
def test_a_chirp_capture_page_draws_the_record_with_its_models_and_every_candidate(tmp_path):
    """Issues 28/29: the Identify answer for an input only output error reads (a chirp) has the plot: the
    recorded output, the validation part's start, the best valid models as the assessment simulated them
    (recomputed here through its public API), and every candidate with its validation fit and why not valid."""
    from cli.test_identify_validation import chirp_capture, record_expected
    from designer.identify.assess import identify_record
    from designer.identify.io import read_capture
    path = chirp_capture(tmp_path)
    out = jobs.run({"prog": "identify", "fields": {}, "capture": str(path), "want": "page"})
    assert out["status"] == 0, out["error"]
    page = out["page"]
    json.dumps(page, allow_nan=False)
    cap = read_capture(path)
    a = identify_record(cap.t, cap.y, cap.u).assessment
    plot = page["plot"]
    assert page["kind"] == "broadband" and "record" not in page and "second" not in page
    assert plot["validation_start_s"] == pytest.approx(cap.t[a.split.n_est], rel=1e-12)
    six = {"rtol": 5e-6, "atol": 1e-12}      # the page's numbers have six significant digits
    np.testing.assert_allclose(plot["x"], cap.t, **six)
    assert plot["series"][0]["label"] == "recorded output"
    np.testing.assert_allclose(plot["series"][0]["y"], cap.y, **six)
    expected = record_expected(a, cap.u, cap.y)
    assert [s["label"] for s in plot["series"][1:]] == [
        f"{c.route} {c.name} ({c.kind}), validation fit {c.fit_percent:.1f} %" for c, _, _ in expected]
    for s, (_, ym, _) in zip(plot["series"][1:], expected):
        np.testing.assert_allclose(s["y"], ym, **six)
    rows = page["candidates"]
    assert len(rows) == len(out["json"]["validation"]["models"]) == len(a.candidates)
    assert [r["valid"] for r in rows] == sorted((r["valid"] for r in rows), reverse=True)   # valid ones first
    assert all(r["note"] for r in rows if not r["valid"]) and not any(r["note"] for r in rows if r["valid"])
    best = out["json"]["validation"]["best"]
    assert (rows[0]["route"], rows[0]["model"]) == (best["route"], best["model"])
    assert rows[0]["fit_percent"] == pytest.approx(best["validation"]["fit_percent"])


@pytest.mark.parametrize("gain", [1, 2])
def test_the_plant_pages_bench_names_the_input_resistor_the_section_declares(gain):
    """Issue 26: the generator's row names the section's input resistor as its declaration gives it (the sheet's
    settings table), not a designator spelt in the web layer."""
    from designer.filters.sallen_key_lowpass_parts import section_of
    from designer.plant.design import design_plant
    from designer.plant.spec import PlantSpec
    from designer.report.wiring import bench_rows
    result = design_plant(PlantSpec(fc_hz=3500, zeta=0.2, gain=gain), simulate=False)
    ref = section_of(result.built).designators[0]
    rows = bench_rows(result.test, result.scope, ref)
    assert jobs.plant_page(result)["bench"][:len(rows)] == rows
    assert any(ref in str(cell) for row in rows for cell in row)


def test_a_cached_schematic_is_drawn_in_the_requests_language():
    """A bug fixed: the worker's schematic cache was keyed by the parts only, so a section plant drawn for a
    Spanish request came back with Spanish labels ("Etapa 1") for the next English one."""
    from designer.core.i18n import catalogue
    stage = catalogue("es").get("Stage {number}: {topology}", "")
    assert stage.startswith("Etapa")
    ask = {"fc": 3500, "zeta": 0.2, "topology": "mfb-lowpass", "no-sim": True}
    es = jobs.design_plant_task({**ask, "lang": "es"}, "page")
    en = jobs.design_plant_task(ask, "page")
    assert es["status"] == 0 and en["status"] == 0, (es["error"], en["error"])
    assert "Etapa" in es["page"]["schematic_svg"] and "Etapa" not in en["page"]["schematic_svg"]
    assert "Stage" in en["page"]["schematic_svg"]


def test_a_section_plants_worst_case_on_the_page_spreads_the_opamps_gbw_as_the_command_line_does(tmp_path):
    """Bug (issue 26): the page's worst case of a section plant refused --tol GBW=30% ("this design has no part
    GBW") while design-plant --topology took it; one library call now (tolerance.mcspec.section_tolerance)."""
    import subprocess

    from helpers import script
    fields = {"fc": 1000, "zeta": 0.3, "topology": "mfb-lowpass", "worst-case": True, "tol": ["GBW=30%"],
              "no-sim": True}
    out = jobs.run({"prog": "design-plant", "fields": fields, "want": "json"})
    assert out["status"] == 0, out["error"]
    cli = subprocess.run([script("design-plant"), "--topology", "mfb-lowpass", "--fc", "1000", "--zeta", "0.3", "--worst-case", "--tol", "GBW=30%",
                          "--no-sim", "--json", "--out", str(tmp_path)], capture_output=True, text=True, timeout=300)
    assert cli.returncode == 0, cli.stderr
    assert out["json"]["worst_case"] == json.loads(cli.stdout)["worst_case"]
    out = jobs.run({"prog": "design-plant", "fields": {**fields, "tol": ["SR=30%"]}, "want": "json"})
    assert out["status"] == 2 and out["field"] == "tol", out
