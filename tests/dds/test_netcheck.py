# SPDX-License-Identifier: Apache-2.0
"""The loopback proof: what the kernel says about the sockets of live DDS processes."""

from __future__ import annotations

import os
import socket
import subprocess
import sys
import time

import pytest
from dds_helpers import exchange_round

from ima.dds import dds_env, netcheck


def test_agents_and_listener_stay_on_loopback(agents, connect, domain):
    ags = agents(3, security="off")  # the listener has no security plugins
    clients = {a.node: connect(a) for a in ags}
    listener = subprocess.Popen([sys.executable, "-m", "ima.dds.listen", "--domain",
                                 str(domain), "--timeout", "30", "--json"],
                                stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                                env=dds_env())
    try:
        for frame in range(5):
            exchange_round(clients, frame, {1: 7, 2: 7, 3: 7})
        time.sleep(1.0)  # the listener has joined by now
        assert listener.poll() is None, listener.stderr.read()
        pids = [a.pid for a in ags] + [listener.pid]
        assert netcheck.check_loopback_only(pids) == []
        lo = socket.if_nametoindex("lo")
        for a in ags:
            socks = netcheck.sockets_of(a.pid)
            # Cyclone's three: discovery and data receive sockets, the transmit socket
            assert len([s for s in socks if s.proto == "udp"]) >= 3
            for s in socks:
                assert s.device == lo, s
            assert any(s.local == "127.0.0.1" for s in socks)  # the transmit socket
            assert a.of_kind("dds_ready")[0]["bound_sockets"] == len(socks)
        assert netcheck.sockets_of(listener.pid)  # it does use DDS
    finally:
        listener.kill()
        listener.wait()


def test_a_socket_open_to_every_interface_is_reported():
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    try:
        s.bind(("0.0.0.0", 0))
        port = s.getsockname()[1]
        problems = netcheck.check_loopback_only([os.getpid()])
        assert any(f"0.0.0.0:{port}" in p and "bound to no device" in p for p in problems)
        s.setsockopt(socket.SOL_SOCKET, socket.SO_BINDTODEVICE, b"lo\0")
        assert not any(f":{port} " in p for p in netcheck.check_loopback_only([os.getpid()]))
    finally:
        s.close()
    t = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    try:
        t.bind(("127.0.0.1", 0))
        port = t.getsockname()[1]
        assert not any(f":{port} " in p for p in netcheck.check_loopback_only([os.getpid()]))
    finally:
        t.close()


def test_no_multicast_group_joined_off_loopback(agents):
    ags = agents(2)
    with open(f"/proc/{ags[0].pid}/net/igmp") as f:
        text = f.read()
    # the kernel's own groups at most (all hosts; all snoopers on a bridge)
    groups = [line.split()[0] for line in text.splitlines() if line.startswith("\t")]
    assert set(groups) <= netcheck.KERNEL_GROUPS_V4, text
    assert "0100FFEF" not in text  # Cyclone's default discovery group 239.255.0.1


def test_a_dead_pid_is_a_problem():
    p = subprocess.Popen(["true"])
    p.wait()
    assert netcheck.check_loopback_only([p.pid]) == [f"pid {p.pid} (?): not running"]


@pytest.mark.parametrize("device", ["nonexistent0"])
def test_unknown_device(device):
    assert netcheck.check_loopback_only([os.getpid()], device=device) == [
        f"no interface {device}"]


def test_route_localnet_is_reported(tmp_path, monkeypatch):
    for dev, val in (("lo", "1"), ("default", "1"), ("eth0", "1"), ("eth1", "0")):
        (tmp_path / dev).mkdir()
        (tmp_path / dev / "route_localnet").write_text(val + "\n")
    monkeypatch.setattr(netcheck, "SYSCTL_IPV4_CONF", str(tmp_path))
    problems = netcheck.check_loopback_only([os.getpid()])
    assert [p for p in problems if "route_localnet" in p] == [
        "route_localnet is on for eth0: a packet from 127.0.0.1 may leave through it"]
