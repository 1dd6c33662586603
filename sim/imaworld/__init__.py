# SPDX-License-Identifier: Apache-2.0
"""The simulated world: JSBSim aircraft, sensors, smart actuators, wind, C2 link, pilot station."""
