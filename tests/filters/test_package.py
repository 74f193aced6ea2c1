"""The package's own rules, checked on its source: every module declares
``__all__`` (and defines what it lists), ``designer.filters`` re-exports every
module's public API, no import cycle among its modules (imports inside
functions counted), no import of another module's ``_private`` name, imports
only from ``core`` and ``spice`` (and the standard library, numpy, scipy,
PySpice), and numpydoc docstrings (Parameters, Returns) on every public name."""

import ast
import importlib
import inspect

import designer.filters as filters
from helpers import ROOT

PKG = ROOT / "designer" / "filters"
MODULES = sorted(p.stem for p in PKG.glob("*.py") if p.stem != "__init__")


def imports(stem):
    """(module path as a list, imported names) of every import in a module of the package."""
    tree = ast.parse((PKG / f"{stem}.py").read_text())
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            base = ["designer", "filters"][: 3 - node.level] if node.level else []
            yield base + (node.module.split(".") if node.module else []), [a.name for a in node.names]
        elif isinstance(node, ast.Import):
            for a in node.names:
                yield a.name.split("."), []


def test_every_module_declares_all_and_the_package_reexports_it():
    exported = set(filters.__all__)
    owners = {}
    for stem in MODULES:
        for name in getattr(importlib.import_module(f"designer.filters.{stem}"), "__all__", ()):
            owners.setdefault(name, set()).add(stem)
    for stem in MODULES:
        mod = importlib.import_module(f"designer.filters.{stem}")
        assert hasattr(mod, "__all__"), stem
        for name in mod.__all__:
            assert hasattr(mod, name), (stem, name)
            if name in MODULES or len(owners[name]) > 1:
                # a module's own name, and a name several modules share (the generic search's joint_search and
                # the Sallen-Key fast path's), are reached through their module (designer.core.exports)
                continue
            assert name in exported and getattr(filters, name) is getattr(mod, name), (stem, name)


def test_no_import_cycle_no_private_import_and_only_core_spice_and_report_below():
    graph = {}
    for stem in MODULES:
        graph[stem] = set()
        for path, names in imports(stem):
            if path[:1] == ["designer"]:
                assert path[1] in ("filters", "core", "spice", "report"), (stem, path)
                assert not any(n.startswith("_") for n in names), (stem, path, names)
                if path[1] == "filters" and len(path) > 2:
                    graph[stem].add(path[2])

    def visit(node, trail):
        assert node not in trail, " -> ".join([*trail, node])
        for nxt in graph.get(node, ()):
            visit(nxt, [*trail, node])
    for stem in MODULES:
        visit(stem, [])


def public_callables():
    for name in filters.__all__:
        obj = getattr(filters, name)
        if inspect.isclass(obj):
            yield name, obj
            for attr, member in vars(obj).items():
                if not attr.startswith("_") and (inspect.isfunction(member) or isinstance(member, staticmethod)):
                    yield f"{name}.{attr}", getattr(obj, attr)
            for attr in ("coefficients", "synthesize", "netlist", "limits", "response", "figures"):
                if hasattr(obj, attr):
                    yield f"{name}.{attr}", getattr(obj, attr)
        elif inspect.isfunction(obj):
            yield name, obj


def test_public_names_have_numpydoc_parameters_and_returns():
    bad = []
    for name, obj in public_callables():
        doc = inspect.getdoc(obj) or ""
        if not doc:
            bad.append(f"{name}: no docstring")
            continue
        if inspect.isclass(obj):
            init = obj.__init__
            takes = init is not object.__init__ and len(inspect.signature(init).parameters) > 1
            if takes and "Parameters\n----------" not in doc and "Attributes\n----------" not in doc:
                bad.append(f"{name}: no Parameters")
            continue
        sig = inspect.signature(obj)
        params = [p for p in sig.parameters if p not in ("self", "cls")]
        if params and "Parameters\n----------" not in doc:
            bad.append(f"{name}: no Parameters")
        if sig.return_annotation not in (None, "None", inspect.Signature.empty) and "Returns\n-------" not in doc:
            bad.append(f"{name}: no Returns")
    assert not bad, "\n".join(bad)
