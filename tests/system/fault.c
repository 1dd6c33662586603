/* SPDX-License-Identifier: Apache-2.0 */
/* Test partition for the fault system tests: one periodic process reports a tick each
 * period and, from the release the module's Arguments name, misbehaves.
 *
 *   Arguments="good"          never misbehaves (the fault-free twin of the others)
 *   Arguments="spin N"        from release N on, computes forever without an APEX call
 *   Arguments="segv N"        at release N, writes through a null pointer
 *   Arguments="exit N CODE"   at release N, calls exit(CODE)
 */
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ARINC653.h"

static const char *mode = "good";
static long fault_at = -1;
static int exit_code;

static void report(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
static void report(const char *fmt, ...)
{
    char buf[MAX_ERROR_MESSAGE_SIZE];
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    if (n < 0)
        return;
    if (n >= (int)sizeof buf)
        n = (int)sizeof buf - 1;
    RETURN_CODE_TYPE rc;
    REPORT_APPLICATION_MESSAGE((MESSAGE_ADDR_TYPE)buf, n, &rc);
}

static void misbehave(void)
{
    if (strcmp(mode, "spin") == 0) {
        /* volatile: the loop must really burn CPU and never be folded away. */
        volatile uint64_t x = 0;
        for (;;)
            x++;
    }
    if (strcmp(mode, "segv") == 0) {
        /* Volatile pointer to volatile: the compiler can neither see that it is null (and
         * emit a trap instruction, SIGILL) nor drop the store; the MMU must raise SIGSEGV. */
        volatile int *volatile p = NULL;
        *p = 1;
    }
    if (strcmp(mode, "exit") == 0)
        exit(exit_code);
}

static void work(void)
{
    for (long n = 0;; n++) {
        RETURN_CODE_TYPE rc;
        SYSTEM_TIME_TYPE now;
        GET_TIME(&now, &rc);
        if (n == fault_at) {
            report("fault %s at release %ld", mode, n);
            misbehave();
        }
        report("tick %ld t=%lld", n, (long long)now);
        PERIODIC_WAIT(&rc);
    }
}

int main(int argc, char **argv)
{
    if (argc >= 2)
        mode = argv[1];
    if (argc >= 3)
        fault_at = strtol(argv[2], NULL, 10);
    if (argc >= 4)
        exit_code = (int)strtol(argv[3], NULL, 10);
    RETURN_CODE_TYPE rc;
    PARTITION_STATUS_TYPE st;
    GET_PARTITION_STATUS(&st, &rc);
    PROCESS_ATTRIBUTE_TYPE a = {
        .PERIOD = st.PERIOD, .TIME_CAPACITY = st.PERIOD, .ENTRY_POINT = (SYSTEM_ADDRESS_TYPE)work,
        .STACK_SIZE = 65536, .BASE_PRIORITY = 10, .DEADLINE = SOFT, .NAME = "work"};
    PROCESS_ID_TYPE pid;
    CREATE_PROCESS(&a, &pid, &rc);
    if (rc == NO_ERROR)
        START(pid, &rc);
    if (rc != NO_ERROR) {
        fprintf(stderr, "sys_fault: cannot start its process: return code %d\n", (int)rc);
        return 1;
    }
    SET_PARTITION_MODE(NORMAL, &rc);
    return 1;
}
