# SPDX-License-Identifier: Apache-2.0
"""Benchmarks run by `ima bench`; each prints its measurements (JSON with --json)."""
