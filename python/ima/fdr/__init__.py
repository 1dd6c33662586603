# SPDX-License-Identifier: Apache-2.0
"""Flight data recorder files: decoding (records.py) and their plots (plot.py)."""
