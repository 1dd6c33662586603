/* SPDX-License-Identifier: Apache-2.0 */
/* Test partition of the isolation tests: stack overflows end in a fault, never in another
 * stack. Arguments name the scenario; the partition reports "OVERFLOW <scenario>" before it
 * overflows, and "SURVIVED <scenario>" if it ever comes back.
 *
 *   Arguments="init"      the initialisation process (the main thread's stack) recurses
 *   Arguments="process"   an ARINC process recurses into the guard page under its stack
 *   Arguments="clash"     an ARINC process calls a function whose frame is larger than the
 *                         whole stack: its first write would land past the guard page, in
 *                         whatever is mapped below (the stack of the process created after
 *                         it, say), unless the partition is compiled to probe its stack page
 *                         by page (-fstack-clash-protection)
 */
#include <limits.h>
#include <stdint.h>
#include <stdlib.h>

#include "apex_check.h"

static const char *scenario = "init";

static volatile long deepest = LONG_MAX; /* never reached: no stack holds that many pages */

/* Each level keeps a page of its own alive, so the recursion cannot become a loop. */
static __attribute__((noinline)) long recurse(long depth)
{
    if (depth >= deepest)
        return 0;
    volatile char page[4096];
    page[0] = (char)depth;
    page[sizeof page - 1] = (char)depth;
    return recurse(depth + 1) + page[0] + page[sizeof page - 1];
}

static __attribute__((noinline)) void huge_frame(void)
{
    volatile char frame[512 * 1024];
    frame[0] = 1; /* the lowest address first: 512 KiB below the caller */
    frame[sizeof frame - 1] = 1;
}

static volatile uint32_t victim_canary = 0;

static void victim(void)
{
    /* The process whose stack lies below the overflowing one; it checks that its stack still
     * holds what it wrote before the overflow. */
    volatile uint8_t mine[256 * 1024];
    memset((void *)mine, 0xa5, sizeof mine);
    victim_canary = 1;
    RETURN_CODE_TYPE rc;
    for (;;) {
        size_t bad = 0;
        for (size_t i = 0; i < sizeof mine; i++)
            bad += mine[i] != 0xa5;
        report("victim stack intact=%s", bad == 0 ? "yes" : "no");
        PERIODIC_WAIT(&rc);
    }
}

static void overflow(void)
{
    report("OVERFLOW %s", scenario);
    if (strcmp(scenario, "clash") == 0)
        huge_frame();
    else
        report("SURVIVED %s depth %ld", scenario, recurse(0));
    report("SURVIVED %s", scenario);
    RETURN_CODE_TYPE rc;
    for (;;)
        PERIODIC_WAIT(&rc);
}

int main(int argc, char **argv)
{
    if (argc > 1)
        scenario = argv[1];
    if (strcmp(scenario, "init") == 0)
        overflow();
    PARTITION_STATUS_TYPE st;
    RETURN_CODE_TYPE rc;
    GET_PARTITION_STATUS(&st, &rc);
    /* Created first, so its stack is mapped above the victim's. */
    PROCESS_ATTRIBUTE_TYPE a = process_attributes("overflow", overflow, 10, st.PERIOD, st.PERIOD);
    a.STACK_SIZE = 64 * 1024;
    PROCESS_ID_TYPE id;
    CREATE_PROCESS(&a, &id, &rc);
    setup_rc("CREATE_PROCESS overflow", rc);
    PROCESS_ATTRIBUTE_TYPE v = process_attributes("victim", victim, 20, st.PERIOD, st.PERIOD);
    v.STACK_SIZE = 1024 * 1024;
    PROCESS_ID_TYPE vid;
    CREATE_PROCESS(&v, &vid, &rc);
    setup_rc("CREATE_PROCESS victim", rc);
    START(vid, &rc);
    START(id, &rc);
    enter_normal();
    return 1;
}
