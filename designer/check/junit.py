"""The JUnit XML of a ``check-design`` run, in the layout the CI reporters
read (GitHub's JUnit actions, GitLab's ``artifacts:reports:junit``, Jenkins):
``<testsuites>`` with one ``<testsuite>`` per spec and one ``<testcase>`` per
check and corner, ``classname`` carrying the corner (``lab3-plant[TL072]``);
a failed check is a ``<failure>``, a simulator crash or timeout (or a spec
that proved bad while running) an ``<error>``, a report-only check
``<skipped>``; the versions (tool, Python, ngspice, simulator) and any golden
file warnings are ``<properties>`` of the suite. Counts and times are
attributes, as those readers expect.

The XML stays well-formed whatever the names and messages hold: ``<&>`` and
quotes are escaped, and the characters XML 1.0 forbids (C0 controls but tab,
newline and carriage return; lone surrogates, as a file name that is not UTF-8
decodes to; U+FFFE, U+FFFF) are written as visible escapes (:func:`visible`:
``\\x01``, ``\\xff`` for the byte 0xff of a file name), not U+FFFD, so that
the reader still sees which character it was.
"""

from __future__ import annotations

import re
import time
import xml.etree.ElementTree as ET

from .result import ERROR, FAIL, SIM_ERROR, SKIP, headline

__all__ = ["junit_xml", "visible"]


#: a character XML 1.0 does not allow: all but tab, newline, CR, U+0020-U+D7FF, U+E000-U+FFFD, U+10000 up
_NOT_XML = re.compile("[^\t\n\r\u0020-\ud7ff\ue000-\ufffd\U00010000-\U0010ffff]")


def visible(text) -> str:
    """``text`` with every character XML 1.0 forbids as a visible escape: ``\\x01``,
    ``\\x1b``; a lone surrogate from a byte that is not UTF-8 (surrogateescape) as
    that byte, ``\\xff``; any other as ``\\udXXX`` (not reversible: a backslash stays
    as it is).

    Parameters
    ----------
    text : str
        Any text.

    Returns
    -------
    str
        The text XML 1.0 can hold.
    """
    return _NOT_XML.sub(_escape, str(text))


def _escape(match) -> str:
    c = ord(match.group())
    if 0xDC80 <= c <= 0xDCFF:
        return f"\\x{c - 0xDC00:02x}"
    return f"\\x{c:02x}" if c < 0x100 else f"\\u{c:04x}"


def _seconds(s: float) -> str:
    return f"{max(0.0, s):.3f}"


def junit_xml(outcomes, seconds: float) -> str:
    """The XML document (text) for a run's :class:`~designer.check.result.SpecOutcome` list.

    Parameters
    ----------
    outcomes : list of designer.check.result.SpecOutcome
        The run's specs and their corners.
    seconds : float
        The run's duration.

    Returns
    -------
    str
        The JUnit XML document.
    """
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
    for el in root.iter():   # names, files, messages and warnings are the user's text
        for key, value in list(el.attrib.items()):
            el.set(key, visible(value))
        if el.text:
            el.text = visible(el.text)
    ET.indent(root)
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, encoding="unicode") + "\n"
