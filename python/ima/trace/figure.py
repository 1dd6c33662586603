# SPDX-License-Identifier: Apache-2.0
"""Saving the subcommands' PNG plots: a folder that cannot take the file is an error with
one line, never a traceback; the figure is closed either way."""

from __future__ import annotations

from pathlib import Path

from ima.errors import ImaError


def save(fig, png: Path) -> None:
    import matplotlib.pyplot as plt

    fig.tight_layout()
    try:
        fig.savefig(png, dpi=110)
    except OSError as e:
        raise ImaError(f"{png}: cannot write the plot: {e.strerror}") from e
    finally:
        plt.close(fig)
