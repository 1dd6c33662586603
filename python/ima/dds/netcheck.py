# SPDX-License-Identifier: Apache-2.0
"""Proof that DDS processes talk over loopback only, from what the kernel says about them.

check_loopback_only(pids) looks at every IP socket each process holds (/proc/PID/fd) and
accepts it only if the kernel would keep its traffic on the loopback interface:
 - its local address is a loopback address (127.0.0.0/8, ::1): the kernel refuses to route a
   packet with a loopback source out of any other interface; or
 - it is bound to the loopback device (SO_BINDTODEVICE, read through sock_diag): it receives
   only what came in on lo and sends only through lo, whatever its address (Cyclone binds its
   receive sockets to INADDR_ANY; ima-dds-node and ima.dds.bind_dds_sockets bind them to lo).
It also checks that no multicast group is joined on another interface (/proc/PID/net/igmp and
igmp6) beyond the groups the kernel joins by itself, and that no interface but loopback has
route_localnet on (which would let a packet with a loopback source out). Those belong to the
network namespace, not to one process: a group joined by any process shows up.
"""

from __future__ import annotations

import os
import socket
import struct
from dataclasses import dataclass

NETLINK_SOCK_DIAG = 4
SOCK_DIAG_BY_FAMILY = 20
NLM_F_REQUEST = 0x1
NLM_F_DUMP = 0x300
NLMSG_ERROR = 2
NLMSG_DONE = 3

NLMSG = struct.Struct("=IHHII")
# inet_diag_req_v2: family, protocol, ext, pad, states, then inet_diag_sockid
INET_DIAG_REQ = struct.Struct("=BBBBI")
# inet_diag_sockid: sport, dport (big-endian), src[16], dst[16], if, cookie[2]
SOCKID = struct.Struct("=HH16s16sI8s")
# inet_diag_msg: family, state, timer, retrans, sockid, expires, rqueue, wqueue, uid, inode
DIAG_MSG_HEAD = struct.Struct("=BBBB")
DIAG_MSG_TAIL = struct.Struct("=IIIII")

# Groups the kernel joins by itself (as /proc/net/igmp and igmp6 print them): all hosts on
# every multicast-capable interface, and on a bridge with multicast snooping the all-snoopers
# group of RFC 4286 (other runs' network namespaces and bridges come and go on a test host).
KERNEL_GROUPS_V4 = {"010000E0",  # 224.0.0.1, all hosts
                    "6A0000E0"}  # 224.0.0.106, all snoopers (bridge)
KERNEL_GROUPS_V6_PREFIXES = ("ff020000000000000000000000000001",  # all nodes, link-local
                             "ff010000000000000000000000000001",  # all nodes, node-local
                             "ff020000000000000000000000000002",  # all routers
                             "ff02000000000000000000000000006a",  # all snoopers (bridge)
                             "ff0200000000000000000001ff")  # solicited-node


SYSCTL_IPV4_CONF = "/proc/sys/net/ipv4/conf"


@dataclass
class SockInfo:
    inode: int
    proto: str  # udp, udp6, tcp, tcp6
    local: str
    port: int
    device: int | None = None  # bound device index (0: none), None if unknown


def _socket_inodes(pid: int) -> set[int]:
    out = set()
    fd_dir = f"/proc/{pid}/fd"
    for name in os.listdir(fd_dir):
        try:
            target = os.readlink(f"{fd_dir}/{name}")
        except OSError:
            continue  # closed meanwhile
        if target.startswith("socket:["):
            out.add(int(target[8:-1]))
    return out


def _addr(hexaddr: str, v6: bool) -> str:
    raw = bytes.fromhex(hexaddr)
    if not v6:
        return socket.inet_ntop(socket.AF_INET, raw[::-1])
    # four host-order 32-bit words
    words = b"".join(raw[i:i + 4][::-1] for i in range(0, 16, 4))
    return socket.inet_ntop(socket.AF_INET6, words)


def _proc_net(pid: int, proto: str) -> dict[int, SockInfo]:
    out = {}
    try:
        with open(f"/proc/{pid}/net/{proto}") as f:
            next(f)
            for line in f:
                parts = line.split()
                local, _ = parts[1].split(":")
                port = int(parts[1].split(":")[1], 16)
                inode = int(parts[9])
                out[inode] = SockInfo(inode, proto, _addr(local, proto.endswith("6")), port)
    except FileNotFoundError:
        pass
    return out


def _bound_devices(family: int, protocol: int) -> dict[int, int]:
    """inode -> bound device index of every socket of a family/protocol (sock_diag dump)."""
    s = socket.socket(socket.AF_NETLINK, socket.SOCK_RAW, NETLINK_SOCK_DIAG)
    try:
        req = INET_DIAG_REQ.pack(family, protocol, 0, 0, 0xFFFFFFFF) + SOCKID.pack(
            0, 0, b"", b"", 0, b"")
        msg = NLMSG.pack(NLMSG.size + len(req), SOCK_DIAG_BY_FAMILY, NLM_F_REQUEST | NLM_F_DUMP,
                         1, 0) + req
        s.sendto(msg, (0, 0))
        out = {}
        while True:
            data = s.recv(65536)
            off = 0
            while off + NLMSG.size <= len(data):
                length, mtype, _, _, _ = NLMSG.unpack_from(data, off)
                if mtype == NLMSG_DONE:
                    return out
                if mtype == NLMSG_ERROR:
                    (err,) = struct.unpack_from("=i", data, off + NLMSG.size)
                    raise OSError(-err, os.strerror(-err))
                body = off + NLMSG.size
                sockid = SOCKID.unpack_from(data, body + DIAG_MSG_HEAD.size)
                tail = DIAG_MSG_TAIL.unpack_from(data, body + DIAG_MSG_HEAD.size + SOCKID.size)
                out[tail[4]] = sockid[4]
                off += (length + 3) & ~3
            if not data:
                return out
    finally:
        s.close()


def _is_loopback(addr: str) -> bool:
    if ":" in addr:
        if addr.startswith("::ffff:"):
            return addr[7:].startswith("127.")
        return addr == "::1"
    return addr.startswith("127.")


def _comm(pid: int) -> str:
    try:
        with open(f"/proc/{pid}/comm") as f:
            return f.read().strip()
    except OSError:
        return "?"


def _igmp_problems(pid: int, loopback: str) -> list[str]:
    problems = []
    try:
        with open(f"/proc/{pid}/net/igmp") as f:
            dev = None
            next(f)
            for line in f:
                if not line.startswith("\t"):
                    dev = line.split()[1]
                    continue
                group = line.split()[0]
                if dev != loopback and group not in KERNEL_GROUPS_V4:
                    ip = socket.inet_ntop(socket.AF_INET, bytes.fromhex(group)[::-1])
                    problems.append(f"multicast group {ip} joined on {dev}")
    except FileNotFoundError:
        pass
    try:
        with open(f"/proc/{pid}/net/igmp6") as f:
            for line in f:
                parts = line.split()
                dev, group = parts[1], parts[2]
                if dev != loopback and not group.startswith(KERNEL_GROUPS_V6_PREFIXES):
                    problems.append(f"IPv6 multicast group {group} joined on {dev}")
    except FileNotFoundError:
        pass
    return problems


def _route_localnet_problems(loopback: str) -> list[str]:
    """Interfaces that would route a packet with a loopback source (net/ipv4/route.c).

    /proc/sys/net shows the network namespace of the process that reads it: ours."""
    base = SYSCTL_IPV4_CONF
    problems = []
    for dev in sorted(os.listdir(base)):
        if dev in (loopback, "default"):
            continue
        try:
            with open(f"{base}/{dev}/route_localnet") as f:
                if f.read().strip() != "0":
                    problems.append(f"route_localnet is on for {dev}: a packet from 127.0.0.1 "
                                    "may leave through it")
        except OSError:
            pass
    return problems


def sockets_of(pid: int) -> list[SockInfo]:
    """Every IP (UDP, TCP) socket pid holds, with its bound device where the kernel says."""
    inodes = _socket_inodes(pid)
    table: dict[int, SockInfo] = {}
    for proto in ("udp", "udp6", "tcp", "tcp6"):
        table.update(_proc_net(pid, proto))
    mine = [table[i] for i in sorted(inodes) if i in table]
    if mine:
        devs: dict[int, int] = {}
        for fam in (socket.AF_INET, socket.AF_INET6):
            for proto in (socket.IPPROTO_UDP, socket.IPPROTO_TCP):
                try:
                    devs.update(_bound_devices(fam, proto))
                except OSError:
                    pass
        for s in mine:
            s.device = devs.get(s.inode)
    return mine


def check_loopback_only(pids, device: str = "lo") -> list[str]:
    """Problems that could let traffic of these processes leave the machine ([] = none)."""
    problems: list[str] = []
    try:
        lo_index = socket.if_nametoindex(device)
    except OSError:
        return [f"no interface {device}"]
    netns_checked = set()
    for pid in pids:
        who = f"pid {pid} ({_comm(pid)})"
        try:
            socks = sockets_of(pid)
        except FileNotFoundError:
            problems.append(f"{who}: not running")
            continue
        for s in socks:
            if _is_loopback(s.local) or s.device == lo_index:
                continue
            if s.device is None:
                why = "its bound device is unknown (sock_diag unavailable)"
            elif s.device:
                why = f"bound to device index {s.device}, not {device}"
            else:
                why = "bound to no device"
            problems.append(f"{who}: {s.proto} socket {s.local}:{s.port} (inode {s.inode}) "
                            f"is not on loopback: {why}")
        try:
            ns = os.readlink(f"/proc/{pid}/ns/net")
        except OSError:
            ns = str(pid)
        if ns not in netns_checked:
            netns_checked.add(ns)
            problems += [f"{who}: {p}" for p in _igmp_problems(pid, device)]
            if len(netns_checked) == 1:
                problems += _route_localnet_problems(device)
    return problems
