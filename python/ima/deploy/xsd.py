# SPDX-License-Identifier: Apache-2.0
"""Validates a module file against config/schema/ima653_module.xsd with libxml2's xmllint, the
same schema and validator ima-ske loads modules with."""

from __future__ import annotations

import hashlib
import re
import shutil
import subprocess
from pathlib import Path

from ima import paths
from ima.errors import ImaError

RULE = "schema ima653_module.xsd"

# xmllint: "FILE:LINE: element NAME: Schemas validity error : MESSAGE"
_LINE = re.compile(r"^(?P<file>.*?):(?P<line>\d+): element (?P<elem>[^:]+): "
                   r"(?:Schemas validity|Schemas parser) error ?: (?P<msg>.*)$")


def module_schema() -> Path:
    return paths.repo_root() / "config" / "schema" / "ima653_module.xsd"


def _start_line(path: Path, line: int, element: str) -> int:
    """The line where the start tag of `element` reported at `line` begins. libxml2 gives the
    line where the tag ends; ima-ske, and so this, the line where it begins."""
    try:
        lines = path.read_text(encoding="utf-8").splitlines()
    except (OSError, UnicodeDecodeError):
        return line
    tag = re.compile(rf"<{re.escape(element)}(\s|/|>|$)")
    for n in range(min(line, len(lines)), 0, -1):
        if tag.search(lines[n - 1]):
            return n
    return line


# Contents this process found valid (with the schema as it was): a campaign's worker deploys
# the same modules run after run.
_VALID: set[tuple[bytes, int]] = set()


def validate_module(path: Path, timeout: float = 60.0) -> None:
    """Raises ImaError `FILE:LINE: error: ELEMENT: MESSAGE (rule: ...)` unless `path` is valid."""
    try:
        key = (hashlib.sha256(Path(path).read_bytes()).digest(),
               module_schema().stat().st_mtime_ns)
    except OSError:
        key = None
    if key is not None and key in _VALID:
        return
    xmllint = shutil.which("xmllint")
    if xmllint is None:
        raise ImaError("xmllint not found: it validates the generated modules; install "
                       "libxml2-utils (./ima checks for it)")
    cmd = [xmllint, "--noout", "--schema", str(module_schema()), str(path)]
    try:
        done = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired as exc:
        raise ImaError(f"xmllint --schema {path}: no answer after {timeout:g} s") from exc
    if done.returncode == 0:
        if key is not None:
            _VALID.add(key)
        return
    for line in done.stderr.splitlines():
        m = _LINE.match(line)
        if m:
            start = _start_line(path, int(m["line"]), m["elem"])
            raise ImaError(f"{path}:{start}: error: {m['elem']}: {m['msg'].strip()} "
                           f"(rule: {RULE})", exit_code=2)
    first = next((ln for ln in done.stderr.splitlines() if ln.strip()), "no message")
    raise ImaError(f"{path}: error: {first.strip()} (rule: {RULE}; xmllint exit code "
                   f"{done.returncode})", exit_code=2)
