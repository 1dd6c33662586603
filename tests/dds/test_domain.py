# SPDX-License-Identifier: Apache-2.0
"""Per-run DDS domain ids: in range, held while in use, never handed out twice at once."""

from __future__ import annotations

import random
import subprocess
import sys

import pytest

from ima import dds
from ima.errors import ImaError


def test_ids_are_distinct_and_in_range():
    got = [dds.domain_for_run() for _ in range(20)]
    try:
        assert len(set(got)) == 20
        assert all(dds.DOMAIN_MIN <= d <= dds.DOMAIN_MAX for d in got)
    finally:
        for d in got:
            dds.release_domain(d)


def test_a_held_id_is_not_given_to_another_process():
    d = dds.domain_for_run(random.Random(1))
    try:
        # another process drawing with the same seed gets a different id
        code = ("import random; from ima import dds; "
                "print(dds.domain_for_run(random.Random(1)))")
        out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                             check=True).stdout
        assert int(out) != d
    finally:
        dds.release_domain(d)
    # released: the same draw gets it again
    again = dds.domain_for_run(random.Random(1))
    assert again == d
    dds.release_domain(again)


def test_lock_fd_and_config():
    d = dds.domain_for_run()
    try:
        assert dds.domain_lock_fd(d) >= 0
    finally:
        dds.release_domain(d)
    with pytest.raises(ImaError):
        dds.domain_lock_fd(d)
    assert dds.config_uri().startswith("file:///")
    assert dds.config_path().name == "cyclonedds-loopback.xml"
    env = dds.dds_env({})
    assert env["CYCLONEDDS_URI"] == dds.config_uri()


def test_shipped_config_keeps_to_loopback():
    text = dds.config_path().read_text()
    for needle in ('<NetworkInterface name="lo" multicast="false"',
                   "<AllowMulticast>false</AllowMulticast>",
                   "<ParticipantIndex>auto</ParticipantIndex>",
                   "<MaxAutoParticipantIndex>20</MaxAutoParticipantIndex>",
                   '<Peer address="127.0.0.1"/>', '<Domain Id="any">'):
        assert needle in text
