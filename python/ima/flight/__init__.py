# SPDX-License-Identifier: Apache-2.0
"""Flights: running world, CAN bus and nodes together, and judging the result."""
