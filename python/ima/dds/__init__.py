# SPDX-License-Identifier: Apache-2.0
"""DDS of a run: its domain id, the loopback-only Cyclone configuration, socket confinement.

Every DDS process of the product (the nodes' agents, `python -m ima.dds.listen`, the
benchmark's ddsperf) runs with config/dds/cyclonedds-loopback.xml and the run's own
domain id. Nothing here imports cyclonedds: the launcher uses it without loading Cyclone.
"""

from __future__ import annotations

import fcntl
import os
import random
import socket
import tempfile
import time
from pathlib import Path

from ima import paths
from ima.errors import ImaError

# DDSI maps domain d to UDP ports 7400 + 250 d + ...; ids above 232 overflow the port range.
# 0 is everybody's default: never used by a run.
DOMAIN_MIN = 1
DOMAIN_MAX = 230

LOCK_DIR = Path(tempfile.gettempdir()) / "ima-dds-domains"

_held: dict[int, int] = {}  # domain -> descriptor holding its lock


def config_path() -> Path:
    """The Cyclone configuration: $IMA_DDS_CONFIG, else the shipped loopback one."""
    env = os.environ.get("IMA_DDS_CONFIG")
    path = Path(env.removeprefix("file://")) if env else (
        paths.repo_root() / "config" / "dds" / "cyclonedds-loopback.xml")
    if not path.is_file():
        raise ImaError(f"Cyclone DDS configuration not found: {path}")
    return path.resolve()


def config_uri() -> str:
    """CYCLONEDDS_URI for config_path()."""
    return "file://" + str(config_path())


def dds_env(base: dict | None = None) -> dict:
    """An environment for a child process that uses DDS: the configuration set both ways."""
    env = dict(os.environ if base is None else base)
    env["CYCLONEDDS_URI"] = config_uri()
    env["IMA_DDS_CONFIG"] = str(config_path())
    return env


def use_loopback_config() -> None:
    """Points this process's Cyclone (the cyclonedds package) at the configuration.

    Call before creating the first DomainParticipant: Cyclone reads CYCLONEDDS_URI when a
    domain is created."""
    os.environ["CYCLONEDDS_URI"] = config_uri()


def domain_for_run(rng: random.Random | None = None) -> int:
    """Picks a DDS domain id no other run on this machine holds, and holds it.

    The draw is random (seeded from the pid and the clock) in DOMAIN_MIN..DOMAIN_MAX; an id is
    held through an flock on LOCK_DIR/<id>.lock, released by release_domain() or when every
    process that holds the descriptor has exited (children started with pass_fds=
    [domain_lock_fd(d)] keep it held). A crash never leaves an id taken."""
    rng = rng or random.Random(os.getpid() * 1_000_003 ^ time.time_ns())
    try:
        LOCK_DIR.mkdir(mode=0o1777, exist_ok=True)
        if LOCK_DIR.stat().st_uid == os.getuid():
            os.chmod(LOCK_DIR, 0o1777)  # shared by every user of the machine (sticky, like /tmp)
    except OSError as e:
        raise ImaError(f"cannot create the DDS domain lock folder {LOCK_DIR}: {e}") from e
    ids = list(range(DOMAIN_MIN, DOMAIN_MAX + 1))
    rng.shuffle(ids)
    for d in ids:
        if d in _held:
            continue
        path = LOCK_DIR / f"{d}.lock"
        try:
            fd = os.open(path, os.O_RDONLY | os.O_CREAT | os.O_CLOEXEC, 0o444)
        except OSError:
            continue
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            os.close(fd)
            continue
        _held[d] = fd
        return d
    raise ImaError(f"no free DDS domain id in {DOMAIN_MIN}..{DOMAIN_MAX} (see {LOCK_DIR})")


def domain_lock_fd(domain: int) -> int:
    """The descriptor holding `domain` (for pass_fds of the run's processes)."""
    try:
        return _held[domain]
    except KeyError:
        raise ImaError(f"DDS domain {domain} is not held by this process") from None


def release_domain(domain: int) -> None:
    fd = _held.pop(domain, None)
    if fd is not None:
        os.close(fd)


def bind_dds_sockets(device: str = "lo") -> int:
    """Binds every IP socket of this process to `device` (SO_BINDTODEVICE); returns the count.

    Cyclone binds its unicast receive sockets to INADDR_ANY whatever interface it is told to
    use; after this the kernel delivers to them only what came in on `device` and sends from
    them only through it. ima-dds-node does the same in C (--bind-device)."""
    count = 0
    for name in os.listdir("/proc/self/fd"):
        try:
            fd = int(name)
            s = socket.socket(fileno=os.dup(fd))
        except (ValueError, OSError):
            continue
        try:
            if s.family not in (socket.AF_INET, socket.AF_INET6):
                continue
            cur = s.getsockopt(socket.SOL_SOCKET, socket.SO_BINDTODEVICE, 16).split(b"\0")[0]
            if cur == device.encode():
                count += 1
                continue
            if cur:
                continue  # bound elsewhere by its owner: netcheck reports it
            s.setsockopt(socket.SOL_SOCKET, socket.SO_BINDTODEVICE, device.encode() + b"\0")
            count += 1
        except OSError:
            pass
        finally:
            s.close()  # the duplicate only
    return count
