"""check.junit: the JUnit XML stays well-formed whatever a spec's file name,
name, corner, message or warning holds (control characters, a file name that
is not UTF-8, ``]]>``, quotes, ``<&>``): what XML allows is escaped and read
back exactly, what XML 1.0 forbids is written as a visible escape (``\\x01``)."""

import os
import subprocess
import xml.dom.minidom
import xml.etree.ElementTree as ET

import pytest
from helpers import script

from designer.check.junit import junit_xml, visible
from designer.check.result import ERROR, FAIL, PASS, SIM_ERROR, SKIP, SPEC_ERROR, Case, CornerOutcome, SpecOutcome
from designer.check.summary import summary_markdown

NASTY = "a\x01b\x1bc\x00d\x7f <&> \"q\" 'q' ]]> \ud800 \udcff \ufffe tab\tnl\ncr\r é 𝄞"
#: what XML allows, which must read back exactly
KEPT = "<&> \"q\" 'q' ]]>"


def outcome(text: str) -> SpecOutcome:
    cases = (Case("fn_hz", "TL072", FAIL, f"fn_hz = 3 kHz below min {text}"),
             Case("simulation", "TL072", ERROR, f"simulation: {text}", error_kind=SIM_ERROR),
             Case("zeta", "TL072", SKIP, f"report only: {text}"),
             Case(f"q{text}", "TL072", PASS, "q fine"),
             Case("golden_out", "TL072", ERROR, f"golden file {text}", error_kind=SPEC_ERROR))
    corner = CornerOutcome("TL072", cases, warnings=(f"golden file {text} was recorded elsewhere",), seconds=1.0)
    tool = {"name": "designer", "version": "0", "python": "3", "ngspice": text, "simulator": "pyspice"}
    return SpecOutcome(f"spec{text}", f"/specs/{text}.yaml", "plant", [corner], tool)


def test_visible_escapes_what_xml_forbids_and_keeps_the_rest():
    assert visible("a\x01b\x1b\x00") == "a\\x01b\\x1b\\x00"
    assert visible("lab\udcff.yaml") == "lab\\xff.yaml"     # os.fsdecode(b"lab\xff.yaml")
    assert visible("\ud800\ufffe\uffff") == "\\ud800\\ufffe\\uffff"
    assert visible(KEPT + "\t\n\r é 𝄞 \x7f") == KEPT + "\t\n\r é 𝄞 \x7f"


def test_the_xml_is_well_formed_whatever_the_names_and_messages_hold():
    text = junit_xml([outcome(NASTY)], 1.5)
    text.encode("utf-8")   # no lone surrogate left
    root = ET.fromstring(text.encode("utf-8"))
    xml.dom.minidom.parseString(text.encode("utf-8"))
    suite = root.find("testsuite")
    shown = visible(NASTY)
    assert suite.get("name") == f"spec{shown}" and suite.get("file") == f"/specs/{shown}.yaml"
    assert KEPT in suite.get("name") and "\\x01" in suite.get("name") and "\\xff" in suite.get("name")
    props = {p.get("name"): p.get("value") for p in suite.iter("property")}
    assert props["ngspice"] == shown and props["warning_1"] == f"golden file {shown} was recorded elsewhere"
    failure = suite.find("testcase/failure")
    assert failure.get("message") == f"spec{shown} [TL072]: fn_hz = 3 kHz below min {shown}"
    assert failure.text == failure.get("message").replace("\r", "\n")   # a parser reads a CR in text as a newline
    assert [c.get("name") for c in suite.iter("testcase")][3] == f"q{shown}"
    assert {c.tag for c in suite.iter() if c.tag in ("failure", "error", "skipped")} == {"failure", "error",
                                                                                         "skipped"}
    assert (suite.get("tests"), suite.get("failures"), suite.get("errors"), suite.get("skipped")) == ("5", "1", "2",
                                                                                                     "1")


def test_the_summary_shows_the_same_escapes():
    md = summary_markdown([outcome(NASTY)], 1.5)
    md.encode("utf-8")
    assert "\x01" not in md and "\\x01" in md and "\\xff" in md and "\n".join(md.splitlines()) + "\n" == md


RC = "rc\nV1 in 0 PULSE(0 1 1u 1n 1n 1 2)\nR1 in out 1k\nC1 out 0 1n\n.tran 10n 20u\n.meas tran vmax MAX v(out)\n.end\n"


@pytest.mark.spice
@pytest.mark.parametrize("raw", [b"lab\x01.yaml", b"lab\xff.yaml", b"lab\x1b]]>&<.yaml"])
def test_check_design_writes_well_formed_junit_for_a_spec_file_of_any_name(tmp_path, raw):
    folder = os.fsencode(tmp_path)
    with open(os.path.join(folder, b"rc.cir"), "w") as fh:
        fh.write(RC)
    spec = os.path.join(folder, raw)
    with open(spec, "w") as fh:   # the name: key, as the file's stem is no plain name
        fh.write("name: lab\nkind: netlist\ndeck: rc.cir\nchecks:\n  vmax: {max: 0.5}\n")
    junit, summary = tmp_path / "j.xml", tmp_path / "s.md"
    out = subprocess.run([os.fsencode(script("check-design")), spec, b"--junit", os.fsencode(junit), b"--summary",
                          os.fsencode(summary), b"--simulator", b"ngspice-cli"], capture_output=True, timeout=120)
    assert out.returncode == 1, out.stderr   # vmax ~ 1 V: above its max, a failure, reported
    data = junit.read_bytes()
    root = ET.fromstring(data)
    xml.dom.minidom.parseString(data)
    suite = root.find("testsuite")
    assert suite.get("name") == "lab" and suite.get("failures") == "1"
    assert suite.get("file") == visible(os.path.join(os.fsdecode(folder), os.fsdecode(raw)))
    assert "Traceback" not in out.stderr.decode("utf-8", "replace")
    assert "lab" in summary.read_text(encoding="utf-8")
