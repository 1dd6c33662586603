# SPDX-License-Identifier: Apache-2.0
"""Helpers of the DDS tests: distinct inputs per node and frame, a lockstep round of exchanges."""

from __future__ import annotations

from ima.dds.xch import Agreed, Inputs, XchClient


def inputs_for(node: int, frame: int, wait_mask: int) -> Inputs:
    """Distinct, checkable inputs of a node for a frame."""
    return Inputs(valid=0x7, wait_mask=wait_mask, gps_t_ns=frame * 50_000_000 - node,
                  gps_seq=node * 10_000 + frame, ahrs_seq=frame, air_seq=node,
                  gps=[47.0 + node / 10, 8.0 + frame / 1000, 3000.0, 100.0, 90.0],
                  ahrs=[float(node), float(frame)] + [0.5] * 7, air=[100.0, 3000.0, -node * 1.0])


def dds_inputs(node: int, frame: int, wait_mask: int):
    """inputs_for as the CrossChannelInputs sample a node's agent publishes for the frame."""
    from ima.dds.types import CrossChannelInputs

    x = inputs_for(node, frame, wait_mask)
    return CrossChannelInputs(node=node, frame=frame, t_ns=frame * 50_000_000, valid=x.valid,
                              wait_mask=x.wait_mask, gps_t_ns=x.gps_t_ns, ahrs_t_ns=x.ahrs_t_ns,
                              air_t_ns=x.air_t_ns, gps_seq=x.gps_seq, gps_fix=x.gps_fix,
                              gps_sats=x.gps_sats, ahrs_seq=x.ahrs_seq,
                              ahrs_status=x.ahrs_status, air_seq=x.air_seq,
                              air_status=x.air_status, gps=x.gps, ahrs=x.ahrs, air=x.air)


def exchange_round(clients: dict[int, XchClient], frame: int, masks: dict[int, int],
                   timeout: float = 20.0) -> dict[int, Agreed]:
    """Every client sends its INPUTS for frame (with its wait mask), then collects its AGREED:
    what the io partitions of lockstep nodes do at a frame start."""
    for node, c in clients.items():
        c.send_inputs(frame, frame * 50_000_000, inputs_for(node, frame, masks[node]))
    return {node: c.await_agreed(frame, timeout) for node, c in clients.items()}
