"""design-filter: the summary with units, JSON, the deck and result.json
written, and bad input as one line with exit status 2."""

import json
import subprocess
from pathlib import Path

import pytest
from helpers import script

from designer.cli.filter import analyze_filter_main, design_filter_main


@pytest.mark.parametrize("argv, words", [
    (["--order", "11", "--fc", "1k"], "--order must be 1 to 10"),
    (["--order", "2.5", "--fc", "1k"], "--order must be a whole number"),
    (["--order", "4", "--fc", "1k", "--family", "elliptic"], "allowed: butterworth, bessel, chebyshev"),
    (["--order", "4", "--fc", "1k", "--topology", "tow-thomas"], "allowed: sallen-key, mfb, auto"),
    (["--order", "4", "--fc", "1k", "--type", "notch"], "allowed: lowpass, highpass, bandpass"),
    (["--order", "4", "--fc", "1k", "--family", "chebyshev", "--ripple", "5"], "--ripple must be 0.01 dB to 3 dB"),
    (["--order", "4", "--fc", "1k", "--ripple", "1"], "only a chebyshev filter has a ripple"),
    (["--family", "chebyshev", "--passband", "1k", "--max-loss", "4", "--stopband", "2k", "--min-attenuation", "60"],
     "--max-loss: a chebyshev mask's passband loss is its ripple, which must be 0.01 dB to 3 dB, got 4 dB"),
    (["--order", "4"], "give --order and --fc"),
    (["--passband", "3k", "--max-loss", "1", "--stopband", "2k", "--min-attenuation", "40"],
     "must be below its stopband edge"),
    (["--passband", "3k", "--max-loss", "1", "--stopband", "3.3k", "--min-attenuation", "80"],
     "order 104, above the limit 10"),
    (["--passband", "3k", "--max-loss", "1"], "a mask needs all of"),
    (["--type", "bandpass", "--family", "bessel", "--passband", "300,3k", "--max-loss", "3", "--stopband",
      "60,15k", "--min-attenuation", "80"], "needs a bessel prototype of order 12 (a band-pass of order 24), above "
                                            "the limit 10 (wide band-pass: order 10 gives 74.9 dB"),
    (["--order", "10", "--fc", "1k", "--family", "chebyshev", "--ripple", "3"], "too slow for stage 5"),
    (["--order", "4", "--fc", "1M", "--opamp", "ideal"], "not realisable within the part bounds"),
    (["--order", "4", "--fc", "1k", "--opamp", "uA709"], "uA709"),
    (["--order", "4", "--fc", "abc"], "--fc"),
    (["--order", "4", "--fc", "1k", "--bogus"], "unrecognized arguments"),
    (["--type", "bandpass", "--order", "2", "--f-low", "1.1k", "--f-high", "900"],
     "the band's edges cross: --f-low (1100 Hz) is not below --f-high (900 Hz)"),
    (["--type", "bandpass", "--order", "2", "--fc", "1k"], "a bandpass takes its edges"),
    (["--order", "2", "--fc", "1k", "--f-low", "900"], "band edges are for a bandpass"),
    (["--order", "4", "--fc", "1k", "--apply-optimum"], "--apply-optimum goes with --optimize yield"),
    (["--order", "6", "--fc", "1k", "--gain", "4", "--stage-gain", "2,3,1"],
     "--stage-gain: 2 x 3 x 1 = 6 is not --gain 4"),
    (["--order", "6", "--fc", "1k", "--gain", "4", "--stage-gain", "2,2"],
     "--stage-gain: give one gain per stage (3 stages, in build order), got 2"),
    (["--order", "6", "--fc", "1k", "--gain", "4", "--stage-gain", "4,0.5,2"], "--stage-gain must be 1 to 100"),
    (["--order", "6", "--fc", "1k", "--gain", "4", "--stage-gain", "2,x,2"], "--stage-gain"),
    (["--order", "6", "--fc", "1k", "--gain", "100", "--stage-gain", "1,1,100", "--opamp", "TL072"],
     "stage 3's output peaks at 100 V at --amplitude 1 V, beyond TL072's swing of +-13.5 V; lower --amplitude "
     "or --stage-gain"),
    (["--type", "bandpass", "--order", "2", "--f-low", "900", "--f-high", "1.1k", "--gain", "2", "--stage-gain",
      "2,1"], "--stage-gain: a narrow band-pass's sections peak at their own fn"),
    (["--type", "bandpass", "--passband", "1.1k,900", "--max-loss", "1", "--stopband", "600,1.7k",
      "--min-attenuation", "30"], "--passband's edges cross: 1100 Hz is not below 900 Hz"),
    (["--type", "bandpass", "--passband", "900,1.1k", "--max-loss", "1", "--stopband", "950,1.7k",
      "--min-attenuation", "30"], "the stopband is not outside the passband: --stopband (950, 1700 Hz)"),
    (["--type", "bandpass", "--passband", "900,1.1k", "--max-loss", "1", "--stopband", "600",
      "--min-attenuation", "30"], "--stopband: a band-pass mask takes two edges F1,F2"),
    (["--type", "bandpass", "--passband", "900,1.1k", "--max-loss", "1", "--stopband", "600,1.7k",
      "--min-attenuation", "30", "--order", "3"], "--order: give either a band-pass's order and edges or its mask"),
    (["--passband", "900,1.1k", "--max-loss", "1", "--stopband", "3k", "--min-attenuation", "30"],
     "--passband: two edges F1,F2 are for a bandpass"),
    (["--family", "chebyshev", "--passband", "1k", "--max-loss", "1", "--stopband", "10k", "--min-attenuation", "30",
      "--max-delay-error", "1", "--delay-to", "1k"], "--max-delay-error: a group-delay target is for a bessel filter"),
    (["--family", "bessel", "--order", "4", "--fc", "1k", "--max-delay-error", "1", "--delay-to", "1k"],
     "--max-delay-error: a group-delay target joins a mask"),
    (["--family", "bessel", "--passband", "1k", "--max-loss", "3", "--stopband", "10k", "--min-attenuation", "30",
      "--max-delay-error", "1"], "--delay-to: a group-delay target needs both --max-delay-error and --delay-to"),
])
def test_bad_input_is_one_line_exit_2(argv, words, capsys):
    assert design_filter_main(argv + ["--no-sim"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("design-filter: error: ")
    assert words in err, err


def test_summary_in_engineering_notation(capsys):
    assert design_filter_main(["--order", "4", "--fc", "1k", "--no-sim"]) == 0
    out = capsys.readouterr().out
    for words in ("4th-order Butterworth low-pass, fc 1 kHz (-3 dB)", "sallen-key-lowpass", "Q 0.5412",
                  "Q 1.307", "kOhm", "nF", "max passband deviation", "-3 dB frequency", "joint across the stages",
                  "per-stage rounding", "peak gain"):
        assert words in out, words


def test_help_teaches_each_input():
    out = subprocess.run([script("design-filter"), "--help"], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0
    for words in ("--order", "1 to 10", "--ripple", "0.01 dB to 3 dB", "--passband", "--min-attenuation",
                  "--topology", "sallen-key, mfb", "--gain", "--opamp", "--amplitude", "--series", "--json", "--out"):
        assert words in out.stdout, words


@pytest.mark.spice
def test_json_deck_and_result_written(tmp_path):
    out = subprocess.run([script("design-filter"), "--type", "highpass", "--family", "chebyshev", "--ripple", "0.5",
                          "--order", "5", "--fc", "1k", "--json", "--out", str(tmp_path / "hp")],
                         capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    d = json.loads(out.stdout)
    assert d["spec"]["order"] == 5 and len(d["stages"]) == 3
    assert d["spice"]["max_deviation_passband_db"] < 0.05
    assert d["figures"]["error_joint_db"] <= d["figures"]["error_per_stage_db"] + 1e-12
    deck = Path(d["files"]["deck"]).read_text()
    assert "\nac dec" in deck and deck.rstrip().endswith(".end")
    assert json.loads(Path(d["files"]["result_json"]).read_text()) == d
    # the deck stands alone: ngspice -b runs it
    run = subprocess.run(["ngspice", "-b", d["files"]["deck"]], capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    meas = {k.strip(): float(v.split()[0]) for k, v in (line.split("=", 1) for line in run.stdout.splitlines()
                                                        if line.startswith(("f3db_hz", "passband_db")))}
    f3 = meas["f3db_hz"]
    assert f3 == pytest.approx(d["figures"]["f3_hz"], rel=0.01)


# ---- analyze-filter and the tolerance options ---------------------------------------------------
@pytest.fixture(scope="module")
def designed(tmp_path_factory):
    """A mask design's result.json (no SPICE: fast), the parts analyze-filter starts from."""
    folder = tmp_path_factory.mktemp("mask")
    assert design_filter_main(["--family", "chebyshev", "--passband", "3k", "--max-loss", "1", "--stopband", "12k",
                               "--min-attenuation", "40", "--no-sim", "--json", "--out", str(folder)]) == 0
    return folder / "result.json"


def test_analyze_filter_of_the_designed_parts_is_the_design(designed, capsys):
    capsys.readouterr()
    d = json.loads(designed.read_text())
    assert analyze_filter_main(["--from", str(designed), "--no-sim", "--json"]) == 0
    a = json.loads(capsys.readouterr().out)
    assert a["stages"][0]["parts"] == d["stages"][0]["parts"]
    for k in ("f3_hz", "passband_deviation_db", "mask_passband_margin_db", "mask_stopband_margin_db",
              "error_joint_db"):
        assert a["figures"][k] == pytest.approx(d["figures"][k], rel=1e-9, abs=1e-12), k


def test_analyze_filter_part_as_built_moves_the_response(designed, capsys):
    capsys.readouterr()
    d = json.loads(designed.read_text())
    r = d["stages"][0]["parts"]["R1"]
    assert analyze_filter_main(["--from", str(designed), "--no-sim", "--json", "--part", f"R101={1.2 * r}"]) == 0
    a = json.loads(capsys.readouterr().out)
    assert a["stages"][0]["parts"]["R1"] == pytest.approx(1.2 * r)
    # stage 1 is the first-order section: its corner moves down by 1.2, and so does the -3 dB point
    assert a["figures"]["f3_hz"] < d["figures"]["f3_hz"]


def test_analyze_filter_part_takes_a_list_as_analyze_plant_does(designed, capsys):
    """--part R101=.. C101=.. (a list) is two repeated --part: analyze-plant and design-pid take a list too."""
    d = json.loads(designed.read_text())
    p = d["stages"][0]["parts"]
    items = [f"R101={1.2 * p['R1']}", f"C101={0.9 * p['C1']}"]
    got = []
    for argv in (["--part", *items], ["--part", items[0], "--part", items[1]]):
        capsys.readouterr()
        assert analyze_filter_main(["--from", str(designed), "--no-sim", "--json", *argv]) == 0
        a = json.loads(capsys.readouterr().out)
        a.pop("tool")
        got.append(a)
    assert got[0] == got[1] and got[0]["stages"][0]["parts"]["C1"] == pytest.approx(0.9 * p["C1"])


@pytest.mark.parametrize("argv, words", [
    (["--part", "R909=1k"], "--part 'R909=1k': give DESIGNATOR=VALUE with one of this filter's parts: R101"),
    (["--part", "R101=-1k"], "--part R101 must be above 0"),
    (["--tol", "R=1%"], "--tol goes with --monte-carlo N"),
    (["--monte-carlo", "5"], "--monte-carlo '5': give a whole number, 10 to"),
    (["--monte-carlo", "100", "--spice-samples", "101"], "--spice-samples '101': give a whole number, 1 to 100"),
    (["--monte-carlo", "100", "--limit", "bogus_hz=1:2"], "unknown figure"),
    (["--monte-carlo", "100", "--tol", "R=80%"], "at most 50 %"),
    (["--monte-carlo", "100", "--tol", "Q7=1%"], "this design has no part Q7"),
    (["--jobs", "2"], "--jobs goes with --monte-carlo N"),
])
def test_analyze_filter_bad_input_is_one_line_exit_2(designed, argv, words, capsys):
    capsys.readouterr()
    assert analyze_filter_main(["--from", str(designed), "--no-sim"] + argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("analyze-filter: error: "), err
    assert words in err, err


@pytest.mark.parametrize("content, words", [(None, "cannot read it"), ("{", "not JSON"),
                                            ('{"tool": "design-plant"}', "not a design-filter result.json")])
def test_analyze_filter_refuses_what_is_not_a_result(tmp_path, content, words, capsys):
    path = tmp_path / "r.json"
    if content is not None:
        path.write_text(content)
    assert analyze_filter_main(["--from", str(path), "--no-sim"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and words in err, err


def test_design_filter_yield_and_its_optimum_in_json(capsys):
    argv = ["--family", "chebyshev", "--passband", "3k", "--max-loss", "1", "--stopband", "12k", "--min-attenuation",
            "40", "--no-sim", "--json", "--monte-carlo", "400", "--seed", "3", "--optimize", "yield"]
    assert design_filter_main(argv) == 0
    d = json.loads(capsys.readouterr().out)
    y = d["monte_carlo"]["yield"]
    assert y["samples"] == 400 and y["ci95"][0] <= y["fraction"] <= y["ci95"][1]
    o = d["optimize_yield"]
    # the same draws: the joint choice's yield is the Monte Carlo's
    assert o["yield_joint"] == pytest.approx(y["fraction"])
    assert o["yield_optimized"] >= o["yield_joint"]
    assert d["monte_carlo"]["tighten"]["part"] in d["monte_carlo"]["nominal_parts"]


def test_design_filter_optimize_needs_a_mask(capsys):
    assert design_filter_main(["--order", "4", "--fc", "1k", "--no-sim", "--optimize", "yield"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--optimize yield needs a mask" in err


def test_summary_shows_yield_and_worst_case(designed, capsys):
    capsys.readouterr()
    assert analyze_filter_main(["--from", str(designed), "--no-sim", "--monte-carlo", "200", "--worst-case"]) == 0
    out = capsys.readouterr().out
    for words in ("Monte Carlo: 200 builds", "95 % Wilson interval", "tighten stage", "Worst case over the tolerance"):
        assert words in out, words


@pytest.mark.spice
def test_analyze_filter_proof_and_spice_engine(designed, capsys):
    capsys.readouterr()
    assert analyze_filter_main(["--from", str(designed), "--json", "--monte-carlo", "100", "--spice-samples",
                                "5"]) == 0
    a = json.loads(capsys.readouterr().out)
    assert a["spice"]["nrms"]["ac_opamp"] < 1 and a["spice"]["nrms"]["tran_opamp"] < 1
    assert a["spice"]["mask"]["met"] is True
    assert a["monte_carlo"]["spice"]["samples"] == 5


def _stage_args(d: dict) -> list:
    """--stage and --part options of a design-filter result's stages (stage i's R1 is Ri01)."""
    argv = []
    for i, st in enumerate(d["stages"], 1):
        argv += ["--stage", st["topology"]]
        argv += [f"--part={r[0]}{i}0{r[1:]}={v!r}" for r, v in st["parts"].items()]
    return argv


def test_analyze_filter_per_stage_is_the_result_json(designed, capsys):
    """The same parts typed per stage (--target, --stage, --part) give what --from gives."""
    capsys.readouterr()
    d = json.loads(designed.read_text())
    target = "--family chebyshev --passband 3k --max-loss 1 --stopband 12k --min-attenuation 40"
    assert analyze_filter_main(["--target", target, *_stage_args(d), "--no-sim", "--json"]) == 0
    a = json.loads(capsys.readouterr().out)
    assert analyze_filter_main(["--from", str(designed), "--no-sim", "--json"]) == 0
    b = json.loads(capsys.readouterr().out)
    assert [s["parts"] for s in a["stages"]] == [s["parts"] for s in b["stages"]]
    assert [s["q"] for s in a["stages"]] == [s["q"] for s in b["stages"]]
    for k in ("f3_hz", "passband_deviation_db", "mask_passband_margin_db", "mask_stopband_margin_db"):
        assert a["figures"][k] == pytest.approx(b["figures"][k], rel=1e-9), k


@pytest.mark.parametrize("argv, words", [
    (["--stage", "sallen-key-lowpass"], "give --from RESULT_JSON, or --target"),
    (["--target", "--order 4 --fc 1k", "--stage", "sallen-key-lowpass"], "the target is 2 sections"),
    (["--target", "--order 2 --fc 1k", "--stage", "sallen-key-lowpass", "--part", "R101=1k"],
     "stage 1 (sallen-key-lowpass) needs R102"),
    (["--target", "--order 2 --fc 1k", "--stage", "mfb-highpass"], "the target has none left"),
    (["--target", "--order 2 --fc 1k", "--stage", "tow-thomas"], "tow-thomas"),
    (["--target", "--order 2 --bogus", "--stage", "sallen-key-lowpass"], "unrecognized arguments: --bogus"),
    (["--target", "--order 2 --fc 1k", "--stage", "rc-lowpass", "--stage", "rc-lowpass"], "the target is 1 sections"),
])
def test_analyze_filter_per_stage_bad_input(argv, words, capsys):
    assert analyze_filter_main(argv + ["--no-sim"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("analyze-filter: error: "), err
    assert words in err, err


def test_analyze_filter_from_and_target_exclude_each_other(designed, capsys):
    assert analyze_filter_main(["--from", str(designed), "--target", "--order 2 --fc 1k", "--no-sim"]) == 2
    assert "give one or the other" in capsys.readouterr().err


def test_design_filter_apply_optimum_builds_the_yield_optimal_set(capsys):
    argv = ["--family", "chebyshev", "--passband", "1k", "--max-loss", "1", "--stopband", "2k", "--min-attenuation",
            "40", "--topology", "mfb", "--opamp", "TL072", "--no-sim", "--json", "--monte-carlo", "600", "--seed", "5",
            "--optimize", "yield"]
    assert design_filter_main(argv) == 0
    joint = json.loads(capsys.readouterr().out)
    assert "applied" not in joint["optimize_yield"]   # without --apply-optimum: as before, the joint set built
    assert design_filter_main(argv + ["--apply-optimum"]) == 0
    built = json.loads(capsys.readouterr().out)
    o = built["optimize_yield"]
    assert o["applied"] and o["joint_parts"] == [s["parts"] for s in joint["stages"]]
    assert [s["parts"] for s in built["stages"]] == o["parts"]
    # the same draws: the built set's Monte Carlo yield is the optimum's, never below the joint one's
    assert built["monte_carlo"]["yield"]["fraction"] == pytest.approx(o["yield_optimized"])
    assert joint["monte_carlo"]["yield"]["fraction"] == pytest.approx(o["yield_joint"])
    assert o["yield_optimized"] >= o["yield_joint"]
    f = built["figures"]
    assert f["built"] == "yield-optimal" and f["error_joint_db"] == joint["figures"]["error_joint_db"]
    assert f["error_built_db"] >= f["error_joint_db"] - 1e-12   # the joint choice is the least error
    assert f["f3_hz"] != joint["figures"]["f3_hz"] or o["stages_changed"] == []


def test_design_filter_apply_optimum_summary_names_what_is_built(capsys):
    argv = ["--family", "chebyshev", "--passband", "1k", "--max-loss", "1", "--stopband", "2k", "--min-attenuation",
            "40", "--topology", "mfb", "--opamp", "TL072", "--no-sim", "--optimize", "yield", "--monte-carlo", "300",
            "--apply-optimum"]
    assert design_filter_main(argv) == 0
    assert "built: the yield-optimal set" in capsys.readouterr().out


BAND_MASK = ["--type", "bandpass", "--passband", "900,1.1k", "--max-loss", "1", "--stopband", "600,1.7k",
             "--min-attenuation", "30", "--opamp", "TL072"]


@pytest.mark.spice
def test_bandpass_mask_met_on_the_model_and_on_spice(tmp_path, capsys):
    assert design_filter_main(BAND_MASK + ["--json", "--out", str(tmp_path)]) == 0
    d = json.loads(capsys.readouterr().out)
    f, sp = d["figures"], d["spice"]
    assert d["spec"]["mask"]["passband_hz"] == [900.0, 1100.0] and d["spec"]["bandpass_method"] == "narrow"
    assert f["mask_passband_margin_db"] >= 0 and f["mask_stopband_margin_db"] >= 0
    assert f["mask_violation_joint_db"] == 0 <= f["mask_violation_per_stage_db"]
    # SPICE's .ac meets the mask too, and agrees with the model's margins at the edges
    assert sp["mask"]["met"]
    assert sp["mask"]["passband_margin_db"] == pytest.approx(f["mask_passband_margin_db"], abs=0.01)
    assert sp["mask"]["stopband_margin_db"] == pytest.approx(f["mask_stopband_margin_db"], abs=0.01)
    sheet = (tmp_path / "build-sheet.md").read_text()
    assert "loss <= 1 dB from 900 Hz to 1.1 kHz" in sheet and "below 600 Hz and above 1.7 kHz" in sheet
    # analyze-filter of the result keeps the mask (the same order and edges picked from it)
    assert analyze_filter_main(["--from", str(tmp_path / "result.json"), "--no-sim", "--json"]) == 0
    a = json.loads(capsys.readouterr().out)
    assert a["spec"]["mask"] == d["spec"]["mask"] and a["spec"]["order"] == d["spec"]["order"]
    assert a["figures"]["mask_passband_margin_db"] == pytest.approx(f["mask_passband_margin_db"])


def test_bandpass_mask_yield_counts_against_the_mask(capsys):
    argv = ["--type", "bandpass", "--family", "chebyshev", "--passband", "300,3k", "--max-loss", "1", "--stopband",
            "100,9k", "--min-attenuation", "30", "--opamp", "TL072", "--no-sim", "--json", "--monte-carlo", "300",
            "--seed", "2"]
    assert design_filter_main(argv) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["spec"]["bandpass_method"] == "wide"
    mc = d["monte_carlo"]
    # the yield's window is the mask's, and the nominal build's figures are the design's at the mask's edges
    assert {(lim["figure"], lim.get("min"), lim.get("max")) for lim in mc["limits"]} == \
        {("passband_loss_db", None, 1.0), ("stopband_attenuation_db", 30.0, None)}
    assert mc["nominal_figures"]["stopband_attenuation_db"] == pytest.approx(
        30.0 + d["figures"]["mask_stopband_margin_db"], abs=0.05)
    assert 0 <= mc["yield"]["passed"] <= 300


@pytest.mark.spice
def test_bessel_delay_target_picks_the_order_and_is_checked_on_spice(tmp_path, capsys):
    argv = ["--family", "bessel", "--passband", "1k", "--max-loss", "3", "--stopband", "10k", "--min-attenuation",
            "30", "--opamp", "TL072"]
    assert design_filter_main(argv + ["--no-sim", "--json"]) == 0
    plain = json.loads(capsys.readouterr().out)
    assert design_filter_main(argv + ["--max-delay-error", "1", "--delay-to", "1k", "--json", "--out",
                                      str(tmp_path)]) == 0
    d = json.loads(capsys.readouterr().out)
    f, m = d["figures"], d["spice"]["mask"]
    # the target raises the order above the mask's own, and the parts meet it
    assert d["spec"]["order"] > plain["spec"]["order"] and f["delay_target_met"]
    # SPICE's .ac phase gives the model's delay error (its sweep's lowest point standing for DC)
    assert m["delay_error_pct"] == pytest.approx(f["delay_error_pct"], abs=0.01) and m["met"]
    assert "group delay from DC to 1 kHz" in (tmp_path / "build-sheet.md").read_text()
    assert design_filter_main(argv + ["--max-delay-error", "1", "--delay-to", "1k", "--no-sim"]) == 0
    out = capsys.readouterr().out
    assert "the group delay within 1 % of its DC value up to 1 kHz" in out and ": met" in out


def test_delay_target_summary_shows_the_per_stage_roundings_delay(capsys):
    # the summary puts the joint choice's delay error beside the per-stage rounding's and the nearest values'
    argv = ["--family", "bessel", "--passband", "1k", "--max-loss", "3", "--stopband", "5k", "--min-attenuation",
            "40", "--max-delay-error", "0.15", "--delay-to", "500", "--series", "E12", "--c-series", "E12",
            "--opamp", "TL072", "--no-sim"]
    assert design_filter_main(argv + ["--json"]) == 0
    f = json.loads(capsys.readouterr().out)["figures"]
    assert design_filter_main(argv) == 0
    out = capsys.readouterr().out
    assert (f"group delay error (at most 0.15 %, weighed by the joint choice): joint {f['delay_error_pct']:.3g} %, "
            f"per-stage {f['delay_error_per_stage_pct']:.3g} %, nearest {f['delay_error_nearest_pct']:.3g} %") in out
    assert f["delay_target_met"] and not f["delay_target_met_per_stage"]


def test_analyze_filter_writes_its_sheet_in_the_language_asked(designed, tmp_path, capsys):
    from helpers import english_left
    assert analyze_filter_main(["--from", str(designed), "--no-sim", "--out", str(tmp_path / "es"), "--lang",
                                "es"]) == 0
    assert analyze_filter_main(["--from", str(designed), "--no-sim", "--out", str(tmp_path / "en")]) == 0
    capsys.readouterr()
    es, en = ((tmp_path / d / "build-sheet.md").read_text() for d in ("es", "en"))
    assert "Lista de materiales" in es and "máscara: margen en la banda de paso" in es and "hasta 3 kHz" in es
    assert "Bill of materials" in en and "mask: passband margin" in en
    assert english_left((tmp_path / "es" / "build-sheet.html").read_text()) == []


def test_delay_target_joins_the_mask_in_the_yield(capsys, tmp_path):
    argv = ["--family", "bessel", "--passband", "1k", "--max-loss", "3", "--stopband", "10k", "--min-attenuation",
            "30", "--max-delay-error", "1", "--delay-to", "1k", "--opamp", "TL072", "--no-sim", "--json",
            "--monte-carlo", "300", "--seed", "3"]
    assert design_filter_main(argv) == 0
    d = json.loads(capsys.readouterr().out)
    mc = d["monte_carlo"]
    assert {(lim["figure"], lim.get("min"), lim.get("max")) for lim in mc["limits"]} == \
        {("passband_loss_db", None, 3.0), ("stopband_attenuation_db", 30.0, None), ("delay_error_pct", None, 1.0)}
    assert mc["nominal_figures"]["delay_error_pct"] == pytest.approx(d["figures"]["delay_error_pct"], abs=1e-6)
    # the mask alone as --limit: the same draws, a yield at least as high
    assert design_filter_main(argv + ["--limit", "passband_loss_db=0:3", "--limit", "stopband_attenuation_db=30:1000"]) == 0
    plain = json.loads(capsys.readouterr().out)["monte_carlo"]
    assert plain["yield"]["passed"] >= mc["yield"]["passed"]
    # a delay limit on a filter without a delay target: one line, exit 2, nothing written
    out = tmp_path / "sheet"
    assert design_filter_main(["--family", "butterworth", "--order", "2", "--fc", "1k", "--no-sim", "--monte-carlo",
                               "100", "--limit", "delay_error_pct=0:1", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "--limit 'delay_error_pct': unknown figure" in err and len(err.strip().splitlines()) == 1
    assert not out.exists()


def test_design_filter_monte_carlo_the_same_whatever_the_workers():
    """--jobs 1, --jobs 2 and --dask local (a LocalCluster the command starts and stops) draw the same
    builds: the JSON's monte_carlo section is the same, byte for byte, and nothing is printed on stderr."""
    argv = [script("design-filter"), "--family", "chebyshev", "--passband", "1k", "--max-loss", "1", "--stopband",
            "3k", "--min-attenuation", "30", "--opamp", "TL072", "--monte-carlo", "2000", "--seed", "3", "--no-sim",
            "--json"]
    got = {}
    for where in (["--jobs", "1"], ["--jobs", "2"], ["--dask", "local"]):
        p = subprocess.run(argv + where, capture_output=True, text=True, timeout=300)
        assert p.returncode == 0 and p.stderr == "", (where, p.stderr)
        got[where[-1]] = json.dumps(json.loads(p.stdout)["monte_carlo"], sort_keys=True)
    assert got["1"] == got["2"] == got["local"]
    assert json.loads(got["1"])["yield"]["samples"] == 2000


def test_design_filter_alternatives_list_the_joint_searchs_best_sets(capsys):
    """--alternatives N: the JSON's alternatives are design_alternatives' (the joint choice first, its parts
    the stages'), the summary lists them with the mask met; without it the JSON has no such key."""
    from designer.filters import FilterSpec
    from designer.filters.alternatives import design_alternatives
    from designer.filters.design import design
    argv = ["--family", "chebyshev", "--passband", "1k", "--max-loss", "1", "--stopband", "3k", "--min-attenuation",
            "30", "--opamp", "TL072", "--no-sim"]
    assert design_filter_main(argv + ["--alternatives", "4", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    want = design_alternatives(design(FilterSpec(family="chebyshev", passband_hz=1e3, max_loss_db=1,
                                                 stopband_hz=3e3, min_attenuation_db=30, opamp="TL072")), 4)
    assert d["alternatives"] == [a.to_dict() for a in want]
    first = {}
    for st in d["stages"]:
        first.update({f"{r[0]}{st['stage']}0{r[1:]}": v for r, v in st["parts"].items()})
    assert d["alternatives"][0]["parts"] == first
    assert d["alternatives"][0]["error_db"] == pytest.approx(d["figures"]["error_joint_db"], abs=1e-12)
    assert design_filter_main(argv + ["--alternatives", "3"]) == 0
    out = capsys.readouterr().out
    assert "Alternatives (best first; the joint choice is 1; worst deviation from the ideal; limits: the mask):" in out
    assert out.count("meets the limits") + out.count("breaks the limits by") == 3
    assert design_filter_main(argv + ["--json"]) == 0
    assert "alternatives" not in json.loads(capsys.readouterr().out)


@pytest.mark.parametrize("value, words", [("2.5", "--alternatives must be a whole number from 1 to 50, got '2.5'"),
                                          ("51", "--alternatives must be 1 to 50, got '51'")])
def test_design_filter_alternatives_bad_count_is_one_line_nothing_written(tmp_path, capsys, value, words):
    assert design_filter_main(["--order", "4", "--fc", "1k", "--no-sim", "--alternatives", value,
                               "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and words in err
    assert list(tmp_path.iterdir()) == []
