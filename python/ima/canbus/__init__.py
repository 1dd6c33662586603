# SPDX-License-Identifier: Apache-2.0
"""The virtual CAN bus from Python: wire protocol, client, DBC codecs, python-can interface."""
