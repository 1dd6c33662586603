# SPDX-License-Identifier: Apache-2.0
"""Reads a system model's YAML: the system file and the file it includes, merged into one
document, with the file and line every top-level key came from (for error messages and for
paths relative to the file that wrote them)."""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from ima import yamlfile
from ima.deploy.locate import Locator, path_text
from ima.deploy.model import SystemModelError

INCLUDE_KEY = "include"


@dataclass
class _File:
    path: Path
    doc: Any
    locator: Locator


@dataclass
class Source:
    """The merged document of a system model and where each top-level key was written."""

    doc: dict
    main: _File
    # top-level key -> the file that holds it (the system file unless it came from the include)
    owners: dict[str, _File] = field(default_factory=dict)

    def file_of(self, parts: tuple) -> _File:
        if parts and isinstance(parts[0], str) and parts[0] in self.owners:
            return self.owners[parts[0]]
        return self.main

    def where(self, parts: tuple) -> str:
        """`FILE:LINE` of the value at `parts` (or of its deepest existing parent)."""
        f = self.file_of(parts)
        line = f.locator.line(parts)
        return f"{f.path}:{line}" if line else str(f.path)

    def base(self, top_key: str) -> Path:
        """The folder that paths written under `top_key` are relative to."""
        return self.file_of((top_key,)).path.resolve().parent

    def included(self) -> list[Path]:
        """The files other than the system file that the model was read from."""
        return sorted({f.path.resolve() for f in self.owners.values()} - {self.main.path.resolve()})


def _read(path: Path) -> _File:
    if not path.is_file():
        raise SystemModelError(f"{path}: no such system file")
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise SystemModelError(f"{path}: cannot read: {exc}") from exc
    try:
        # Parsed once (libyaml's parser when PyYAML has it): the nodes keep the lines that
        # errors name, and the document is constructed from them, within yamlfile's bounds.
        root = yamlfile.compose(text)
        doc = yamlfile.construct(root)
    except yamlfile.YamlLimitError as exc:
        raise SystemModelError(f"{path}: refused: {exc}") from exc
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f"{path}:{mark.line + 1}" if mark else str(path)
        problem = getattr(exc, "problem", None) or str(exc)
        raise SystemModelError(f"{where}: not valid YAML: {problem}") from exc
    _check_unique_keys(root, path)
    return _File(path, doc, Locator(root))


def _check_unique_keys(node: yaml.Node | None, path: Path, parts: tuple = ()) -> None:
    """YAML keeps the last of two equal keys without a word: refuse them instead."""
    if isinstance(node, yaml.MappingNode):
        seen: set[str] = set()
        for key, value in node.value:
            name = key.value if isinstance(key, yaml.ScalarNode) else str(key)
            if name in seen:
                raise SystemModelError(f"{path}:{key.start_mark.line + 1}: {path_text(parts)}: "
                                       f"key '{name}' appears twice")
            seen.add(name)
            _check_unique_keys(value, path, parts + (name,))
    elif isinstance(node, yaml.SequenceNode):
        for i, item in enumerate(node.value):
            _check_unique_keys(item, path, parts + (i,))


def read_source(path: Path) -> Source:
    """The system file, merged with the file its `include` names (relative to the system
    file's folder). A key may be written in one of the two files only, and an included file
    includes nothing further: what a model is made of is never more than two files deep."""
    main = _read(path)
    if not isinstance(main.doc, dict):
        return Source(main.doc, main)  # the schema says what is wrong
    source = Source(dict(main.doc), main, {k: main for k in main.doc})
    ref = main.doc.get(INCLUDE_KEY)
    if ref is None:
        return source
    where = f"{main.path}:{main.locator.line((INCLUDE_KEY,))}: {INCLUDE_KEY}"
    if not isinstance(ref, str) or not ref:
        raise SystemModelError(f"{where}: expected the path of a YAML file, not {ref!r}")
    inc_path = Path(os.path.normpath(path.parent / ref))
    if not inc_path.is_file():
        raise SystemModelError(f"{where}: no such file: {inc_path}")
    inc = _read(inc_path)
    if not isinstance(inc.doc, dict):
        raise SystemModelError(f"{inc.path}: an included file is a mapping of system model keys")
    if INCLUDE_KEY in inc.doc:
        line = inc.locator.line((INCLUDE_KEY,))
        raise SystemModelError(f"{inc.path}:{line}: {INCLUDE_KEY}: an included file includes "
                               "nothing further")
    for key, value in inc.doc.items():
        if key in main.doc:
            raise SystemModelError(
                f"{main.path}:{main.locator.line((key,))}: {key}: also written in "
                f"{inc.path}:{inc.locator.line((key,))}: a key is written in one file only")
        source.doc[key] = value
        source.owners[key] = inc
    del source.doc[INCLUDE_KEY]
    return source
