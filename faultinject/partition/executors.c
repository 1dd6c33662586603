/* SPDX-License-Identifier: Apache-2.0 */
/* The misbehaviours of fi/partition.h, each done for real in the calling process. */
#include "fi/partition.h"

#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

/* volatile: the compiler must neither fold the bad operation nor prove it undefined and
 * drop it; each is done as written, at run time. */
static volatile uintptr_t outside_address = 0x10; /* an address no partition owns */
static volatile int zero_divisor = 0;
static volatile int numerator = 1;
static volatile int depth_limit = 1 << 30; /* deeper than any stack */
static volatile int sink;
static void *volatile kept; /* the last block: so that the allocations are not optimised away */
static char *volatile null_block; /* what the refused malloc returned */

void fi_crash(void) { abort(); }

void fi_memory_violation(void) { *(volatile int *)outside_address = 1; }

void fi_write_byte(volatile void *addr)
{
    volatile char *p = addr;
    char v = *p; /* a readable mapping: the read succeeds, the write is what faults */
    *p = v;
}

void *fi_readonly_port_mapping(void)
{
    FILE *f = fopen("/proc/self/maps", "r");
    if (!f)
        return NULL;
    char line[512];
    void *found = NULL;
    while (!found && fgets(line, sizeof line, f)) {
        unsigned long lo;
        char perms[5];
        /* Port memory objects are named "ima-..." by the SKE; a destination's is mapped
         * without write permission. */
        if (strstr(line, "memfd:ima-") && sscanf(line, "%lx-%*x %4s", &lo, perms) == 2 &&
            perms[1] == '-')
            found = (void *)(uintptr_t)lo;
    }
    fclose(f);
    return found;
}

void fi_numeric_error(void) { sink = numerator / zero_divisor; }

static int recurse(int depth)
{
    volatile char pad[1024];
    pad[0] = (char)depth;
    if (depth >= depth_limit)
        return pad[0];
    return recurse(depth + 1) + pad[0]; /* not a tail call: each frame stays on the stack */
}

int fi_stack_overflow(void)
{
    sink = recurse(0);
    return sink;
}

void fi_spin_forever(void)
{
    for (;;)
        sink++;
}

static int64_t cpu_ns(void)
{
    struct timespec ts;
    if (clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts) != 0)
        return -1;
    return (int64_t)ts.tv_sec * 1000000000LL + ts.tv_nsec;
}

int64_t fi_spin_cpu(int64_t ns)
{
    int64_t t0 = cpu_ns();
    if (t0 < 0)
        return -1;
    int64_t used = 0;
    while (used < ns) {
        /* Reading the clock is a system call: a few thousand iterations between reads keep
         * the spin mostly computation, and the overshoot far below a microsecond. */
        for (int i = 0; i < 2000; i++)
            sink++;
        int64_t t = cpu_ns();
        if (t < 0)
            return -1;
        used = t - t0;
    }
    return used;
}

long fi_illegal_request(bool system_partition)
{
    if (system_partition)
        return kill(getppid(), 0);
    return socket(AF_INET, SOCK_DGRAM, 0);
}

long fi_fork(void)
{
    pid_t p = fork();
    if (p == 0)
        _exit(0);
    return p;
}

long fi_kill_parent(void) { return kill(getppid(), SIGKILL); }

size_t fi_exhaust_memory(size_t max_mib)
{
    /* Untouched: the limit counts what is allocated, and filling every block would take
     * longer than a window on a slow host. */
    size_t mib = 0;
    while (max_mib == 0 || mib < max_mib) {
        char *p = malloc(1u << 20);
        if (!p) {
            null_block = p;
            break;
        }
        kept = p;
        mib++;
    }
    return mib;
}

void fi_write_through_null(void)
{
    char *p = null_block; /* NULL: the allocation malloc refused */
    p[64] = 1;
}

void fi_corrupt_bytes(void *buf, size_t len)
{
    unsigned char *b = buf;
    for (size_t i = 0; i < len; i++)
        b[i] ^= 0x5Au;
}

fi_flood_result_t fi_flood(fi_send_fn send, void *ctx, int attempts, bool stop_when_full)
{
    fi_flood_result_t r = {0, 0};
    for (int i = 0; i < attempts; i++) {
        if (send(ctx)) {
            r.sent++;
        } else {
            r.refused++;
            if (stop_when_full)
                break;
        }
    }
    return r;
}
