# SPDX-License-Identifier: Apache-2.0
"""The redundancy voter of nodes/include/voter/voter.h, from Python (ctypes on libima_voter.so).

The world's smart actuators vote with the same C code the nodes link, so there is one voter in
the product. The library is $IMA_VOTER_LIB, else <build dir>/nodes/libima_voter.so (the build
dir is $IMA_BUILD_DIR, else <repo>/build).
"""

from __future__ import annotations

import ctypes
import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from ima.errors import ImaError

MAX_CH = 3
MAX_DIM = 12
CHANNELS = ("A", "B", "C")
STATUS_NAMES = ("MID3", "AVG2", "SINGLE", "SAFE", "DISAGREE")
REASON_NAMES = ("none", "miscompare", "absent")
MID3, AVG2, SINGLE, SAFE, DISAGREE = range(5)


class VoterCfg(ctypes.Structure):
    _fields_ = [("n", ctypes.c_uint), ("dim", ctypes.c_uint),
                ("threshold", ctypes.c_double * MAX_DIM), ("persist", ctypes.c_uint),
                ("safe", ctypes.c_double * MAX_DIM)]


class VoterState(ctypes.Structure):
    _fields_ = [("cfg", VoterCfg), ("count", ctypes.c_uint * MAX_CH),
                ("failed", ctypes.c_uint8), ("reason", ctypes.c_uint8 * MAX_CH),
                ("disagree_count", ctypes.c_uint), ("disagree", ctypes.c_bool),
                ("frames", ctypes.c_uint64)]


class VoterOut(ctypes.Structure):
    _fields_ = [("value", ctypes.c_double * MAX_DIM), ("status", ctypes.c_int),
                ("used", ctypes.c_uint8), ("miscompare", ctypes.c_uint8),
                ("newly_failed", ctypes.c_uint8), ("newly_disagree", ctypes.c_bool)]


_Vectors = (ctypes.c_double * MAX_DIM) * MAX_CH


def library_path() -> Path:
    env = os.environ.get("IMA_VOTER_LIB")
    if env:
        return Path(env)
    from ima import paths
    return paths.build_dir() / "nodes" / "libima_voter.so"


_lib: ctypes.CDLL | None = None


def library() -> ctypes.CDLL:
    """The loaded library (once per process), its layout checked against our mirror."""
    global _lib
    if _lib is not None:
        return _lib
    path = library_path()
    if not path.is_file():
        raise ImaError(f"the voter library is not built: {path} is missing (run ./ima to build, "
                       f"or set IMA_VOTER_LIB)")
    try:
        lib = ctypes.CDLL(str(path))
    except OSError as e:
        raise ImaError(f"cannot load the voter library {path}: {e}") from e
    lib.voter_init.argtypes = [ctypes.POINTER(VoterState), ctypes.POINTER(VoterCfg)]
    lib.voter_init.restype = ctypes.c_int
    lib.voter_reset.argtypes = [ctypes.POINTER(VoterState)]
    lib.voter_reset.restype = None
    lib.voter_step.argtypes = [ctypes.POINTER(VoterState), ctypes.POINTER(_Vectors),
                               ctypes.c_uint8, ctypes.POINTER(VoterOut)]
    lib.voter_step.restype = None
    lib.voter_mid3.argtypes = [ctypes.c_double] * 3
    lib.voter_mid3.restype = ctypes.c_double
    for f in ("voter_status_name", "voter_reason_name"):
        getattr(lib, f).argtypes = [ctypes.c_int]
        getattr(lib, f).restype = ctypes.c_char_p
    for f in ("voter_sizeof_cfg", "voter_sizeof_voter", "voter_sizeof_out"):
        getattr(lib, f).argtypes = []
        getattr(lib, f).restype = ctypes.c_size_t
    sizes = {"voter_cfg_t": (lib.voter_sizeof_cfg(), ctypes.sizeof(VoterCfg)),
             "voter_t": (lib.voter_sizeof_voter(), ctypes.sizeof(VoterState)),
             "voter_out_t": (lib.voter_sizeof_out(), ctypes.sizeof(VoterOut))}
    bad = [f"{k} is {c} bytes in C, {p} here" for k, (c, p) in sizes.items() if c != p]
    if bad:
        raise ImaError(f"{path} does not match sim/imaworld/voter.py: {'; '.join(bad)} "
                       f"(rebuild with ./ima)")
    _lib = lib
    return lib


def mid3(a: float, b: float, c: float) -> float:
    return library().voter_mid3(a, b, c)


def status_name(s: int) -> str:
    return library().voter_status_name(s).decode()


def reason_name(r: int) -> str:
    return library().voter_reason_name(r).decode()


def mask_letters(mask: int) -> str:
    """Channel bit mask -> letters, "AC" for 0b101."""
    return "".join(CHANNELS[c] for c in range(MAX_CH) if mask >> c & 1)


@dataclass(frozen=True)
class Vote:
    """One voting frame's result (voter_out_t)."""
    value: tuple[float, ...]  # dim values
    status: str  # "MID3", "AVG2", "SINGLE", "SAFE", "DISAGREE"
    used: int  # bit c: channel c formed the value
    miscompare: int  # bit c: channel c miscompared or missed
    newly_failed: int  # bit c: channel c declared failed this frame
    newly_disagree: bool


class Voter:
    """A voter_t of n channels of dim values. Raises ImaError on a configuration voter_init
    refuses (or that cannot even be passed to it)."""

    def __init__(self, n: int, dim: int, thresholds: Sequence[float], persist: int,
                 safe: Sequence[float] | None = None) -> None:
        self._lib = library()
        if not 1 <= dim <= MAX_DIM or len(thresholds) != dim or \
                (safe is not None and len(safe) != dim) or persist < 0 or n < 0:
            raise ImaError(f"bad voter configuration: n={n}, dim={dim}, "
                           f"{len(thresholds)} thresholds, persist={persist}")
        cfg = VoterCfg()
        cfg.n, cfg.dim, cfg.persist = n, dim, min(persist, 0xFFFFFFFF)
        for d in range(dim):
            cfg.threshold[d] = thresholds[d]
            cfg.safe[d] = 0.0 if safe is None else safe[d]
        self._v = VoterState()
        if self._lib.voter_init(ctypes.byref(self._v), ctypes.byref(cfg)) != 0:
            raise ImaError(f"bad voter configuration: n={n} (1..{MAX_CH}), dim={dim} "
                           f"(1..{MAX_DIM}), persist={persist} (>= 1), thresholds "
                           f"{list(thresholds)} (>= 0)")
        self.n, self.dim = n, dim
        self._x = _Vectors()
        self._out = VoterOut()

    def step(self, values: Sequence[Sequence[float] | None]) -> Vote:
        """One voting frame: values[c] is channel c's vector, or None if it sent nothing."""
        x, present = self._x, 0
        for c, vec in enumerate(values[:self.n]):
            if vec is None:
                continue
            present |= 1 << c
            row = x[c]
            for d in range(self.dim):
                row[d] = vec[d]
        out = self._out
        self._lib.voter_step(ctypes.byref(self._v), ctypes.byref(x), present,
                             ctypes.byref(out))
        return Vote(value=tuple(out.value[:self.dim]), status=STATUS_NAMES[out.status],
                    used=out.used, miscompare=out.miscompare, newly_failed=out.newly_failed,
                    newly_disagree=bool(out.newly_disagree))

    def reset(self) -> None:
        self._lib.voter_reset(ctypes.byref(self._v))

    def forgive(self, mask: int) -> None:
        """Test switch only (imaworld --test-switch no-vote-out): the channels of `mask` are
        no longer failed, their bad-frame counts start again from 0."""
        v = self._v
        v.failed &= ~mask & 0xFF
        for c in range(self.n):
            if mask >> c & 1:
                v.count[c] = 0
                v.reason[c] = 0

    @property
    def failed(self) -> int:
        """Bit c: channel c failed (latched)."""
        return self._v.failed

    def reason(self, c: int) -> str:
        """Why channel c failed: "none", "miscompare" or "absent"."""
        return REASON_NAMES[self._v.reason[c]]

    @property
    def disagree(self) -> bool:
        return bool(self._v.disagree)

    @property
    def frames(self) -> int:
        return self._v.frames

    @property
    def counts(self) -> tuple[int, ...]:
        return tuple(self._v.count[:self.n])

