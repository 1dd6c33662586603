# SPDX-License-Identifier: Apache-2.0
"""Seeded mutations of the product's input files: mild ones (a number scaled, an optional key
dropped) that mostly stay valid and reach past the parsers, and hostile ones (bytes flipped,
lines cut or repeated, extreme or non-finite numbers, empty, huge or non-ASCII names,
entities, deep nesting) that must be refused with one clear error."""

from __future__ import annotations

import copy
import math
import random
import re

# Values a careless or hostile user writes where a number or a name belongs.
HOSTILE_VALUES = [0, -1, 1e308, -1e308, math.nan, math.inf, 2**63, -(2**63), "", "x" * 5000,
                  "héllo名前", "a\u0000b", None, [], {}, True, "0x", "1e999", "-0"]
HOSTILE_TEXT = ["<!DOCTYPE a [<!ENTITY e \"x\">]>", "&e;", "\u0000", "\ufffd\ufffe", "]]>",
                "<![CDATA[", "*a", "&a [", "{{{{", "\t", "\r\n", "é" * 300, "9" * 400]

_NUMBER = re.compile(r"(?<![\w.])(\d+(?:\.\d+)?)(?![\w.])")


def mild_number(rng: random.Random, value: float | int) -> float | int:
    """A plausible other value: scaled a little, or one step away."""
    if isinstance(value, bool):
        return not value
    if isinstance(value, int):
        return max(1, value + rng.choice((-1, 1))) if abs(value) < 64 else \
            int(value * rng.choice((0.5, 2)))
    return round(value * rng.uniform(0.8, 1.2), 6)


def mutate_text(rng: random.Random, text: str) -> str:
    """A hostile edit of the raw text."""
    lines = text.splitlines(keepends=True)
    op = rng.randrange(8)
    if op == 0 and text:  # a character replaced
        i = rng.randrange(len(text))
        return text[:i] + rng.choice("<>&\"'=/\\ \n\u00e9\u0000#*-:[]{}") + text[i + 1:]
    if op == 1 and lines:  # a line dropped
        del lines[rng.randrange(len(lines))]
        return "".join(lines)
    if op == 2 and lines:  # a line repeated
        i = rng.randrange(len(lines))
        lines.insert(i, lines[i])
        return "".join(lines)
    if op == 3:  # cut short
        return text[:rng.randrange(len(text) + 1)]
    if op == 4:  # junk inserted
        i = rng.randrange(len(text) + 1)
        return text[:i] + rng.choice(HOSTILE_TEXT) + text[i:]
    if op == 5:  # a number made extreme
        found = list(_NUMBER.finditer(text))
        if found:
            m = rng.choice(found)
            new = rng.choice(["0", "-1", "1e308", "nan", "inf", "99999999999999999999", "-0",
                              "0.0000000001"])
            return text[:m.start()] + new + text[m.end():]
    if op == 6 and len(lines) > 1:  # two lines swapped
        i, j = rng.randrange(len(lines)), rng.randrange(len(lines))
        lines[i], lines[j] = lines[j], lines[i]
        return "".join(lines)
    return text + rng.choice(HOSTILE_TEXT)


# Attributes of a module a designer changes on their own, and plausible other values.
_MILD_XML = [
    (re.compile(r'StackSize="(\d+)"'), lambda rng, v: str(int(v) * rng.choice((2, 4)))),
    (re.compile(r'MaxNbMessages="(\d+)"'), lambda rng, v: str(max(1, int(v) + rng.choice(
        (-4, -1, 1, 8))))),
    (re.compile(r'SizeBytes="(0x[0-9a-fA-F]+)"'), lambda rng, v: hex(int(v, 16) * 2)),
    (re.compile(r'Criticality="(LEVEL_[A-E])"'), lambda rng, v: rng.choice(
        ["LEVEL_A", "LEVEL_B", "LEVEL_C", "LEVEL_D", "LEVEL_E"])),
    (re.compile(r'ModuleVersion="([^"]*)"'), lambda rng, v: str(rng.randrange(1, 99))),
]


def mutate_text_mild(rng: random.Random, text: str) -> str:
    """One or two attributes of a module file given plausible other values."""
    for _ in range(rng.choice((1, 2))):
        rx, change = rng.choice(_MILD_XML)
        found = list(rx.finditer(text))
        if not found:
            continue
        m = rng.choice(found)
        text = text[:m.start(1)] + change(rng, m.group(1)) + text[m.end(1):]
    return text


def _paths(doc, at=()):
    """Every (path, value) of a nested document."""
    yield at, doc
    if isinstance(doc, dict):
        for k, v in doc.items():
            yield from _paths(v, at + (k,))
    elif isinstance(doc, list):
        for i, v in enumerate(doc):
            yield from _paths(v, at + (i,))


def _set(doc, path, value):
    node = doc
    for k in path[:-1]:
        node = node[k]
    node[path[-1]] = value


def _delete(doc, path):
    node = doc
    for k in path[:-1]:
        node = node[k]
    del node[path[-1]]


def mutate_doc(rng: random.Random, doc, mild: bool):
    """A copy of a parsed YAML document with one change: mild (a number nudged, a list item
    dropped or repeated) or hostile (a value replaced by one of HOSTILE_VALUES, a key dropped,
    a value nested deep)."""
    doc = copy.deepcopy(doc)
    paths = [p for p, _ in _paths(doc) if p]
    if not paths:
        return rng.choice(HOSTILE_VALUES)
    if mild:
        numbers = [p for p, v in _paths(doc) if p and isinstance(v, int | float)]
        lists = [p for p, v in _paths(doc) if p and isinstance(v, list) and len(v) > 1]
        if numbers and (not lists or rng.random() < 0.8):
            p = rng.choice(numbers)
            _set(doc, p, mild_number(rng, _get(doc, p)))
        elif lists:
            p = rng.choice(lists)
            items = _get(doc, p)
            if rng.random() < 0.5:
                del items[rng.randrange(len(items))]
            else:
                items.append(copy.deepcopy(rng.choice(items)))
        return doc
    p = rng.choice(paths)
    op = rng.randrange(3)
    if op == 0:
        _set(doc, p, copy.deepcopy(rng.choice(HOSTILE_VALUES)))
    elif op == 1:
        _delete(doc, p)
    else:
        deep = _get(doc, p)
        for _ in range(rng.choice((10, 70, 150))):
            deep = [deep]
        _set(doc, p, deep)
    return doc


def _get(doc, path):
    for k in path:
        doc = doc[k]
    return doc
