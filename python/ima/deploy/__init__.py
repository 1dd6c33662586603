# SPDX-License-Identifier: Apache-2.0
"""`ima deploy`: the system model (config/systems/*.yaml) to one ARINC 653 module per node,
the partitions' C glue and a deployment summary (docs/deployment.md)."""

from ima.deploy.generate import DeployResult, generate
from ima.deploy.load import load_system
from ima.deploy.model import Node, System, SystemModelError

__all__ = ["DeployResult", "Node", "System", "SystemModelError", "generate", "load_system"]
