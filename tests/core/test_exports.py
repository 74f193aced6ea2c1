"""designer.core.exports: a package's names re-exported lazily (PEP 562), each module imported on first use."""

import sys

import pytest

from designer.core.exports import lazy_exports


@pytest.fixture
def lazy_package(tmp_path, monkeypatch):
    """A package of its own whose __init__ re-exports ``heavy.answer`` and ``light.name`` lazily."""
    pkg = tmp_path / "lazypkg"
    pkg.mkdir()
    (pkg / "__init__.py").write_text(
        "from designer.core.exports import lazy_exports\n\n"
        '__all__, __getattr__, __dir__ = lazy_exports(__name__, {"heavy": ("answer",), "light": ("name",)})\n')
    (pkg / "heavy.py").write_text('__all__ = ["answer"]\n\nanswer = 42\n')
    (pkg / "light.py").write_text('__all__ = ["name"]\n\nname = "light"\n')
    monkeypatch.syspath_prepend(str(tmp_path))
    yield "lazypkg"
    for mod in [m for m in sys.modules if m.split(".")[0] == "lazypkg"]:
        del sys.modules[mod]


def test_a_module_is_imported_on_first_use_only(lazy_package):
    import importlib
    pkg = importlib.import_module(lazy_package)
    assert pkg.__all__ == ["answer", "name"]
    assert "lazypkg.heavy" not in sys.modules and "lazypkg.light" not in sys.modules
    assert pkg.answer == 42
    assert "lazypkg.heavy" in sys.modules and "lazypkg.light" not in sys.modules
    assert pkg.answer is sys.modules["lazypkg.heavy"].answer and "answer" in vars(pkg)   # kept for the next use
    assert {"answer", "name"} <= set(dir(pkg))


def test_an_unknown_name_is_an_attribute_error(lazy_package):
    import importlib
    pkg = importlib.import_module(lazy_package)
    with pytest.raises(AttributeError, match="module 'lazypkg' has no attribute 'missing'"):
        pkg.missing
    assert not hasattr(pkg, "missing")


def test_the_table_gives_the_sorted_names():
    names, getattr_, dir_ = lazy_exports("designer.core", {"units": ("parse_value", "format_eng")})
    assert names == ["format_eng", "parse_value"] and callable(getattr_) and callable(dir_)
