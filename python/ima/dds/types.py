# SPDX-License-Identifier: Apache-2.0
"""The DDS topic types of nodes/dds/rpas.idl as cyclonedds dataclasses (same names, order, keys).

rpas.idl is the source; tests/dds/test_types.py checks that these classes list the same fields
in the same order and that they interoperate with the C agent on the wire.
"""

from dataclasses import dataclass, field

from cyclonedds.idl import IdlStruct
from cyclonedds.idl.annotations import final, key
from cyclonedds.idl.types import array, float64, int64, uint32


@dataclass
@final
class CrossChannelInputs(IdlStruct, typename="rpas::CrossChannelInputs"):
    node: uint32
    key("node")
    frame: uint32 = 0
    t_ns: int64 = 0
    valid: uint32 = 0
    wait_mask: uint32 = 0
    gps_t_ns: int64 = 0
    ahrs_t_ns: int64 = 0
    air_t_ns: int64 = 0
    gps_seq: uint32 = 0
    gps_fix: uint32 = 0
    gps_sats: uint32 = 0
    ahrs_seq: uint32 = 0
    ahrs_status: uint32 = 0
    air_seq: uint32 = 0
    air_status: uint32 = 0
    plan_crc: uint32 = 0
    gps: array[float64, 5] = field(default_factory=lambda: [0.0] * 5)
    ahrs: array[float64, 9] = field(default_factory=lambda: [0.0] * 9)
    air: array[float64, 3] = field(default_factory=lambda: [0.0] * 3)


@dataclass
@final
class NodeHealth(IdlStruct, typename="rpas::NodeHealth"):
    node: uint32
    key("node")
    frame: uint32 = 0
    t_ns: int64 = 0
    membership: uint32 = 0
    flags: uint32 = 0
    fcs_mode: uint32 = 0
    failed: uint32 = 0


@dataclass
@final
class Telemetry(IdlStruct, typename="rpas::Telemetry"):
    node: uint32
    key("node")
    frame: uint32 = 0
    t_ns: int64 = 0
    fcs_mode: uint32 = 0
    fallback: uint32 = 0
    nav_flags: uint32 = 0
    lat_deg: float64 = 0.0
    lon_deg: float64 = 0.0
    alt_ft: float64 = 0.0
    ias_kt: float64 = 0.0
    gs_kt: float64 = 0.0
    hdg_deg: float64 = 0.0
    trk_deg: float64 = 0.0
    vs_fpm: float64 = 0.0
    roll_deg: float64 = 0.0
    pitch_deg: float64 = 0.0
    cmd: array[float64, 4] = field(default_factory=lambda: [0.0] * 4)


@dataclass
@final
class MissionData(IdlStruct, typename="rpas::MissionData"):
    node: uint32
    key("node")
    frame: uint32 = 0
    t_ns: int64 = 0
    mode: uint32 = 0
    lat_mode: uint32 = 0
    vert_mode: uint32 = 0
    hdg_deg: float64 = 0.0
    alt_ft: float64 = 0.0
    ias_kt: float64 = 0.0
    vs_fpm: float64 = 0.0


# Topic name -> type, in the order of rpas.idl.
TOPICS: dict[str, type[IdlStruct]] = {
    "rpas_CrossChannelInputs": CrossChannelInputs,
    "rpas_NodeHealth": NodeHealth,
    "rpas_Telemetry": Telemetry,
    "rpas_MissionData": MissionData,
}
