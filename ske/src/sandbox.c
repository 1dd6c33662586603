/* SPDX-License-Identifier: Apache-2.0 */
/* Spatial partitioning of a partition's process (ARINC 653 Part 1, spatial partitioning):
 * its memory limit and stack, the system-call filter it is started under, and the check
 * that it confined itself further before it gets the CPU. */
#include "ske__sandbox.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <unistd.h>

#include "ske_sandbox.h"

uint32_t ske__sandbox_flags(const ske_partition_cfg_t *cfg)
{
    return cfg->system_partition ? SKE_SANDBOX_IO : 0;
}

/* Sets a limit's soft and hard values; the hard one is lowered too, so that nothing in the
 * partition could raise the soft one back. */
static int limit(int resource, rlim_t value)
{
    struct rlimit r = {value, value};
    return setrlimit(resource, &r) == 0 ? 0 : -errno;
}

int ske__sandbox_enter(const ske_partition_cfg_t *cfg, int ctl_fd, int n_ports, int output_fd)
{
    /* Partition_Memory bounds the partition's data: heap, process stacks, static data of the
     * program and its libraries (RLIMIT_DATA counts private writable mappings and the heap).
     * Past it, an allocation fails with ENOMEM, which the partition sees (malloc returns NULL,
     * CREATE_PROCESS returns INVALID_CONFIG), instead of a later kill at a page fault. */
    int rc = 0;
    if (cfg->memory_bytes > 0)
        rc = limit(RLIMIT_DATA, (rlim_t)cfg->memory_bytes);
    /* The initialisation process runs on the main thread's stack, which grows on demand up
     * to RLIMIT_STACK with the kernel's guard gap below it: a fixed size, so that an overflow
     * faults at the same depth on every host (less only if ima-ske may not raise its own). */
    struct rlimit stack;
    if (rc == 0 && getrlimit(RLIMIT_STACK, &stack) == 0) {
        rlim_t size = SKE_SANDBOX_STACK_BYTES;
        rc = limit(RLIMIT_STACK, stack.rlim_max < size ? stack.rlim_max : size);
    }
    ske_sandbox_prog_t prog;
    ske_sandbox_policy_t pol = {
        .flags = ske__sandbox_flags(cfg),
        .self = (int32_t)getpid(),
        .shared_fd_lo = ctl_fd,
        .shared_fd_hi = ctl_fd + 1 + n_ports,
        .output_fd = output_fd,
    };
    if (rc == 0)
        rc = ske_sandbox_build(&pol, SKE_SANDBOX_LOAD, &prog);
    if (rc == 0)
        rc = ske_sandbox_install(&prog);
    return rc;
}

/* The value of "Key:" in a /proc status text, or -1. */
static long status_field(const char *text, const char *key)
{
    size_t klen = strlen(key);
    for (const char *l = text; *l;) {
        if (strncmp(l, key, klen) == 0 && l[klen] == ':') {
            char *end;
            long v = strtol(l + klen + 1, &end, 10);
            return end == l + klen + 1 ? -1 : v;
        }
        const char *nl = strchr(l, '\n');
        if (!nl)
            break;
        l = nl + 1;
    }
    return -1;
}

static bool read_status(const char *path, char *buf, size_t size)
{
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    if (fd < 0)
        return false;
    size_t n = 0;
    ssize_t r;
    while (n + 1 < size && (r = read(fd, buf + n, size - 1 - n)) > 0)
        n += (size_t)r;
    close(fd);
    buf[n] = '\0';
    return n > 0;
}

int ske__sandbox_verify(pid_t pid, const ske_partition_cfg_t *cfg, char *err, size_t errlen)
{
    char path[64], text[4096];
    snprintf(path, sizeof path, "/proc/%d/status", (int)pid);
    if (!read_status(path, text, sizeof text)) {
        snprintf(err, errlen, "partition '%s': cannot read %s to check its confinement: %s",
                 cfg->name, path, strerror(errno));
        return SKE_E_PARTITION;
    }
    long mode = status_field(text, "Seccomp");
    long filters = status_field(text, "Seccomp_filters");
    long nnp = status_field(text, "NoNewPrivs");
    /* The partition inherits any filter ima-ske itself runs under (a container's), then gets
     * the LOAD filter, then must have installed its own. Kernels before 5.9 do not count
     * filters: there only the mode can be checked. */
    long inherited = 0;
    char self[4096];
    if (read_status("/proc/self/status", self, sizeof self)) {
        long f = status_field(self, "Seccomp_filters");
        inherited = f > 0 ? f : 0;
    }
    bool counted = filters >= 0;
    if (mode == 2 && nnp == 1 && (!counted || filters >= inherited + 2))
        return SKE_OK;
    snprintf(err, errlen,
             "partition '%s' (%s) is not confined: it attached without installing its own "
             "system-call filter (seccomp mode %ld, %ld of the 2 filters, no_new_privs %ld); is "
             "it linked with this APEX library?",
             cfg->name, cfg->executable, mode, counted ? filters - inherited : -1L, nnp);
    return SKE_E_PARTITION;
}
