# SPDX-License-Identifier: Apache-2.0
"""YAML as the product reads it from users (system models, pilot scripts, campaign files):
safe types only, libyaml's parser when PyYAML has it, and a bound on what a document may
become. YAML aliases share a node, so ten lines of `&a [*b, *b, ...]` stand for billions of
values once taken apart, and an alias inside itself for an endless one; a document is refused
before it is constructed when it nests deeper than MAX_DEPTH or holds more than MAX_VALUES
values with its aliases counted where they are used."""

from __future__ import annotations

import math

import yaml

MAX_DEPTH = 64  # the product's own files nest 8 levels at most
MAX_VALUES = 1_000_000  # a 10-minute pilot script or the full campaign: well under 100,000

_LOADER = getattr(yaml, "CSafeLoader", yaml.SafeLoader)


class YamlLimitError(ValueError):
    """The document is beyond a bound (its message says which, and where)."""


def compose(text: str) -> yaml.Node | None:
    """The document's node graph (its lines kept), checked against the bounds; raises
    yaml.YAMLError for what is not YAML and YamlLimitError beyond the bounds."""
    loader = _LOADER(text)
    try:
        try:
            root = loader.get_single_node()
        except RecursionError:
            raise YamlLimitError(f"nested deeper than {MAX_DEPTH} levels") from None
    finally:
        loader.dispose()
    check(root)
    return root


def construct(root: yaml.Node | None):
    """The Python value of a checked node graph (safe types only)."""
    if root is None:
        return None
    loader = _LOADER("")
    try:
        return loader.construct_document(root)
    finally:
        loader.dispose()


def load_document(text: str, path, error: type[Exception]):
    """`load(text)`; a document beyond the bounds or not YAML raises `error` with one line
    naming `path` (and, for YAML, the line and column)."""
    try:
        return load(text)
    except YamlLimitError as e:
        raise error(f"{path}: refused: {e}") from e
    except yaml.YAMLError as e:
        mark = getattr(e, "problem_mark", None)
        where = f" (line {mark.line + 1}, column {mark.column + 1})" if mark else ""
        raise error(f"{path}: not valid YAML{where}: "
                    f"{getattr(e, 'problem', None) or e}") from e


def first_not_finite(value, where: tuple = ()) -> tuple[tuple, float] | None:
    """The first NaN or infinity in a loaded document, with the path to it (a JSON Schema's
    bounds let them through: every comparison with NaN is false); None if there is none."""
    if isinstance(value, float) and not math.isfinite(value):
        return where, value
    items = value.items() if isinstance(value, dict) else enumerate(value) \
        if isinstance(value, list) else ()
    for k, v in items:
        found = first_not_finite(v, where + (k,))
        if found is not None:
            return found
    return None


def load(text: str):
    """safe_load, within the bounds."""
    return construct(compose(text))


def check(root: yaml.Node | None) -> None:
    """Walks the node graph as construction would (an alias counted at every use), without
    recursion: refuses a depth beyond MAX_DEPTH (an alias inside itself never ends) and more
    than MAX_VALUES values."""
    if root is None:
        return
    count = 0
    stack = [(root, 1)]
    while stack:
        node, depth = stack.pop()
        count += 1
        if count > MAX_VALUES:
            raise YamlLimitError(f"more than {MAX_VALUES:,} values once its aliases are "
                                 f"expanded (line {node.start_mark.line + 1})")
        if depth > MAX_DEPTH:
            raise YamlLimitError(f"line {node.start_mark.line + 1}: nested deeper than "
                                 f"{MAX_DEPTH} levels (or an alias used inside itself)")
        if isinstance(node, yaml.SequenceNode):
            stack.extend((item, depth + 1) for item in node.value)
        elif isinstance(node, yaml.MappingNode):
            for key, value in node.value:
                stack.append((key, depth + 1))
                stack.append((value, depth + 1))
