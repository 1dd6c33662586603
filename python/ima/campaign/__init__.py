# SPDX-License-Identifier: Apache-2.0
"""Fault campaigns: a campaign file expanded into runs, the runs flown in parallel (on this
machine or a Dask cluster) and judged against golden runs, and the report."""
