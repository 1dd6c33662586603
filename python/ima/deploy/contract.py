# SPDX-License-Identifier: Apache-2.0
"""The build's step that turns a system model into the partitions' C contract (their ports,
processes and message checks): `python -m ima.deploy.contract MODEL.yaml GLUE_DIR STAMP`."""

from __future__ import annotations

import sys
from pathlib import Path

from ima.deploy.generate import write_glue
from ima.deploy.load import load_system
from ima.errors import ImaError


def main(argv: list[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else argv
    if len(args) != 3:
        print("usage: python -m ima.deploy.contract MODEL.yaml GLUE_DIR STAMP", file=sys.stderr)
        return 2
    model, glue_dir, stamp = (Path(a) for a in args)
    try:
        written = write_glue(load_system(model), glue_dir)
    except ImaError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return exc.exit_code
    # The stamp lists what was generated: the build's record that the step ran.
    stamp.write_text("".join(f"{path.name}\n" for path, _ in written), encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
