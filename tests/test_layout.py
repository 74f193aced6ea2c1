"""The dependency rule of the package, checked on every import statement:
``{cli, web} -> {plant, pid, identify} -> {spice, report} -> core`` (``web -> cli``), ``pid -> plant``,
and ``identify -> plant`` only for the comparison with a design; ``filters``
(the circuits as plug-ins) stands on ``spice`` and ``core`` only and the plant wing (a plant on any
topology) and what runs it stand on it; ``tolerance``
(Monte Carlo) runs the wings' models; ``check`` (the CI checker of users'
designs) runs the wings and tolerance, and only ``cli`` uses it."""

import ast
from pathlib import Path

from helpers import ROOT

PKG = ROOT / "designer"
#: layer -> the layers it may import from (besides itself)
ALLOWED = {
    "core": set(),
    "spice": {"core"},
    "report": {"core"},
    # the circuits as plug-ins (Topology, its sections, the cascade): below the wings
    "filters": {"core", "spice"},
    "plant": {"core", "spice", "report", "filters"},
    "pid": {"core", "spice", "report", "plant"},
    "identify": {"core", "spice", "report"},
    "tolerance": {"core", "spice", "report", "plant", "pid", "filters"},
    "check": {"core", "spice", "report", "plant", "pid", "identify", "tolerance", "filters"},
    "cli": {"core", "spice", "report", "plant", "pid", "identify", "check", "tolerance", "filters"},
    # the web page: a front end beside cli, whose parsers and checks it shares
    "web": {"core", "spice", "report", "plant", "pid", "identify", "check", "tolerance", "cli"},
}
#: the one module of identify that may use plant (the comparison with a design)
IDENTIFY_TO_PLANT = {"designer/identify/against.py"}


def imported_layers(path: Path):
    """(line, layer) of every designer.* import in a module, relative ones resolved."""
    rel = path.relative_to(ROOT).with_suffix("")
    pkg = list(rel.parts[:-1]) if rel.name != "__init__" else list(rel.parts[:-1])
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = pkg[: len(pkg) - (node.level - 1)]
                mod = base + (node.module.split(".") if node.module else [])
                targets = [mod] if node.module else [mod + [a.name] for a in node.names]
            else:
                targets = [node.module.split(".")] if node.module else []
        elif isinstance(node, ast.Import):
            targets = [a.name.split(".") for a in node.names]
        else:
            continue
        for t in targets:
            if t and t[0] == "designer" and len(t) > 1:
                yield node.lineno, t[1]


def test_imports_follow_the_dependency_rule():
    bad = []
    for path in sorted(PKG.rglob("*.py")):
        rel = path.relative_to(ROOT)
        if len(rel.parts) < 3:
            continue   # designer/__init__.py: the lazy public API names modules as strings
        layer = rel.parts[1]
        for line, target in imported_layers(path):
            if target == layer or target not in ALLOWED:
                continue
            ok = target in ALLOWED[layer] or (layer == "identify" and target == "plant"
                                              and str(rel) in IDENTIFY_TO_PLANT)
            if not ok:
                bad.append(f"{rel}:{line} imports designer.{target}")
    assert not bad, "\n".join(bad)
