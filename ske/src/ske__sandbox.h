/* SPDX-License-Identifier: Apache-2.0 */
/* How ima-ske confines a partition's process: resource limits and the loader's system-call
 * filter before exec, and the check that the partition added its own filter. */
#ifndef SKE__SANDBOX_H
#define SKE__SANDBOX_H

#include <stddef.h>
#include <stdint.h>
#include <sys/types.h>

#include "ske/config.h"

/* The main thread's stack (the initialisation process's), whatever ima-ske was given. */
#define SKE_SANDBOX_STACK_BYTES (8u << 20)

/* The sandbox flags for a partition's control block. */
uint32_t ske__sandbox_flags(const ske_partition_cfg_t *cfg);

/* In the partition's process, between fork and exec, once its descriptors are in place
 * (control block at ctl_fd, its n_ports ports right above): sets its resource limits (data
 * from Partition_Memory, stack), then installs the LOAD filter. Returns 0 or -errno;
 * allocates nothing. */
int ske__sandbox_enter(const ske_partition_cfg_t *cfg, int ctl_fd, int n_ports, int output_fd);

/* Once the partition has attached, before its first grant: SKE_OK if it runs under its own
 * filter on top of the LOAD filter, else SKE_E_PARTITION with a one-line message. */
int ske__sandbox_verify(pid_t pid, const ske_partition_cfg_t *cfg, char *err, size_t errlen);

#endif /* SKE__SANDBOX_H */
