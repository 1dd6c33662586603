/* SPDX-License-Identifier: Apache-2.0 */
/* The system-call policy of a partition, as seccomp filters: one source for ima-ske, which
 * confines the program from its exec on, and for the APEX library, which narrows the policy
 * to what a running partition may do before its first grant. */
#ifndef SKE_SANDBOX_H
#define SKE_SANDBOX_H

#include <linux/filter.h>
#include <stdint.h>

#include "ske_abi.h"

/* Two filters, both kept until the process ends (the kernel applies every filter a process
 * installed, the strictest answer wins):
 *   LOAD  installed by ima-ske right before exec: what the program loader and the C library's
 *         start-up need on top of RUN (read-only opens, exec, the APEX installing RUN), and
 *         nothing that reaches another process (fork, threads, signals, tracing, limits,
 *         System V IPC, sockets and file writes outside system partitions);
 *   RUN   installed by the APEX library before the first grant: the partition's policy. */
typedef enum {
    SKE_SANDBOX_LOAD = 0,
    SKE_SANDBOX_RUN = 1,
} ske_sandbox_stage_t;

/* What a denied call raises: SIGSYS with si_code SYS_SECCOMP, si_syscall the call's number,
 * si_arch its ABI, and si_errno one of these reasons. The call is not made, whatever the
 * partition does with SIGSYS (a handler that returns resumes after the call with its return
 * register unchanged; an ignored or blocked SIGSYS kills the process). */
enum {
    SKE_SANDBOX_DENIED_CALL = 1, /* the call is not in the partition's policy */
    SKE_SANDBOX_DENIED_ARGS = 2, /* the call is, but not with these arguments */
    SKE_SANDBOX_DENIED_ABI = 3, /* another system-call ABI (i386 int 0x80, x32) */
};

typedef struct {
    uint32_t flags; /* SKE_SANDBOX_* of the control block */
    int32_t self; /* the partition's process id: the only target of its signals */
    /* The only descriptors it may map shared: [shared_fd_lo, shared_fd_hi), its control
     * block and ports while the APEX library maps them; none once it runs (the APEX has
     * closed them: a file a system partition opens is I/O, never shared memory). */
    int32_t shared_fd_lo;
    int32_t shared_fd_hi;
    /* Its output file (ima:Linux OutputFile), which the SKE opened for it: besides standard
     * output and error, the one descriptor it may write and sync. Below 3: none. */
    int32_t output_fd;
} ske_sandbox_policy_t;

#define SKE_SANDBOX_PROG_MAX 1024

typedef struct {
    struct sock_filter ins[SKE_SANDBOX_PROG_MAX];
    unsigned short len;
} ske_sandbox_prog_t;

/* Builds the filter of one stage. Returns 0, -ENOSYS on an architecture the policy does not
 * know, -E2BIG if the program does not fit. Allocates nothing (usable between fork and exec). */
int ske_sandbox_build(const ske_sandbox_policy_t *policy, ske_sandbox_stage_t stage,
                      ske_sandbox_prog_t *prog);

/* Sets no-new-privileges and installs the filter on the calling process: 0 or -errno. */
int ske_sandbox_install(const ske_sandbox_prog_t *prog);

#endif /* SKE_SANDBOX_H */
