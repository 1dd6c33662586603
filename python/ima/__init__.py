# SPDX-License-Identifier: Apache-2.0
"""The ima tool: runs, tests and measures the IMA Testbed from one command line."""

__version__ = "0.1.0"
