# SPDX-License-Identifier: Apache-2.0
"""Names a value of a YAML document the way a reader finds it: its path and its line."""

from __future__ import annotations

from collections.abc import Iterable

import yaml


def path_text(parts: Iterable[str | int]) -> str:
    """`nodes[1].index` for ("nodes", 1, "index"); `(top level)` for ()."""
    out = ""
    for p in parts:
        out += f"[{p}]" if isinstance(p, int) else (f".{p}" if out else str(p))
    return out or "(top level)"


class Locator:
    """Maps a path in the loaded document to the line of the YAML text it came from."""

    def __init__(self, root: yaml.Node | None) -> None:
        self._root = root

    def line(self, parts: Iterable[str | int]) -> int | None:
        """The line (1-based) of the value at `parts`, or of its deepest existing parent. A
        value found under a mapping key is placed on the key's line (for a nested mapping, the
        line that names it)."""
        node = self._root
        if node is None:
            return None
        line = node.start_mark.line + 1
        for part in parts:
            child = None
            if isinstance(node, yaml.MappingNode):
                for key, value in node.value:
                    if isinstance(key, yaml.ScalarNode) and key.value == str(part):
                        child, line = value, key.start_mark.line + 1
                        break
            elif isinstance(node, yaml.SequenceNode) and isinstance(part, int):
                if 0 <= part < len(node.value):
                    child = node.value[part]
                    line = child.start_mark.line + 1
            if child is None:
                break
            node = child
        return line
