# SPDX-License-Identifier: Apache-2.0
"""Shows a deployment summary: a rich table on a terminal, aligned plain text otherwise."""

from __future__ import annotations

from typing import IO

COLUMNS = ("Partition", "Node", "Guest", "Rate", "Processes", "Inputs", "Outputs",
           "Criticality", "Replicated")


def _rows(summary: dict) -> list[tuple[str, ...]]:
    rows = []
    for p in summary["partitions"]:
        rows.append((
            p["name"], p["node"], p["personality"], f"{p['rate_hz']:g} Hz",
            ", ".join(p["processes"]) or "-", ", ".join(p["inputs"]) or "-",
            ", ".join(p["outputs"]) or "-", p["criticality"],
            "yes" if p["replicated"] else "no",
        ))
    return rows


def _headline(summary: dict) -> str:
    nodes = summary["nodes"]
    names = ", ".join(f"{n['name']} ({n['channel']})" for n in nodes)
    return (f"System {summary['system']} ({summary['source']}): {len(nodes)} node"
            f"{'s' if len(nodes) != 1 else ''} [{names}], major frame "
            f"{summary['major_frame_s'] * 1000:g} ms")


def _channels(summary: dict) -> str:
    c = summary["channels"]
    return (f"Channels: {c['intra_node']} intra-node per node, {c['can_messages']} CAN "
            f"messages, {c['dds_topics']} DDS topics")


def _files(summary: dict) -> list[str]:
    files = summary["files"]
    width = max(len(f["path"]) for f in files)
    lines = [f"Generated {len(files)} files, {summary['total_lines']} lines, in "
             f"{summary['out_dir']}:"]
    lines += [f"  {f['path'].ljust(width)}  {f['lines']:>5} lines" for f in files]
    return lines


def format_plain(summary: dict) -> str:
    """The summary as aligned text (for logs, pipes and files)."""
    rows = [COLUMNS, *_rows(summary)]
    widths = [max(len(r[i]) for r in rows) for i in range(len(COLUMNS))]
    table = ["  ".join(cell.ljust(w) for cell, w in zip(r, widths, strict=True)).rstrip()
             for r in rows]
    return "\n".join([_headline(summary), "", *table, "", _channels(summary),
                      *_files(summary)]) + "\n"


def print_summary(summary: dict, out: IO[str], tty: bool | None = None) -> None:
    """Prints the summary on `out`: a rich table if it is a terminal, plain text otherwise."""
    if tty is None:
        tty = out.isatty()
    if not tty:
        out.write(format_plain(summary))
        return
    from rich.console import Console
    from rich.table import Table

    console = Console(file=out)
    console.print(_headline(summary), markup=False, highlight=False)
    table = Table(show_edge=False, header_style="bold")
    for col in COLUMNS:
        # The port lists wrap between names; the other cells stay whole.
        wraps = col in ("Processes", "Inputs", "Outputs")
        table.add_column(col, no_wrap=not wraps, overflow="fold" if wraps else "ellipsis")
    for row in _rows(summary):
        table.add_row(*row)
    console.print(table)
    console.print(_channels(summary), markup=False, highlight=False)
    for line in _files(summary):
        console.print(line, markup=False, highlight=False)
