# SPDX-License-Identifier: Apache-2.0
"""DDS Security material of one run: its own certificate authorities, one identity per node,
the signed governance and permissions documents (OMG DDS Security 1.1, builtin plugins).

    RUN_DIR/dds-security/          0700
      identity_ca.pem              the run's identity CA certificate
      permissions_ca.pem           the run's permissions CA certificate
      nodeK.pem, nodeK.key         node K's identity certificate and private key (0600)
      governance.p7s               who may join, what is protected (S/MIME, signed)
      permissions.p7s              one grant per node (S/MIME, signed)

The CAs' private keys live in a temporary directory while the documents are signed and are
deleted then: nothing can issue another identity for the run afterwards. Node K's grant lets
it publish the product's topics only in the DDS partition "nodeK" and read them in every
node's partition; a reader takes a sample's node from the partition its writer is in
(docs/security.md).

Modes (channels.dds.security in the system model, `ima launch --dds-security`):
  off      no security plugins (the Python tools can then join the run's domain)
  auth     authentication and access control; messages neither signed nor encrypted
  sign     as auth, and every RTPS message carries a MAC (the default)
  encrypt  as auth, and every RTPS message is encrypted (AES-GCM)
"""

from __future__ import annotations

import os
import shutil
import subprocess
import tempfile
from dataclasses import dataclass
from datetime import UTC, datetime, timedelta
from pathlib import Path

from ima.errors import ImaError

MODES = ("off", "auth", "sign", "encrypt")
DEFAULT_MODE = "sign"
TOPICS = ("rpas_CrossChannelInputs", "rpas_NodeHealth", "rpas_Telemetry", "rpas_MissionData")
DIR_NAME = "dds-security"
# Long enough for any run, short enough that a copied key is soon worthless.
VALID_DAYS = 7
_SUBJECT_ORG = "IMA Testbed run"
_RTPS_PROTECTION = {"auth": "NONE", "sign": "SIGN", "encrypt": "ENCRYPT"}


def node_partition(index: int) -> str:
    """The DDS partition node `index` publishes in."""
    return f"node{index}"


def subject(name: str) -> str:
    """The subject name of an identity, as the permissions document spells it."""
    return f"CN={name},O={_SUBJECT_ORG}"


@dataclass(frozen=True)
class Material:
    """Where a run's security files are."""

    dir: Path
    mode: str

    def identity(self, name: str) -> tuple[Path, Path]:
        return self.dir / f"{name}.pem", self.dir / f"{name}.key"


def _openssl(*args: str, cwd: Path) -> None:
    exe = shutil.which("openssl")
    if exe is None:
        raise ImaError("openssl not found (Debian package openssl): DDS Security needs it to "
                       "make the run's certificates; or run with --dds-security off")
    p = subprocess.run([exe, *args], cwd=cwd, capture_output=True, text=True)
    if p.returncode != 0:
        err = " ".join(p.stderr.split())[:300]
        raise ImaError(f"openssl {args[0]} failed: {err}")


def _key_opts(key: str) -> list[str]:
    # EC P-256: the builtin authentication plugin accepts it, and its handshake is the cheap one
    return ["-newkey", "ec", "-pkeyopt", "ec_paramgen_curve:prime256v1", "-nodes",
            "-keyout", key]


def _ca(name: str, cwd: Path) -> None:
    _openssl("req", "-x509", *_key_opts(f"{name}.key"), "-sha256", "-days", str(VALID_DAYS),
             "-subj", f"/O={_SUBJECT_ORG}/CN={name.replace('_ca', ' CA')}", "-out", f"{name}.pem",
             cwd=cwd)


def _identity(name: str, ca: Path, out: Path, cwd: Path) -> None:
    _openssl("req", "-x509", *_key_opts(str(out / f"{name}.key")), "-sha256",
             "-days", str(VALID_DAYS), "-subj", f"/O={_SUBJECT_ORG}/CN={name}",
             "-CA", str(ca / "identity_ca.pem"), "-CAkey", str(ca / "identity_ca.key"),
             "-addext", "basicConstraints=critical,CA:FALSE", "-out", str(out / f"{name}.pem"),
             cwd=cwd)
    os.chmod(out / f"{name}.key", 0o600)


def _sign(doc: str, name: str, ca: Path, out: Path) -> None:
    src = ca / f"{name}.xml"
    src.write_text(doc)
    _openssl("smime", "-sign", "-text", "-in", str(src), "-out", str(out / f"{name}.p7s"),
             "-signer", str(ca / "permissions_ca.pem"), "-inkey", str(ca / "permissions_ca.key"),
             cwd=ca)


def governance(domain: int, mode: str) -> str:
    """Who may join the domain and what is protected."""
    prot = _RTPS_PROTECTION[mode]
    return f"""<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"
     xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_governance.xsd">
  <domain_access_rules>
    <domain_rule>
      <domains><id>{domain}</id></domains>
      <allow_unauthenticated_participants>false</allow_unauthenticated_participants>
      <enable_join_access_control>true</enable_join_access_control>
      <discovery_protection_kind>NONE</discovery_protection_kind>
      <liveliness_protection_kind>NONE</liveliness_protection_kind>
      <rtps_protection_kind>{prot}</rtps_protection_kind>
      <topic_access_rules>
        <topic_rule>
          <topic_expression>*</topic_expression>
          <enable_discovery_protection>false</enable_discovery_protection>
          <enable_liveliness_protection>false</enable_liveliness_protection>
          <enable_read_access_control>true</enable_read_access_control>
          <enable_write_access_control>true</enable_write_access_control>
          <metadata_protection_kind>NONE</metadata_protection_kind>
          <data_protection_kind>NONE</data_protection_kind>
        </topic_rule>
      </topic_access_rules>
    </domain_rule>
  </domain_access_rules>
</dds>
"""


def _grant(name: str, domain: int, publish: list[str], subscribe: list[str],
           topics: tuple[str, ...], start: datetime, end: datetime) -> str:
    def rule(kind: str, partitions: list[str]) -> str:
        if not partitions:
            return ""
        tps = "".join(f"<topic>{t}</topic>" for t in topics)
        parts = "".join(f"<partition>{p}</partition>" for p in partitions)
        return (f"\n        <{kind}><topics>{tps}</topics>"
                f"<partitions>{parts}</partitions></{kind}>")

    fmt = "%Y-%m-%dT%H:%M:%S"
    return f"""    <grant name="{name}">
      <subject_name>{subject(name)}</subject_name>
      <validity><not_before>{start.strftime(fmt)}</not_before><not_after>{end.strftime(fmt)}</not_after></validity>
      <allow_rule>
        <domains><id>{domain}</id></domains>{rule("publish", publish)}{rule("subscribe", subscribe)}
      </allow_rule>
      <default>DENY</default>
    </grant>
"""


def permissions(domain: int, nodes: int, extra: dict[str, tuple] | None = None) -> str:
    """Node K publishes in partition nodeK only and reads every node's partition. `extra`:
    more grants, name -> (publish partitions, subscribe partitions, topics)."""
    now = datetime.now(UTC)
    start, end = now - timedelta(hours=1), now + timedelta(days=VALID_DAYS)
    every = [node_partition(k) for k in range(1, nodes + 1)]
    grants = [_grant(f"node{k}", domain, [node_partition(k)], every, TOPICS, start, end)
              for k in range(1, nodes + 1)]
    for name, (pub, sub, topics) in (extra or {}).items():
        grants.append(_grant(name, domain, list(pub), list(sub), tuple(topics), start, end))
    return f"""<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"
     xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_permissions.xsd">
  <permissions>
{"".join(grants)}  </permissions>
</dds>
"""


def prepare(run_dir: Path, nodes: int, domain: int, mode: str = DEFAULT_MODE,
            extra: dict[str, tuple] | None = None) -> Material | None:
    """Makes the run's CAs, node identities and signed documents in RUN_DIR/dds-security;
    None when mode is "off". `extra`: more identities and grants (the benchmark's ddsperf)."""
    if mode not in MODES:
        raise ImaError(f"DDS security mode {mode!r}: expected one of {', '.join(MODES)}")
    if mode == "off":
        return None
    out = run_dir / DIR_NAME
    if out.is_symlink() or (out.exists() and not out.is_dir()):
        raise ImaError(f"{out} exists and is not a directory")
    out.mkdir(mode=0o700, exist_ok=True)
    os.chmod(out, 0o700)
    with tempfile.TemporaryDirectory(prefix="ima-ca-") as tmp:
        ca = Path(tmp)
        for name in ("identity_ca", "permissions_ca"):
            _ca(name, ca)
            shutil.copyfile(ca / f"{name}.pem", out / f"{name}.pem")
        names = [f"node{k}" for k in range(1, nodes + 1)] + list(extra or {})
        for name in names:
            _identity(name, ca, out, ca)
        _sign(governance(domain, mode), "governance", ca, out)
        _sign(permissions(domain, nodes, extra), "permissions", ca, out)
    return Material(out, mode)


def mode_of(directory: Path) -> str | None:
    """The mode a run's material was made for, from its governance document; None if none."""
    try:
        text = (directory / "governance.p7s").read_text(errors="replace")
    except OSError:
        return None
    for mode, kind in _RTPS_PROTECTION.items():
        if f"<rtps_protection_kind>{kind}</rtps_protection_kind>" in text:
            return mode
    return None


def plugin_dir() -> Path:
    """Where Cyclone's security plugins are (Debian: libddsc0debian's own directory), for the
    tools configured by XML (ddsperf); the agent has it from CMake."""
    import glob
    import sysconfig

    arch = sysconfig.get_config_var("MULTIARCH") or "*"
    for pattern in (f"/usr/lib/{arch}/libddsc0debian", f"/usr/lib/{arch}", "/usr/local/lib"):
        for d in sorted(glob.glob(pattern)):
            if (Path(d) / "libdds_security_auth.so").is_file():
                return Path(d)
    raise ImaError("Cyclone's DDS Security plugins are not installed (Debian package "
                   "libddsc0debian)")


def cyclone_xml(material: Material, identity: str) -> str:
    """The <Security> part of a Cyclone configuration for `identity` of the run, for a tool
    that takes its configuration from CYCLONEDDS_URI (ddsperf)."""
    lib = plugin_dir()
    cert, key = material.identity(identity)
    d = material.dir

    def library(name: str, fn: str) -> str:
        return (f'<Library path="{lib}/lib{name}.so" initFunction="init_{fn}" '
                f'finalizeFunction="finalize_{fn}"/>')

    return ("<Security>"
            f"<Authentication>{library('dds_security_auth', 'authentication')}"
            f"<IdentityCA>file:{d}/identity_ca.pem</IdentityCA>"
            f"<IdentityCertificate>file:{cert}</IdentityCertificate>"
            f"<PrivateKey>file:{key}</PrivateKey></Authentication>"
            f"<AccessControl>{library('dds_security_ac', 'access_control')}"
            f"<PermissionsCA>file:{d}/permissions_ca.pem</PermissionsCA>"
            f"<Governance>file:{d}/governance.p7s</Governance>"
            f"<Permissions>file:{d}/permissions.p7s</Permissions></AccessControl>"
            f"<Cryptographic>{library('dds_security_crypto', 'crypto')}</Cryptographic>"
            "</Security>")
