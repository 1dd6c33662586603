# SPDX-License-Identifier: Apache-2.0
"""Paths shared by the launch tests."""

from __future__ import annotations

from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
TRIPLEX = ROOT / "config" / "systems" / "rpas_triplex.yaml"
SIMPLEX = ROOT / "config" / "systems" / "rpas_simplex.yaml"
