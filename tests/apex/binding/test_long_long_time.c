/* SPDX-License-Identifier: Apache-2.0 */
/* An application written as for another APEX implementation: times kept in long long
 * variables and printed with %lld, no casts, built with -Wall -Wextra -Werror (-Wformat=2).
 * Each period it reports its time, its deadline and its partition's period, and writes its
 * time on a sampling port for the C++ partition. */
#include <stdio.h>

#include "ARINC653.h"

/* SYSTEM_TIME_TYPE is long long itself, not merely as wide. */
_Static_assert(_Generic((SYSTEM_TIME_TYPE)0, long long: 1, default: 0), "SYSTEM_TIME_TYPE");
_Static_assert(_Generic((APEX_LONG_INTEGER)0, long long: 1, default: 0), "APEX_LONG_INTEGER");

static SAMPLING_PORT_ID_TYPE time_port;

static void say(const char *text, int len)
{
    RETURN_CODE_TYPE rc;
    REPORT_APPLICATION_MESSAGE((MESSAGE_ADDR_TYPE)text, len, &rc);
}

static void tick(void)
{
    for (long long n = 0;; n++) {
        RETURN_CODE_TYPE rc;
        long long now;
        GET_TIME(&now, &rc);
        PROCESS_ID_TYPE me;
        GET_MY_ID(&me, &rc);
        PROCESS_STATUS_TYPE status;
        GET_PROCESS_STATUS(me, &status, &rc);
        long long *deadline = &status.DEADLINE_TIME; /* compiles only if the types agree */
        PARTITION_STATUS_TYPE partition;
        GET_PARTITION_STATUS(&partition, &rc);

        char text[MAX_ERROR_MESSAGE_SIZE];
        int len = snprintf(text, sizeof text,
                           "tick %lld at %lld ns, deadline %lld ns, period %lld ns", n, now,
                           *deadline, partition.PERIOD);
        say(text, len);
        WRITE_SAMPLING_MESSAGE(time_port, (MESSAGE_ADDR_TYPE)&now, sizeof now, &rc);

        long long parsed = -1;
        if (sscanf(text, "tick %*d at %lld ns", &parsed) == 1 && parsed != now)
            say("parsed time differs", 19);
        PERIODIC_WAIT(&rc);
    }
}

int main(void)
{
    RETURN_CODE_TYPE rc;
    CREATE_SAMPLING_PORT("C_TIME", sizeof(long long), SOURCE, 25000000LL, &time_port, &rc);
    if (rc != NO_ERROR)
        return 1;
    PROCESS_ATTRIBUTE_TYPE attr = {
        .PERIOD = 20000000LL,
        .TIME_CAPACITY = 10000000LL,
        .ENTRY_POINT = (SYSTEM_ADDRESS_TYPE)tick,
        .STACK_SIZE = 65536,
        .BASE_PRIORITY = 10,
        .DEADLINE = SOFT,
        .NAME = "tick",
    };
    PROCESS_ID_TYPE pid;
    CREATE_PROCESS(&attr, &pid, &rc);
    if (rc != NO_ERROR)
        return 1;
    START(pid, &rc);
    SET_PARTITION_MODE(NORMAL, &rc);
    return 1;
}
