/* SPDX-License-Identifier: Apache-2.0 */
/* Process scheduling inside a partition (ARINC 653 Part 1, 2.3.2): the highest-priority
 * ready process runs, first come first served within a priority; a process started in
 * NORMAL mode preempts a lower-priority caller at once, never one of equal priority. Each
 * process appends its name to a log; the last one to run reports it. */
#include "apex_check.h"

static char order[128];
static PROCESS_ID_TYPE urgent_id, peer_id;

static void log_name(const char *name)
{
    if (order[0])
        strncat(order, ",", sizeof order - strlen(order) - 1);
    strncat(order, name, sizeof order - strlen(order) - 1);
}

static void high(void) { log_name("high"); }
static void mid_a(void) { log_name("midA"); }
static void mid_b(void) { log_name("midB"); }
static void urgent(void) { log_name("urgent"); }
static void peer(void) { log_name("peer"); }

static void low(void)
{
    RETURN_CODE_TYPE rc;
    log_name("low");
    /* Started in the order low, midA, midB, high. */
    check_str("priority_then_fifo", "high,midA,midB,low", order);

    order[0] = '\0';
    START(urgent_id, &rc);
    log_name("low");
    check_str("start_preempts_lower", "urgent,low", order);

    order[0] = '\0';
    START(peer_id, &rc);
    log_name("low");
    TIMED_WAIT(1 * MS, &rc);
    check_str("start_keeps_equal", "low,peer", order);
}

int main(void)
{
    start_new_process("low", low, 5, INFINITE_TIME_VALUE);
    start_new_process("midA", mid_a, 20, INFINITE_TIME_VALUE);
    start_new_process("midB", mid_b, 20, INFINITE_TIME_VALUE);
    start_new_process("high", high, 30, INFINITE_TIME_VALUE);
    urgent_id = new_process("urgent", urgent, 40, INFINITE_TIME_VALUE);
    peer_id = new_process("peer", peer, 5, INFINITE_TIME_VALUE);
    enter_normal();
    return 1;
}
