/* SPDX-License-Identifier: Apache-2.0 */
/* The partition's own system-call filter, installed before its first grant. Private to the
 * APEX library. */
#ifndef APEX__SANDBOX_H
#define APEX__SANDBOX_H

#include "ske_abi.h"

/* Narrows the partition's system calls to its policy (ske_sandbox.h, RUN stage) after
 * everything that sets the partition up (ports mapped and their descriptors closed, fault
 * handlers installed) and before it reports ready: from then on a call outside the policy
 * raises SIGSYS. Returns 0 or -errno. */
int apex__sandbox_install(const ske_ctl_t *ctl);

#endif /* APEX__SANDBOX_H */
