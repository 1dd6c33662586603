/* SPDX-License-Identifier: Apache-2.0 */
/* A rogue partition for the isolation example: behaves for a while, then does the one bad
 * thing its arguments name, at its AT-th release:
 *   rogue FAULT AT [handler]
 * FAULT: segv (write outside its memory), write_port (write to a port it only reads),
 *   divide (divide by zero), stack (overflow its stack), spin (keep the CPU past its window),
 *   alloc (allocate past its memory limit), socket, fork, kill (another partition's process),
 *   flood (a queuing port), apex (invalid parameters to APEX services), app_error
 *   (RAISE_APPLICATION_ERROR), deadline (miss its deadline), none (behave).
 * "handler" creates an error handler that logs each error and restarts the failed process. */
#include <signal.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include "ARINC653.h"

static const char *fault = "none";
static unsigned at = 5;
static SAMPLING_PORT_ID_TYPE in_port;
static QUEUING_PORT_ID_TYPE flood_port;
static volatile int sink;
static void *volatile kept;
static volatile uintptr_t outside = 0x10; /* an address the partition does not own */
static volatile int depth_limit = 1 << 30; /* deeper than any stack */

static void report(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
#include <stdarg.h>
static void report(const char *fmt, ...)
{
    char buf[MAX_ERROR_MESSAGE_SIZE];
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    RETURN_CODE_TYPE rc;
    REPORT_APPLICATION_MESSAGE((MESSAGE_ADDR_TYPE)buf, n < (int)sizeof buf ? n : (int)sizeof buf - 1, &rc);
}

static int recurse(int depth)
{
    volatile char pad[1024];
    pad[0] = (char)depth;
    if (depth >= depth_limit)
        return pad[0];
    return recurse(depth + 1) + pad[0];
}

static void misbehave(void)
{
    RETURN_CODE_TYPE rc;
    report("%s: misbehaving now", fault);
    if (strcmp(fault, "segv") == 0) {
        *(volatile int *)outside = 1;
    } else if (strcmp(fault, "write_port") == 0) {
        /* The destination port's memory is mapped read-only: find it and write to it. */
        FILE *f = fopen("/proc/self/maps", "r");
        char line[512];
        while (f && fgets(line, sizeof line, f)) {
            unsigned long lo;
            char perms[5];
            if (strstr(line, "memfd:ima-") && sscanf(line, "%lx-%*x %4s", &lo, perms) == 2 &&
                perms[1] == '-') {
                *(volatile char *)lo = 1;
            }
        }
        report("write_port: no read-only port found");
    } else if (strcmp(fault, "divide") == 0) {
        volatile int zero = 0, numerator = 1; /* volatile both: "1 / x" compiles to no division */
        sink = numerator / zero;
    } else if (strcmp(fault, "stack") == 0) {
        sink = recurse(0);
    } else if (strcmp(fault, "spin") == 0) {
        for (;;)
            sink++;
    } else if (strcmp(fault, "alloc") == 0) {
        /* Untouched: the limit counts what is allocated, and filling it would take longer
         * than the window on a slow host. */
        size_t total = 0;
        for (;;) {
            char *p = malloc(1 << 20);
            if (!p) {
                report("alloc: malloc returned NULL after %zu MiB", total >> 20);
                RAISE_APPLICATION_ERROR(APPLICATION_ERROR, (MESSAGE_ADDR_TYPE) "out of memory", 13, &rc);
                return;
            }
            kept = p; /* so that the allocation is not optimised away */
            total += 1 << 20;
        }
    } else if (strcmp(fault, "socket") == 0) {
        int s = socket(AF_INET, SOCK_DGRAM, 0);
        report("socket: got %d", s);
    } else if (strcmp(fault, "fork") == 0) {
        pid_t p = fork();
        if (p == 0)
            _exit(0);
        report("fork: got %d", (int)p);
    } else if (strcmp(fault, "kill") == 0) {
        int r = kill(getppid(), SIGKILL); /* the SKE, or any process: not for a partition */
        report("kill: got %d", r);
    } else if (strcmp(fault, "flood") == 0) {
        APEX_BYTE msg[16] = {0};
        int sent = 0, refused = 0;
        for (int i = 0; i < 100; i++) {
            SEND_QUEUING_MESSAGE(flood_port, msg, sizeof msg, 0, &rc);
            if (rc == NO_ERROR)
                sent++;
            else
                refused++;
        }
        report("flood: sent %d, refused %d", sent, refused);
    } else if (strcmp(fault, "apex") == 0) {
        /* Invalid parameters get return codes; an invalid address is an illegal request. */
        WRITE_SAMPLING_MESSAGE(999, (MESSAGE_ADDR_TYPE) "x", 1, &rc);
        report("apex: WRITE_SAMPLING_MESSAGE(999) -> %d", (int)rc);
        SEND_QUEUING_MESSAGE(flood_port, (MESSAGE_ADDR_TYPE)outside, 8, 0, &rc);
        report("apex: SEND_QUEUING_MESSAGE(bad address) -> %d", (int)rc);
    } else if (strcmp(fault, "app_error") == 0) {
        RAISE_APPLICATION_ERROR(APPLICATION_ERROR, (MESSAGE_ADDR_TYPE) "sensor out of range", 19, &rc);
        report("app_error: RAISE_APPLICATION_ERROR -> %d", (int)rc);
    } else if (strcmp(fault, "deadline") == 0) {
        TIMED_WAIT(200000000, &rc); /* past its deadline, which is its period */
        report("deadline: woke up late");
    }
}

static void run(void)
{
    RETURN_CODE_TYPE rc;
    for (unsigned n = 1;; n++) {
        /* A flood goes on every release: the destination nobody reads fills, then overflows. */
        if (n == at || (n > at && strcmp(fault, "flood") == 0))
            misbehave();
        PERIODIC_WAIT(&rc);
    }
}

static void on_error(void)
{
    for (;;) {
        ERROR_STATUS_TYPE st;
        RETURN_CODE_TYPE rc;
        GET_ERROR_STATUS(&st, &rc);
        if (rc != NO_ERROR)
            break;
        report("handler: error %d in process %d: %.*s", (int)st.ERROR_CODE, (int)st.FAILED_PROCESS_ID,
               (int)st.LENGTH, (const char *)st.MESSAGE);
        PROCESS_STATUS_TYPE ps;
        GET_PROCESS_STATUS(st.FAILED_PROCESS_ID, &ps, &rc);
        if (rc == NO_ERROR && ps.PROCESS_STATE == DORMANT)
            START(st.FAILED_PROCESS_ID, &rc); /* the faulted process starts again */
    }
    STOP_SELF();
}

int main(int argc, char **argv)
{
    RETURN_CODE_TYPE rc;
    if (argc > 1)
        fault = argv[1];
    if (argc > 2)
        at = (unsigned)strtoul(argv[2], NULL, 10);
    bool handler = argc > 3 && strcmp(argv[3], "handler") == 0;
    PARTITION_STATUS_TYPE ps;
    GET_PARTITION_STATUS(&ps, &rc);
    report("start: %s at release %u%s, start condition %d", fault, at, handler ? ", with error handler" : "",
           (int)ps.START_CONDITION);
    CREATE_SAMPLING_PORT("ROGUE_IN", 64, DESTINATION, 100000000, &in_port, &rc);
    CREATE_QUEUING_PORT("ROGUE_OUT", 16, 4, SOURCE, FIFO, &flood_port, &rc);
    QUEUING_PORT_ID_TYPE never_read; /* a destination nobody reads: the flood overflows it */
    CREATE_QUEUING_PORT("ROGUE_Q_IN", 16, 4, DESTINATION, FIFO, &never_read, &rc);
    if (handler)
        CREATE_ERROR_HANDLER((SYSTEM_ADDRESS_TYPE)on_error, 65536, &rc);
    PROCESS_ATTRIBUTE_TYPE a = {
        .PERIOD = ps.PERIOD, .TIME_CAPACITY = ps.PERIOD, .ENTRY_POINT = (SYSTEM_ADDRESS_TYPE)run,
        .STACK_SIZE = 65536, .BASE_PRIORITY = 10, .DEADLINE = HARD, .NAME = "rogue"};
    PROCESS_ID_TYPE pid;
    CREATE_PROCESS(&a, &pid, &rc);
    START(pid, &rc);
    SET_PARTITION_MODE(NORMAL, &rc);
    return 1;
}
