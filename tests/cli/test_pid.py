"""design-pid from the outside: the console script, its JSON, its files and
its one-line errors (exit status 2, nothing written)."""

import json
import os
import subprocess
from pathlib import Path

import pytest
from helpers import script

from designer.pid import tuning

DESIGN_PID = script("design-pid")
DESIGN_PLANT = script("design-plant")


def run(*args, cwd=None):
    env = dict(os.environ, MPLBACKEND="Agg")
    return subprocess.run([DESIGN_PID, *args], capture_output=True, text=True, cwd=cwd, env=env, timeout=300)


def test_help_teaches():
    p = run("--help")
    assert p.returncode == 0
    for word in ("--plant-fc", "--tuning", "optimize", "--kp", "Kp = R5 R3/(R6 R4)", "examples:"):
        assert word in p.stdout


@pytest.mark.spice
def test_json_keys_and_files(tmp_path):
    p = run("--plant-fc", "3500", "--plant-zeta", "0.2", "--json", "--out", str(tmp_path), "--name", "zn")
    assert p.returncode == 0, p.stderr
    d = json.loads(p.stdout)
    assert {"plant", "tuning", "components", "achieved", "checks", "closed_loop", "files"} <= set(d)
    t = d["tuning"]
    assert t["method"] == "zn"
    assert {"kp", "ti_s", "td_s", "model", "reaction_curve", "fopdt_fit"} <= set(t)
    assert t["model"]["source"] == "tangent" and t["model"]["L_s"] == t["reaction_curve"]["L_s"]
    assert {"K", "L_s", "T_s"} <= set(t["reaction_curve"]) and {"K", "L_s", "T_s"} <= set(t["fopdt_fit"])
    # every rule row says which model it used: the tangent for ZN, the fit for the others
    assert {r["method"]: r["model"]["source"] for r in d["rules"]} == tuning.RULE_MODEL
    comps = d["components"]
    assert {f"R{i}_ohm" for i in range(3, 19)} | {"C3_f", "C4_f"} <= set(comps)
    assert {"kp", "ti_s", "td_s", "f_integrator_hz", "f_differentiator_hz", "f_summer_hz"} <= set(d["achieved"])
    assert all({"name", "ok", "detail"} <= set(c) for c in d["checks"])
    cl = d["closed_loop"]
    assert cl["analytic"]["overshoot_pct"] is not None
    assert {"saturated", "stable", "nrms", "overshoot_pct"} <= set(cl["spice"])
    # files exist and result.json is the same JSON
    for key in ("netlist", "build_sheet_md", "build_sheet_html", "result_json"):
        assert Path(d["files"][key]).is_file()
    assert json.loads(Path(d["files"]["result_json"]).read_text())["components"] == comps
    html = Path(d["files"]["build_sheet_html"]).read_text()
    assert "data:image/png;base64" in html and "R13" in html
    # the deck runs on its own and prints its measurements
    deck = d["files"]["netlist"]
    out = subprocess.run(["ngspice", "-b", deck], capture_output=True, text=True, timeout=120)
    assert "overshoot_pct" in out.stdout and "u_max" in out.stdout


@pytest.mark.spice
def test_explicit_gains_seed_final_design_with_seed_parts():
    p = run("--plant-fc", "3500", "--plant-zeta", "0.2", "--kp", "45", "--ti", "43.215u", "--td", "10.8037u",
            "--seed-parts", "--json", "--no-files")
    assert p.returncode == 0, p.stderr
    d = json.loads(p.stdout)
    assert d["tuning"]["method"] == "explicit" and d["tuning"]["kp"] == 45
    assert d["achieved"]["kp"] == pytest.approx(45, rel=1e-3)
    assert d["closed_loop"]["spice"]["saturated"] is True
    assert d["closed_loop"]["spice"]["stable"] is False
    failed = {c["name"] for c in d["checks"] if not c["ok"]}
    assert {"closed_loop_stable", "phase_margin"} <= failed


def test_plant_from_design_plant_result(tmp_path):
    p = subprocess.run([DESIGN_PLANT, "--fc", "3500", "--zeta", "0.2", "--no-sim", "--out", str(tmp_path),
                        "--name", "plant"], capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr
    rj = tmp_path / "reports" / "plant" / "result.json"
    built = json.loads(rj.read_text())["built"]
    q = run("--plant-json", str(rj), "--tuning", "amigo", "--json", "--no-sim", "--no-files")
    assert q.returncode == 0, q.stderr
    d = json.loads(q.stdout)
    assert d["plant"]["R1_ohm"] == built["R1_ohm"] and d["plant"]["C2_f"] == built["C2_f"]
    assert d["tuning"]["method"] == "amigo"
    assert d["closed_loop"]["spice"] is None


def test_plant_parts_and_pi_rule():
    p = run("--plant-r1", "820", "--plant-r2", "1k", "--plant-c1", "10n", "--plant-c2", "220n", "--tuning", "simc",
            "--opamp", "TL072", "--json", "--no-sim", "--no-files")
    assert p.returncode == 0, p.stderr
    d = json.loads(p.stdout)
    assert d["tuning"]["td_s"] == 0
    assert "R7_ohm" not in d["components"] and "C3_f" not in d["components"]
    assert d["achieved"]["f_differentiator_hz"] is None


@pytest.mark.parametrize("args,needle", [
    (["--plant-fc", "3500", "--plant-zeta", "0.2", "--kp", "0", "--ti", "43u", "--td", "10u"], "--kp"),
    (["--plant-fc", "3500", "--plant-zeta", "0.2", "--kp", "3", "--ti", "-43u", "--td", "10u"], "--ti"),
    (["--plant-fc", "3500", "--plant-zeta", "0.2", "--kp", "3", "--ti", "43u"], "together"),
    (["--plant-fc", "3500", "--plant-zeta", "0.2", "--opamp", "uA709"], "unknown op-amp"),
    (["--plant-fc", "-3500", "--plant-zeta", "0.2"], "--plant-fc"),
    (["--plant-fc", "3500"], "--plant-zeta"),
    ([], "plant"),
    (["--plant-fc", "3500", "--plant-zeta", "0.2", "--tuning", "magic"], "--tuning"),
    (["--plant-fc", "3500", "--plant-zeta", "0.2", "--tuning", "optimize"], "--target-overshoot"),
    (["--plant-fc", "3500", "--plant-zeta", "0.2", "--r-min", "1M", "--r-max", "1k"], "--r-min"),
    (["--plant-fc", "3500", "--plant-zeta", "0.2", "--step", "0"], "--step"),
    (["--plant-fc", "3500", "--plant-zeta", "0.2", "--r-series", "E7"], "E-series"),
    (["--plant-r1", "820", "--plant-r2", "1k"], "together"),
    (["--plant-fc", "3500", "--plant-zeta", "0.2", "--frobnicate"], "unrecognized"),
])
def test_bad_input_is_one_line_exit_2_nothing_written(tmp_path, capsys, args, needle):
    # in-process (the same entry point as the console script) to keep the file fast
    from designer.cli.pid import design_pid_main
    code = design_pid_main([*args, "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert code == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("design-pid: error:")
    assert needle in lines[0]
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").rglob("*.*"))


def test_bad_input_through_the_console_script(tmp_path):
    p = run("--plant-fc", "3500", "--plant-zeta", "0.2", "--kp", "-1", "--ti", "1u", "--td", "1u",
            "--out", str(tmp_path / "out"))
    assert p.returncode == 2 and "Traceback" not in p.stderr
    assert len(p.stderr.strip().splitlines()) == 1 and "--kp" in p.stderr
    assert not (tmp_path / "out").exists()


def _main(capsys, *args):
    from designer.cli.pid import design_pid_main
    code = design_pid_main(list(args))
    return code, capsys.readouterr().err


def test_plant_json_that_is_not_a_result(tmp_path, capsys):
    bad = tmp_path / "x.json"
    bad.write_text(json.dumps({"hello": 1}))
    code, err = _main(capsys, "--plant-json", str(bad), "--no-files")
    assert code == 2 and "not a design-plant result" in err
    bad.write_text("not json")
    code, err = _main(capsys, "--plant-json", str(bad), "--no-files")
    assert code == 2 and "not JSON" in err
    code, err = _main(capsys, "--plant-json", str(tmp_path / "missing.json"), "--no-files")
    assert code == 2 and "--plant-json file" in err and "does not exist" in err


def test_unwritable_output_directory(tmp_path, capsys):
    blocker = tmp_path / "file"
    blocker.write_text("x")
    code, err = _main(capsys, "--plant-fc", "3500", "--plant-zeta", "0.2", "--no-sim", "--out", str(blocker / "sub"))
    assert code == 2 and len(err.strip().splitlines()) == 1


@pytest.mark.spice
def test_a_cascade_plants_pid_writes_its_bundle(tmp_path):
    """Bug: design-pid on a 4th-order design-filter cascade hung at its sheet for good (the renderer and the
    command each blocked sending to the other, core.workers); it writes the whole bundle now."""
    f = subprocess.run([script("design-filter"), "--family", "butterworth", "--order", "4", "--fc", "1k",
                        "--opamp", "TL072", "--no-sim", "--name", "f4", "--out", str(tmp_path)],
                       capture_output=True, text=True, timeout=300)
    assert f.returncode == 0, f.stderr
    p = subprocess.run([script("design-pid"), "--plant-json", str(tmp_path / "reports" / "f4" / "result.json"),
                        "--name", "p4", "--out", str(tmp_path)], capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr
    bundle = tmp_path / "reports" / "p4"
    assert {"result.json", "build-sheet.html", "schematic.png", "closed-loop.png"} <= {x.name for x in
                                                                                        bundle.iterdir()}
    assert json.loads((bundle / "result.json").read_text())["closed_loop"]["spice"] is not None


def test_optimize_without_a_stable_start_names_each_rule_once():
    # a 50 kHz Sallen-Key plant an LM741's stages cannot close: every rule's loop is unstable or refused, and
    # the refusal printed 'simc: simc: the model has complex poles ..' (the rule's reason already names it)
    p = run("--plant-topology", "sallen-key-lowpass", "--plant-part", "R1=1300", "R2=2400", "C1=1.2n", "C2=2.7n",
            "--tuning", "optimize", "--no-sim", "--no-files")
    assert p.returncode == 2 and len(p.stderr.splitlines()) == 1, p.stderr
    assert "optimize needs a rule whose loop is stable to start from" in p.stderr
    assert "simc: the model has complex poles" in p.stderr and "simc: simc:" not in p.stderr
    assert "imc: imc:" not in p.stderr and "zn: unstable" in p.stderr
