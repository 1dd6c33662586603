/* SPDX-License-Identifier: Apache-2.0 */
/* Not a partition: a program that attaches to ima-ske the way the APEX library does but
 * skips the APEX's own system-call filter. ima-ske must refuse it before its first grant;
 * were it ever granted the CPU, it would print "GRANTED" on its standard output. */
#include <stdio.h>
#include <stdlib.h>
#include <sys/mman.h>
#include <unistd.h>

#include "ske_abi.h"

int main(void)
{
    const char *s = getenv(SKE_ENV_CTL_FD);
    if (!s)
        return 2;
    int fd = atoi(s);
    ske_ctl_t *c = mmap(NULL, sizeof *c, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
    if (c == MAP_FAILED)
        return 3;
    close(fd);
    atomic_store(&c->ready, 1);
    ske_futex_wake(&c->ready);
    for (int i = 0; i < 500 && atomic_load(&c->grant_seq) == 0; i++) {
        struct timespec ts = {0, 10000000};
        ske_futex_wait(&c->grant_seq, 0, &ts);
    }
    if (atomic_load(&c->grant_seq) == 0)
        return 4; /* never granted, as it should be (ima-ske kills it before that anyway) */
    puts("GRANTED");
    fflush(stdout);
    return 0;
}
