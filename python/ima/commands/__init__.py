# SPDX-License-Identifier: Apache-2.0
"""Subcommands of the ima CLI: one module each, exposing add_parser(subparsers) and run(args)."""
