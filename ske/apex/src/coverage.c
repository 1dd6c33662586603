/* SPDX-License-Identifier: Apache-2.0 */
/* Coverage builds only (IMA_COVERAGE): a partition's gcov counters. A partition ends by the
 * SKE's SIGKILL, which would lose them; the SKE first sends SKE_COVERAGE_SIGNAL, on which the
 * partition writes them and exits. Not compiled into normal builds. */
#include "apex__rt.h"

#include <signal.h>
#include <sys/resource.h>
#include <unistd.h>

#ifndef IMA_COVERAGE
#error "coverage.c belongs to coverage builds (cmake -DIMA_COVERAGE=ON) only"
#endif

void __gcov_dump(void); /* libgcov: writes every counter of the program to its .gcda file */

static void on_dump(int sig)
{
    (void)sig;
    /* A partition whose output file has a size limit (the disk_full fault) would cut its
     * .gcda files short at that limit, spoiling them for every later run: lift it first (the
     * hard limit is unlimited). */
    struct rlimit fsize;
    if (getrlimit(RLIMIT_FSIZE, &fsize) == 0 && fsize.rlim_cur != fsize.rlim_max) {
        fsize.rlim_cur = fsize.rlim_max;
        setrlimit(RLIMIT_FSIZE, &fsize);
    }
    /* Not async-signal-safe (libgcov uses stdio and malloc): a partition interrupted inside
     * malloc may hang here, and the SKE kills it after a short wait, its counters lost. The
     * partitions the SKE stops wait for their grant in a futex, where this is safe. */
    __gcov_dump();
    _exit(0);
}

void apex__coverage_init(void)
{
    /* On the fault stack: a partition that overflowed its stack still writes its counters. */
    struct sigaction sa = {.sa_handler = on_dump, .sa_flags = SA_ONSTACK};
    sigfillset(&sa.sa_mask);
    sigaction(SKE_COVERAGE_SIGNAL, &sa, NULL);
}
