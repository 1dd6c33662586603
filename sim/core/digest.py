# SPDX-License-Identifier: Apache-2.0
"""Write the header that gives the module imaworld._core the digest of its sources
(imaworld.core.source_digest computes the same, and refuses a module built from others)."""

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from imaworld.core import source_digest  # noqa: E402

out = Path(sys.argv[1])
text = f'#pragma once\n#define CORE_SOURCE_DIGEST "{source_digest()}"\n'
if not out.is_file() or out.read_text() != text:
    out.write_text(text)
