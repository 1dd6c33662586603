/* SPDX-License-Identifier: Apache-2.0 */
/* Benchmark partition: one periodic process that does nothing but wait for its next
 * release, so that a run measures the SKE's own cost per window. */
#include "ARINC653.h"

static void idle_loop(void)
{
    RETURN_CODE_TYPE rc;
    for (;;)
        PERIODIC_WAIT(&rc);
}

int main(void)
{
    RETURN_CODE_TYPE rc;
    PARTITION_STATUS_TYPE st;
    GET_PARTITION_STATUS(&st, &rc);
    PROCESS_ATTRIBUTE_TYPE a = {
        .PERIOD = st.PERIOD, .TIME_CAPACITY = st.PERIOD, .ENTRY_POINT = (SYSTEM_ADDRESS_TYPE)idle_loop,
        .STACK_SIZE = 65536, .BASE_PRIORITY = 10, .DEADLINE = SOFT, .NAME = "idle"};
    PROCESS_ID_TYPE pid;
    CREATE_PROCESS(&a, &pid, &rc);
    START(pid, &rc);
    SET_PARTITION_MODE(NORMAL, &rc);
    return 1;
}
