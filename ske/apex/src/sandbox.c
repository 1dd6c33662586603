/* SPDX-License-Identifier: Apache-2.0 */
/* Spatial partitioning from inside the partition (ARINC 653 Part 1, spatial partitioning):
 * installs its system-call filter from the policy ima-ske wrote into the control block. */
#include "apex__sandbox.h"

#include <unistd.h>

#include "ske_sandbox.h"

int apex__sandbox_install(const ske_ctl_t *ctl)
{
    /* Its control block and ports are mapped and their descriptors closed by now: from here
     * on it may map no file shared. */
    ske_sandbox_policy_t pol = {.flags = ctl->sandbox_flags, .self = (int32_t)getpid(),
                                .output_fd = ctl->output_fd};
    ske_sandbox_prog_t prog;
    int rc = ske_sandbox_build(&pol, SKE_SANDBOX_RUN, &prog);
    if (rc == 0)
        rc = ske_sandbox_install(&prog);
    return rc;
}
