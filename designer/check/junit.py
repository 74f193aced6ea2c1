"""The JUnit XML of a ``check-design`` run, in the layout the CI reporters
read (GitHub's JUnit actions, GitLab's ``artifacts:reports:junit``, Jenkins):
``<testsuites>`` with one ``<testsuite>`` per spec and one ``<testcase>`` per
check and corner, ``classname`` carrying the corner (``lab3-plant[TL072]``);
a failed check is a ``<failure>``, a simulator crash or timeout (or a spec
that proved bad while running) an ``<error>``, a report-only check
``<skipped>``; the versions (tool, Python, ngspice, simulator) and any golden
file warnings are ``<properties>`` of the suite. Counts and times are
attributes, as those readers expect.
"""

from __future__ import annotations

import time
import xml.etree.ElementTree as ET

from .result import ERROR, FAIL, SIM_ERROR, SKIP, headline


def _seconds(s: float) -> str:
    return f"{max(0.0, s):.3f}"


def junit_xml(outcomes, seconds: float) -> str:
    """The XML document (text) for a run's :class:`~designer.check.result.SpecOutcome` list."""
    root = ET.Element("testsuites", name="check-design")
    totals = {"tests": 0, "failures": 0, "errors": 0, "skipped": 0}
    stamp = time.strftime("%Y-%m-%dT%H:%M:%S", time.gmtime())
    for o in outcomes:
        n = o.counts()
        suite_time = sum(c.seconds for c in o.corners)
        suite = ET.SubElement(root, "testsuite", name=o.name, tests=str(n["tests"]), failures=str(n[FAIL]),
                              errors=str(n[ERROR]), skipped=str(n[SKIP]), time=_seconds(suite_time),
                              timestamp=stamp, file=o.file)
        props = ET.SubElement(suite, "properties")
        tool = o.tool
        for key in ("version", "python", "ngspice", "simulator"):
            name = "tool" if key == "version" else key
            value = f"{tool.get('name')} {tool.get('version')}" if key == "version" else tool.get(key)
            ET.SubElement(props, "property", name=name, value=str(value))
        ET.SubElement(props, "property", name="kind", value=o.kind)
        for i, w in enumerate(o.warnings):
            ET.SubElement(props, "property", name=f"warning_{i + 1}", value=w)
        for corner in o.corners:
            per_case = corner.seconds / max(1, len(corner.cases))
            classname = f"{o.name}[{corner.corner}]" if corner.corner else o.name
            for c in corner.cases:
                case = ET.SubElement(suite, "testcase", name=c.id, classname=classname, time=_seconds(per_case),
                                     file=o.file)
                line = headline(o, c)
                if c.status == FAIL:
                    el = ET.SubElement(case, "failure", message=line, type="check")
                    el.text = line
                elif c.status == ERROR:
                    kind = "simulator" if c.error_kind == SIM_ERROR else "spec"
                    el = ET.SubElement(case, "error", message=line, type=kind)
                    el.text = line
                elif c.status == SKIP:
                    ET.SubElement(case, "skipped", message=line)
        for key, k in (("tests", "tests"), ("failures", FAIL), ("errors", ERROR), ("skipped", SKIP)):
            totals[key] += n[k]
    for key, value in totals.items():
        root.set(key, str(value))
    root.set("time", _seconds(seconds))
    ET.indent(root)
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, encoding="unicode") + "\n"
