# SPDX-License-Identifier: Apache-2.0
"""Lets `python -m ima` run the command-line tool."""

from ima.cli import main

raise SystemExit(main(exit_process=True))
