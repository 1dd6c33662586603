# SPDX-License-Identifier: Apache-2.0
"""Fixtures of the DDS tests: real ima-dds-node agents on a domain of their own, fake io clients."""

from __future__ import annotations

import shutil
import sys
import tempfile
from pathlib import Path

import pytest

from ima import dds
from ima.dds.agent import Agent, agent_binary, start_agents
from ima.dds.xch import XchClient

sys.path.insert(0, str(Path(__file__).resolve().parent))


@pytest.fixture(scope="session")
def agent_bin() -> Path:
    try:
        return agent_binary()
    except Exception as e:  # noqa: BLE001 - reported as a failure, with the reason
        pytest.fail(str(e))


@pytest.fixture
def domain():
    """A DDS domain id held for this test alone."""
    d = dds.domain_for_run()
    yield d
    dds.release_domain(d)


@pytest.fixture
def run_dir():
    # Short: Unix socket paths must fit in 108 bytes, pytest's tmp_path may not.
    d = Path(tempfile.mkdtemp(prefix="ima-dds-"))
    yield d
    shutil.rmtree(d, ignore_errors=True)


@pytest.fixture
def agents(agent_bin, run_dir, domain):
    """agents(nodes=3, realtime=False, extra=[...]) -> started, ready agents; stopped after."""
    started: list[Agent] = []

    def start(nodes: int = 3, **kw) -> list[Agent]:
        got = start_agents(nodes, run_dir, domain, **kw)
        started.extend(got)
        return got

    yield start
    for a in started:
        a.stop()


@pytest.fixture
def connect():
    """connect(agent) -> an XchClient playing that node's io partition; closed after."""
    clients: list[XchClient] = []

    def make(agent: Agent, timeout: float = 30.0) -> XchClient:
        c = XchClient(str(agent.socket), agent.node, timeout)
        clients.append(c)
        return c

    yield make
    for c in clients:
        c.close()

