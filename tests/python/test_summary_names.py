# SPDX-License-Identifier: Apache-2.0
"""The flight summary names modes and fallbacks as the DBC's value tables do (the DBC is the
one source of the message layouts)."""

from __future__ import annotations

from faultinject.traces import fcs_choices
from ima.flight import summary


def test_mode_and_fallback_names_are_the_dbcs() -> None:
    assert summary.MODE_NAMES == fcs_choices("FCS_MODE")
    assert summary.FALLBACK_NAMES == fcs_choices("FCS_FALLBACK")
