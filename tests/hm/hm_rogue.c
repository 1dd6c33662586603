/* SPDX-License-Identifier: Apache-2.0 */
/* Test partition of the health-monitoring tests: the faults of partitions/rogues/rogue.c (same
 * arguments, same way of causing each fault), plus what the tests need to see their effect:
 *
 *   hm_rogue FAULT AT [handler]
 *
 * FAULT: none, segv (write outside its memory), write_port (write to the read-only mapping of
 *   a destination port, found in /proc/self/maps: only a system partition may open it),
 *   divide (integer division by zero), stack (overflow its stack), spin (keep the CPU),
 *   app_error (RAISE_APPLICATION_ERROR), deadline (miss its deadline), apex (an invalid
 *   address given to an APEX service), exit (exit(7): the partition's process ends), exit0
 *   (exit(0): it ends with status 0).
 * AT: the release of process "rogue" at which it misbehaves (1 = its first); 0 = during the
 *   partition's initialisation, before NORMAL mode.
 * "handler": an error handler reports each error (GET_ERROR_STATUS) and STARTs the failed
 *   process again if it is DORMANT. "faulty_handler": the same handler, which then writes
 *   outside the partition's memory itself (a fault in state ERROR_HANDLER).
 *
 * Reports (REPORT_APPLICATION_MESSAGE), one per line of the trace:
 *   "start condition=C mode=M"     at initialisation (GET_PARTITION_STATUS)
 *   "tick N"                       process "rogue", each release
 *   "misbehave FAULT"              just before the fault
 *   "write_port ADDRESS NAME"      the address written to and its mapping (memfd:ima-...)
 *   "after FAULT rc=R"             if the faulting call returns (application error, deadline)
 *   "beat N rogue=STATE"           process "beat" (lower priority), each release, with the
 *                                  state of process "rogue" (GET_PROCESS_STATUS)
 *   "handler code=C failed=F state=S: MESSAGE"   the error handler, per error
 *   "handler START(F) rc=R"        when it starts the failed process again */
#include <stdarg.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ARINC653.h"

static const char *fault = "none";
static unsigned at = 3;
static SYSTEM_TIME_TYPE period;
static PROCESS_ID_TYPE rogue_id;
static QUEUING_PORT_ID_TYPE out_port;
static uintptr_t read_only_port; /* the mapping of the destination port, found at start */
static char read_only_name[96];
static volatile int sink;
static volatile uintptr_t outside = 0x10; /* an address the partition does not own */
static volatile int depth_limit = 1 << 30; /* deeper than any stack */
static bool handler_faults;

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
    RETURN_CODE_TYPE rc;
    if (n >= (int)sizeof buf)
        n = (int)sizeof buf - 1;
    REPORT_APPLICATION_MESSAGE((MESSAGE_ADDR_TYPE)buf, n, &rc);
}

static const char *state_name(PROCESS_STATE_TYPE s)
{
    static const char *const names[] = {"DORMANT", "READY", "RUNNING", "WAITING", "FAULTED"};
    return (unsigned)s < 5 ? names[s] : "?";
}

static const char *mode_name(OPERATING_MODE_TYPE m)
{
    static const char *const names[] = {"IDLE", "COLD_START", "WARM_START", "NORMAL"};
    return (unsigned)m < 4 ? names[m] : "?";
}

static int recurse(int depth)
{
    volatile char pad[1024];
    pad[0] = (char)depth;
    if (depth >= depth_limit)
        return pad[0];
    return recurse(depth + 1) + pad[0];
}

/* The SKE maps a destination port's memory from a read-only descriptor (a "memfd:ima-..."
 * object); found the way rogue.c finds it. */
static uintptr_t find_read_only_port(void)
{
    FILE *f = fopen("/proc/self/maps", "r");
    if (!f)
        return 0;
    char line[512];
    uintptr_t found = 0;
    while (!found && fgets(line, sizeof line, f)) {
        unsigned long lo;
        char perms[5];
        const char *name = strstr(line, "memfd:ima-");
        if (name && sscanf(line, "%lx-%*x %4s", &lo, perms) == 2 && perms[1] == '-') {
            found = lo;
            int len = (int)strcspn(name, " \n");
            snprintf(read_only_name, sizeof read_only_name, "%.*s", len, name);
        }
    }
    fclose(f);
    return found;
}

static void misbehave(void)
{
    RETURN_CODE_TYPE rc = NO_ERROR;
    report("misbehave %s", fault);
    if (strcmp(fault, "segv") == 0) {
        *(volatile int *)outside = 1;
    } else if (strcmp(fault, "write_port") == 0) {
        if (!read_only_port) {
            report("write_port: no read-only port mapping found");
            return;
        }
        report("write_port %p %s", (void *)read_only_port, read_only_name);
        *(volatile char *)read_only_port = 1;
    } else if (strcmp(fault, "divide") == 0) {
        volatile int zero = 0, numerator = 1;
        sink = numerator / zero;
    } else if (strcmp(fault, "stack") == 0) {
        sink = recurse(0);
    } else if (strcmp(fault, "spin") == 0) {
        for (;;)
            sink++;
    } else if (strcmp(fault, "app_error") == 0) {
        static const char msg[] = "sensor out of range";
        RAISE_APPLICATION_ERROR(APPLICATION_ERROR, (MESSAGE_ADDR_TYPE)msg, sizeof msg - 1, &rc);
    } else if (strcmp(fault, "deadline") == 0) {
        TIMED_WAIT(3 * period, &rc); /* past the deadline, one period after the release */
    } else if (strcmp(fault, "apex") == 0) {
        SEND_QUEUING_MESSAGE(out_port, (MESSAGE_ADDR_TYPE)outside, 8, 0, &rc);
    } else if (strcmp(fault, "exit") == 0) {
        exit(7);
    } else if (strcmp(fault, "exit0") == 0) {
        exit(0);
    }
    report("after %s rc=%d", fault, (int)rc);
}

static void rogue_process(void)
{
    RETURN_CODE_TYPE rc;
    for (unsigned n = 1;; n++) {
        report("tick %u", n);
        if (n == at)
            misbehave();
        PERIODIC_WAIT(&rc);
    }
}

static void beat_process(void)
{
    RETURN_CODE_TYPE rc;
    for (unsigned n = 1;; n++) {
        PROCESS_STATUS_TYPE st;
        GET_PROCESS_STATUS(rogue_id, &st, &rc);
        report("beat %u rogue=%s", n, rc == NO_ERROR ? state_name(st.PROCESS_STATE) : "?");
        PERIODIC_WAIT(&rc);
    }
}

static void on_error(void)
{
    for (;;) {
        ERROR_STATUS_TYPE e;
        RETURN_CODE_TYPE rc;
        GET_ERROR_STATUS(&e, &rc);
        if (rc != NO_ERROR)
            break;
        PROCESS_STATUS_TYPE ps;
        GET_PROCESS_STATUS(e.FAILED_PROCESS_ID, &ps, &rc);
        bool dormant = rc == NO_ERROR && ps.PROCESS_STATE == DORMANT;
        report("handler code=%d failed=%d state=%s: %.*s", (int)e.ERROR_CODE,
               (int)e.FAILED_PROCESS_ID, rc == NO_ERROR ? state_name(ps.PROCESS_STATE) : "?",
               (int)(e.LENGTH < 60 ? e.LENGTH : 60), (const char *)e.MESSAGE);
        if (dormant) {
            START(e.FAILED_PROCESS_ID, &rc);
            report("handler START(%d) rc=%d", (int)e.FAILED_PROCESS_ID, (int)rc);
        }
        if (handler_faults) {
            report("handler misbehaves");
            *(volatile int *)outside = 1;
        }
    }
    STOP_SELF();
}

static PROCESS_ID_TYPE new_process(const char *name, void (*entry)(void), PRIORITY_TYPE prio)
{
    PROCESS_ATTRIBUTE_TYPE a = {.PERIOD = period, .TIME_CAPACITY = period,
                                .ENTRY_POINT = (SYSTEM_ADDRESS_TYPE)entry, .STACK_SIZE = 65536,
                                .BASE_PRIORITY = prio, .DEADLINE = HARD};
    snprintf(a.NAME, sizeof a.NAME, "%s", name);
    PROCESS_ID_TYPE id = 0;
    RETURN_CODE_TYPE rc;
    CREATE_PROCESS(&a, &id, &rc);
    if (rc != NO_ERROR)
        report("setup: CREATE_PROCESS %s rc=%d", name, (int)rc);
    START(id, &rc);
    if (rc != NO_ERROR)
        report("setup: START %s rc=%d", name, (int)rc);
    return id;
}

int main(int argc, char **argv)
{
    RETURN_CODE_TYPE rc;
    if (argc > 1)
        fault = argv[1];
    if (argc > 2)
        at = (unsigned)strtoul(argv[2], NULL, 10);
    handler_faults = argc > 3 && strcmp(argv[3], "faulty_handler") == 0;
    bool handler = handler_faults || (argc > 3 && strcmp(argv[3], "handler") == 0);
    PARTITION_STATUS_TYPE ps;
    GET_PARTITION_STATUS(&ps, &rc);
    period = ps.PERIOD;
    report("start condition=%d mode=%s", (int)ps.START_CONDITION, mode_name(ps.OPERATING_MODE));
    SAMPLING_PORT_ID_TYPE in_port;
    CREATE_SAMPLING_PORT("ROGUE_IN", 64, DESTINATION, 100000000, &in_port, &rc);
    CREATE_QUEUING_PORT("ROGUE_OUT", 16, 4, SOURCE, FIFO, &out_port, &rc);
    if (strcmp(fault, "write_port") == 0)
        read_only_port = find_read_only_port();
    if (handler) {
        CREATE_ERROR_HANDLER((SYSTEM_ADDRESS_TYPE)on_error, 65536, &rc);
        if (rc != NO_ERROR)
            report("setup: CREATE_ERROR_HANDLER rc=%d", (int)rc);
    }
    rogue_id = new_process("rogue", rogue_process, 10);
    new_process("beat", beat_process, 5);
    if (at == 0)
        misbehave();
    SET_PARTITION_MODE(NORMAL, &rc);
    return 1;
}
