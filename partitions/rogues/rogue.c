/* SPDX-License-Identifier: Apache-2.0 */
/* A rogue partition for the isolation example: behaves for a while, then does the one bad
 * thing its arguments name, at its AT-th release:
 *   rogue FAULT AT [handler]
 * FAULT: segv (write outside its memory), write_port (write to a port it only reads),
 *   divide (divide by zero), stack (overflow its stack), spin (keep the CPU past its window),
 *   alloc (allocate past its memory limit), socket, fork, kill (another partition's process),
 *   flood (a queuing port), apex (invalid parameters to APEX services), app_error
 *   (RAISE_APPLICATION_ERROR), deadline (miss its deadline), none (behave).
 * "handler" creates an error handler that logs each error and restarts the failed process.
 * The misbehaviours themselves are faultinject's (fi/partition.h), the ones the fault
 * injector makes a partition commit. */
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ARINC653.h"
#include "fi/partition.h"

static const char *fault = "none";
static unsigned at = 5;
static SAMPLING_PORT_ID_TYPE in_port;
static QUEUING_PORT_ID_TYPE flood_port;
static volatile uintptr_t outside = 0x10; /* an address the partition does not own */

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

static bool send_flood(void *ctx)
{
    static const APEX_BYTE msg[16] = {0};
    RETURN_CODE_TYPE rc;
    (void)ctx;
    SEND_QUEUING_MESSAGE(flood_port, (MESSAGE_ADDR_TYPE)msg, sizeof msg, 0, &rc);
    return rc == NO_ERROR;
}

static void misbehave(void)
{
    RETURN_CODE_TYPE rc;
    report("%s: misbehaving now", fault);
    if (strcmp(fault, "segv") == 0) {
        fi_memory_violation();
    } else if (strcmp(fault, "write_port") == 0) {
        /* The destination port's memory is mapped read-only: find it and write to it. */
        void *port = fi_readonly_port_mapping();
        if (port)
            fi_write_byte(port);
        report("write_port: no read-only port found");
    } else if (strcmp(fault, "divide") == 0) {
        fi_numeric_error();
    } else if (strcmp(fault, "stack") == 0) {
        fi_stack_overflow();
    } else if (strcmp(fault, "spin") == 0) {
        fi_spin_forever();
    } else if (strcmp(fault, "alloc") == 0) {
        size_t mib = fi_exhaust_memory(0);
        report("alloc: malloc returned NULL after %zu MiB", mib);
        RAISE_APPLICATION_ERROR(APPLICATION_ERROR, (MESSAGE_ADDR_TYPE) "out of memory", 13, &rc);
    } else if (strcmp(fault, "socket") == 0) {
        long s = fi_illegal_request(false); /* socket() */
        report("socket: got %ld", s);
    } else if (strcmp(fault, "fork") == 0) {
        report("fork: got %ld", fi_fork());
    } else if (strcmp(fault, "kill") == 0) {
        long r = fi_kill_parent(); /* the SKE, or any process: not for a partition */
        report("kill: got %ld", r);
    } else if (strcmp(fault, "flood") == 0) {
        fi_flood_result_t r = fi_flood(send_flood, NULL, 100, false);
        report("flood: sent %d, refused %d", r.sent, r.refused);
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
