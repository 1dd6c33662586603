# SPDX-License-Identifier: Apache-2.0
"""Mission plans (config/missions/*.yaml): `plan` loads and checks one, `image` compiles it into
the binary image the mission manager flies (partitions/include/rpas/mission_plan.h),
`geometry` gives its planned path in the local frame, `plot` draws it (docs/mission.md)."""
