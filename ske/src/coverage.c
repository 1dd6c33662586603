/* SPDX-License-Identifier: Apache-2.0 */
/* Coverage builds only (IMA_COVERAGE): before a partition's process is killed, it is asked to
 * write its gcov counters (ske/apex/src/coverage.c), which a SIGKILL alone would lose. Not
 * compiled into normal builds, where killing a partition stays one SIGKILL. */
#include "ske__coverage.h"

#include <signal.h>
#include <stdbool.h>
#include <sys/wait.h>
#include <time.h>

#include "ske_abi.h"

#ifndef IMA_COVERAGE
#error "coverage.c belongs to coverage builds (cmake -DIMA_COVERAGE=ON) only"
#endif

void __gcov_dump(void); /* libgcov: writes the counters to the .gcda files, once */
void __gcov_reset(void); /* libgcov: zeroes them, and allows another dump */

/* Writing a few dozen .gcda files takes milliseconds; a process still at it after this is
 * stuck (interrupted inside malloc, or not attached yet) and is killed without them. */
#define DUMP_WAIT_NS 2000000000LL

/* True once the process has ended, without reaping it: the caller's waitpid does. */
static bool ended(pid_t pid)
{
    siginfo_t si = {0};
    return waitid(P_PID, (id_t)pid, &si, WEXITED | WNOHANG | WNOWAIT) != 0 || si.si_pid == pid;
}

void ske__coverage_dump(pid_t pid)
{
    if (kill(pid, SKE_COVERAGE_SIGNAL) != 0)
        return;
    kill(pid, SIGCONT); /* a partition stopped between its windows takes the signal now */
    int64_t t0 = ske_mono_ns();
    while (!ended(pid) && ske_mono_ns() - t0 < DUMP_WAIT_NS) {
        struct timespec ts = {0, 1000000};
        nanosleep(&ts, NULL);
    }
}

void ske__coverage_child_start(void) { __gcov_reset(); }

void ske__coverage_child_flush(void)
{
    /* Under the loader's filter, which lets libgcov write (ske/abi/src/sandbox_policy.c). */
    __gcov_dump();
    __gcov_reset();
}
