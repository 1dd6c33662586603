# SPDX-License-Identifier: Apache-2.0
"""CAN trace analysis (`ima trace`, docs/can-trace.md): one module per subcommand (stats,
replicas, diff, export, plot) over the frames of a run or a python-can log (source), with
exact frame lengths (bits) and DBC decoding (decode)."""
