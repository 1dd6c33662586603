# SPDX-License-Identifier: Apache-2.0
"""Every tunable parameter of the world in one place: sensors, actuators, atmosphere, limits."""

from __future__ import annotations

from dataclasses import dataclass, field

NS = 1_000_000_000
KT_TO_FPS = 1.6878098571011957
FT_TO_M = 0.3048
G_FPS2 = 32.174049


@dataclass(frozen=True)
class GpsParams:
    period_ms: int = 200  # GPS_POS + GPS_VEL at 5 Hz
    bias_tau_s: float = 300.0  # first-order Gauss-Markov position bias
    bias_sigma_h_m: float = 2.0  # per horizontal axis (north, east)
    bias_sigma_v_m: float = 4.0
    noise_h_m: float = 1.5  # white noise per horizontal axis
    noise_v_m: float = 3.0
    noise_vel_mps: float = 0.1  # white noise per ground-velocity axis (north, east)
    sats: int = 9
    # What a LOST receiver sends: "no_fix" = both frames, fix 0, zero data, counter runs on;
    # "silent" = nothing at all.
    lost_mode: str = "no_fix"


# Augmented GPS (the script's `gps_augmentation`): the errors it leaves (bias per horizontal
# axis, vertical bias, white noise horizontal and vertical, in metres) and the GPS_FIX it
# reports: SBAS-grade (a few decimetres) and GBAS-grade (approach and flare).
GPS_AUGMENTATION = {
    "none": {"bias_sigma_h_m": 2.0, "bias_sigma_v_m": 4.0, "noise_h_m": 1.5, "noise_v_m": 3.0,
             "fix": 3},
    "sbas": {"bias_sigma_h_m": 0.5, "bias_sigma_v_m": 1.0, "noise_h_m": 0.4, "noise_v_m": 0.8,
             "fix": 4},
    "gbas": {"bias_sigma_h_m": 0.1, "bias_sigma_v_m": 0.2, "noise_h_m": 0.15, "noise_v_m": 0.3,
             "fix": 5},
}


@dataclass(frozen=True)
class AhrsParams:
    period_ms: int = 20  # AHRS_ATT, AHRS_RATE, AHRS_ACCEL at 50 Hz
    noise_att_deg: float = 0.1  # roll, pitch
    noise_hdg_deg: float = 0.3
    bias_tau_s: float = 120.0
    bias_sigma_att_deg: float = 0.1
    bias_sigma_hdg_deg: float = 0.5
    noise_rate_dps: float = 0.05
    bias_sigma_rate_dps: float = 0.02
    noise_accel_g: float = 0.01
    bias_sigma_accel_g: float = 0.002


@dataclass(frozen=True)
class AdcParams:
    period_ms: int = 50  # AIR_DATA at 20 Hz
    noise_ias_kt: float = 0.3
    bias_sigma_ias_kt: float = 0.3
    noise_alt_ft: float = 2.0
    bias_sigma_alt_ft: float = 3.0
    bias_tau_s: float = 300.0
    noise_vs_fpm: float = 30.0


@dataclass(frozen=True)
class RadaltParams:
    period_ms: int = 50  # RADALT at 20 Hz
    range_ft: float = 1500.0  # sent only below this height: a low-range radio altimeter
    noise_ft: float = 0.3
    gear_ft: float = 4.4  # the c172p's centre of gravity above the ground on its wheels


@dataclass(frozen=True)
class ActuatorParams:
    status_period_ms: int = 50  # ACT_STATUS at 20 Hz
    surface_rate: float = 2.0  # normalised units per second (full travel -1..1 in 1 s)
    throttle_rate: float = 0.5
    surface_limit: float = 1.0  # |position| limit of elevator, aileron, rudder
    throttle_min: float = 0.0
    throttle_max: float = 1.0
    stale_s: float = 0.1  # no command for this long: commands have stopped (2 cycles)
    hold_s: float = 0.5  # then hold the last command this long ...
    safe_throttle: float = 0.0  # ... then go to the safe position (surfaces 0)
    startup_hold_s: float = 2.0  # before the first command: hold the trimmed positions this long


@dataclass(frozen=True)
class VotingParams:
    """How the smart actuators vote over the flight-control replicas: the system model's
    `voting` section and its major frame, which the launcher passes on (the world has no
    voting settings of its own). Votes are taken at k * period + offset."""
    thresholds: tuple  # |x - voted| above this is a miscompare (elev, ail, rud, thr; normalised)
    persist: int  # consecutive bad votes (miscompare or absent) before a channel is out
    offset_s: float  # when in each voting frame the vote is taken
    period_s: float  # one voting frame per major frame


@dataclass(frozen=True)
class StationParams:
    mode_period_ms: int = 100  # PILOT_MODE + PILOT_TARGETS at 10 Hz
    stick_period_ms: int = 50  # PILOT_STICK at 20 Hz
    downlink_fresh_s: float = 1.0  # an FCS channel's status counts as current this long


@dataclass(frozen=True)
class PilotModelParams:
    """The remote pilot model (pilot_model.py): how a remote pilot flies DIRECT from the
    downlinked telemetry alone (no attitude is downlinked: bank is read off the turn rate,
    heading off the ground track and the wind estimate). Gains are those of a calm, unhurried
    pilot: corrections of a few degrees and a few hundred ft/min."""
    takeover_s: float = 1.0  # from the downlink first showing DIRECT to the pilot's first input
    reaction_s: float = 0.3  # every input acts on what the telemetry showed this long before
    window_s: float = 1.0  # the pilot's eye: the track's trend over this much telemetry
    vs_window_s: float = 2.0  # ... and the altitude's
    fresh_s: float = 1.0  # telemetry older than this is not flown on
    # lateral: heading error -> desired turn rate -> roll stick on the turn-rate error
    hdg_gain: float = 0.1  # deg/s of turn rate per degree of heading error
    turn_rate_max: float = 1.5  # deg/s (half a standard-rate turn)
    roll_gain: float = 0.04  # roll stick per deg/s of turn-rate error
    roll_trim_gain: float = 0.004  # roll stick per deg/s-second (the pilot trims out a drift)
    roll_trim_max: float = 0.1
    roll_max: float = 0.2  # the largest roll input the pilot makes
    # vertical: altitude error -> desired vertical speed -> pitch stick
    alt_gain: float = 5.0  # ft/min per ft of altitude error
    vs_max: float = 500.0  # ft/min
    pitch_gain: float = 0.00005  # pitch stick per ft/min of vertical-speed error
    pitch_trim_gain: float = 0.000005  # pitch stick per ft/min-second
    pitch_trim_max: float = 0.15
    pitch_max: float = 0.2
    climb_power: float = 0.0002  # throttle added per ft/min of vertical speed wanted


@dataclass(frozen=True)
class FaultParams:
    # actuator_float without rate=: a surface no longer driven is brought back to its
    # aerodynamic neutral by its hinge moment, slowed by the actuator's own damping (a
    # backdriven jack); full travel to neutral in 10 s.
    float_rate_per_s: float = 0.1


@dataclass(frozen=True)
class AtmosphereParams:
    # MIL-F-8785C turbulence via JSBSim's Milspec model: (severity, wind at 20 ft AGL in kt).
    turbulence: dict = field(default_factory=lambda: {
        "none": (0, 0.0), "light": (3, 15.0), "moderate": (4, 30.0)})


@dataclass(frozen=True)
class LimitParams:
    max_roll_deg: float = 90.0  # beyond: loss of control, counted as a crash
    max_cas_kt: float = 200.0  # c172p Vne is 163 KCAS; past 200 the model is meaningless
    max_load_g: float = 8.0


@dataclass(frozen=True)
class WorldParams:
    aircraft: str = "c172p"
    physics_hz: int = 120
    truth_period_ms: int = 100  # truth.jsonl at 10 Hz
    mixture: float = 0.87
    gps: GpsParams = field(default_factory=GpsParams)
    ahrs: AhrsParams = field(default_factory=AhrsParams)
    adc: AdcParams = field(default_factory=AdcParams)
    radalt: RadaltParams = field(default_factory=RadaltParams)
    actuators: ActuatorParams = field(default_factory=ActuatorParams)
    station: StationParams = field(default_factory=StationParams)
    atmosphere: AtmosphereParams = field(default_factory=AtmosphereParams)
    limits: LimitParams = field(default_factory=LimitParams)
    faults: FaultParams = field(default_factory=FaultParams)
    pilot_model: PilotModelParams = field(default_factory=PilotModelParams)


DEFAULT = WorldParams()
