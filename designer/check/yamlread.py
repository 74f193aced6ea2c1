"""A spec's YAML, read with bounds whatever the file holds: 1 MiB of YAML
aliases can stand for a billion nodes (a "billion laughs"), an alias can name
the node it sits in, a key given twice silently drops the first, and PyYAML's
composer recurses on nesting. :func:`compose` parses the text once with
PyYAML's SafeLoader, refuses all of that while composing and walking the node
graph (without recursion), then builds the data from the same nodes; every
refusal is one :class:`~designer.core.errors.DesignError` line ``file:line:
what``. It also gives the line of every key path, for the spec's own refusals
(:class:`designer.check.yamldoc._Doc`).
"""

from __future__ import annotations

import functools

from ..core.errors import DesignError
from ..core.fileio import show_cell, shown

__all__ = ["MAX_NODES"]

#: the YAML of a spec is bounded, whatever the file holds (1 MiB of aliases can stand for a billion
#: nodes): at most MAX_NODES nodes with every alias expanded (each use of an alias counts its whole
#: node again, so a few uses of a shared mapping are fine), nested at most MAX_DEPTH deep, and no
#: scalar longer than MAX_SCALAR characters (the top-level description: MAX_DESCRIPTION)
MAX_NODES = 10_000
MAX_DEPTH = 64
MAX_SCALAR = 4 * 1024
MAX_DESCRIPTION = 64 * 1024
_MERGE = "tag:yaml.org,2002:merge"


@functools.cache
def _loader_class():
    """yaml.SafeLoader refusing, while it composes, what would make the spec unbounded:
    an alias inside the node it names (a cycle), more than :data:`MAX_NODES`
    nodes with the aliases expanded, more than :data:`MAX_DEPTH` levels (the
    composer recurses); each refusal at the line of the alias or node."""
    import yaml

    class Loader(yaml.SafeLoader):
        def __init__(self, text, path):
            super().__init__(text)
            self.path = path
            self.total = 0      # nodes of the expanded tree so far (an alias adds its node's size)
            self.sizes = {}     # id(anchored node) -> its expanded size
            self.open = set()   # anchors of the nodes being composed: an alias to one is a cycle
            self.depth = 0

        def refuse(self, mark, message: str) -> DesignError:
            return DesignError(f"{shown(self.path)}:{mark.line + 1}: {message}")

        def count(self, n: int, mark, alias=None) -> None:
            self.total += n
            if self.total > MAX_NODES:
                what = (f"alias *{alias} makes the spec more than {MAX_NODES} YAML nodes with its aliases expanded "
                        "(each use repeats its whole node)" if alias else
                        f"the spec has more than {MAX_NODES} YAML nodes")
                raise self.refuse(mark, f"{what}; a spec may have at most {MAX_NODES}, aliases expanded")

        def compose_node(self, parent, index):
            event = self.peek_event()
            if isinstance(event, yaml.AliasEvent):
                if event.anchor in self.open:
                    raise self.refuse(event.start_mark, f"alias *{event.anchor} is inside the node it names "
                                      "(a recursive structure); an alias may only repeat a node that ends before it")
                if event.anchor in self.anchors:   # else the composer's own "undefined alias"
                    self.count(self.sizes[id(self.anchors[event.anchor])], event.start_mark, event.anchor)
                return super().compose_node(parent, index)
            if self.depth >= MAX_DEPTH:
                raise self.refuse(event.start_mark, f"the spec nests more than {MAX_DEPTH} levels deep; a spec "
                                  f"may nest at most {MAX_DEPTH}")
            self.count(1, event.start_mark)
            before, anchor = self.total - 1, event.anchor
            if anchor is not None:
                self.open.add(anchor)
            self.depth += 1
            try:
                node = super().compose_node(parent, index)
            finally:
                self.depth -= 1
                self.open.discard(anchor)
            if anchor is not None:
                self.sizes[id(node)] = self.total - before
            return node

        def construct_object(self, node, deep=False):
            try:
                return super().construct_object(node, deep)
            except ValueError as exc:   # a date that is none (2024-02-30), an integer of over 4300 digits
                why = str(exc).split(";")[0]
                raise yaml.constructor.ConstructorError(None, None, why, node.start_mark) from None

    return Loader


def _label(keys) -> str:
    return ".".join(map(str, keys)) or "the spec"


def _marks(root, path, loader) -> dict:
    """key path -> 1-based line, from the composed YAML node graph (no cycle,
    at most :data:`MAX_NODES` nodes expanded: :func:`_loader_class`), walked
    with a stack, not recursion; a key given twice in one mapping and a scalar
    over :data:`MAX_SCALAR` are refused. Keys merged in by ``<<`` take the
    line of their definition unless the mapping gives them itself."""
    import yaml

    def refuse(node, message):
        return DesignError(f"{shown(path)}:{node.start_mark.line + 1}: {message}")

    def check_length(node, keys, what):
        limit = MAX_DESCRIPTION if keys == ("description",) else MAX_SCALAR
        if isinstance(node, yaml.ScalarNode) and len(node.value) > limit:
            raise refuse(node, f"{what} is {len(node.value)} characters long; a value may have at most "
                         f"{MAX_SCALAR} (description: {MAX_DESCRIPTION})")

    out = {}
    stack = [(root, (), False)]   # (node, key path, merged in by <<: its lines yield to the mapping's own)
    while stack:
        node, keys, merged = stack.pop()
        out.setdefault(keys, node.start_mark.line + 1)
        check_length(node, keys, _label(keys))
        todo = []
        if isinstance(node, yaml.MappingNode):
            first = {}
            for k, v in node.value:
                line = k.start_mark.line + 1
                check_length(k, (), f"a key in {_label(keys)}")
                if k.tag == _MERGE:
                    out.setdefault(keys + ("<<",), line)
                    items = v.value if isinstance(v, yaml.SequenceNode) else [v]
                    todo += [(m, keys if isinstance(m, yaml.MappingNode) else keys + ("<<",), True) for m in items]
                    continue
                key = _key_of(loader, k)
                if key is not None and key in first:
                    where = f" in {_label(keys)}" if keys else ""
                    raise refuse(k, f"duplicate key {show_cell(k.value)}{where} (first at line {first[key]}); "
                                 "a key may appear once in a mapping")
                if key is not None:
                    first[key] = line
                child = keys + (_scalar(k),)
                if merged:
                    out.setdefault(child, line)
                else:
                    out[child] = line
                todo.append((v, child, merged))
        elif isinstance(node, yaml.SequenceNode):
            todo = [(v, keys + (i,), merged) for i, v in enumerate(node.value)]
        stack.extend(reversed(todo))   # popped in the file's order: the first problem is reported
    return out


def _key_of(loader, node):
    """A scalar key as the mapping will hold it (``1`` and ``0x1`` are one key), None for others."""
    import yaml
    if not isinstance(node, yaml.ScalarNode):
        return None   # a list or mapping as a key: the constructor refuses it (unhashable)
    key = loader.construct_object(node, deep=True)
    try:
        hash(key)
    except TypeError:
        return None
    return key


def _scalar(node):
    """A mapping key as the line table holds it: its text (keys are looked up as text)."""
    return node.value if hasattr(node, "value") and isinstance(node.value, str) else None


def compose(text: str, path):
    """(data, lines) of a spec's text: composed once with the bounded loader,
    checked (:func:`_marks`), then constructed from the same nodes."""
    loader = _loader_class()(text, path)
    try:
        node = loader.get_single_node()
        if node is None:
            return None, {}
        lines = _marks(node, path, loader)
        return loader.construct_document(node), lines
    finally:
        loader.dispose()
