/* SPDX-License-Identifier: Apache-2.0 */
/* Example partition: a second reader of the producer's state, in a later window, that
 * measures how old the data is when it reads it. */
#include "example_msgs.h"

static SAMPLING_PORT_ID_TYPE state_port;

static void watch(void)
{
    int64_t max_age = 0;
    uint32_t reads = 0, invalid = 0;
    for (uint32_t n = 1;; n++) {
        RETURN_CODE_TYPE rc;
        example_state_t st;
        MESSAGE_SIZE_TYPE len;
        VALIDITY_TYPE v;
        SYSTEM_TIME_TYPE now;
        RETURN_CODE_TYPE read_rc;
        READ_SAMPLING_MESSAGE(state_port, (MESSAGE_ADDR_TYPE)&st, &len, &v, &read_rc);
        GET_TIME(&now, &rc);
        if (read_rc == NO_ERROR && len == (MESSAGE_SIZE_TYPE)sizeof st) {
            reads++;
            invalid += v != VALID;
            if (now - st.t_ns > max_age)
                max_age = now - st.t_ns;
        }
        if (n % 20 == 0)
            example_report("monitor: reads=%u invalid=%u max_age_us=%lld", reads, invalid,
                           (long long)(max_age / 1000));
        PERIODIC_WAIT(&rc);
    }
}

int main(void)
{
    RETURN_CODE_TYPE rc;
    CREATE_SAMPLING_PORT("SP_STATE_MON", sizeof(example_state_t), DESTINATION, 100000000, &state_port, &rc);
    example_check(rc, "CREATE_SAMPLING_PORT SP_STATE_MON");
    PROCESS_ATTRIBUTE_TYPE a = {
        .PERIOD = 50000000, .TIME_CAPACITY = 50000000, .ENTRY_POINT = (SYSTEM_ADDRESS_TYPE)watch,
        .STACK_SIZE = 65536, .BASE_PRIORITY = 5, .DEADLINE = SOFT, .NAME = "watch"};
    PROCESS_ID_TYPE pid;
    CREATE_PROCESS(&a, &pid, &rc);
    example_check(rc, "CREATE_PROCESS watch");
    START(pid, &rc);
    example_check(rc, "START watch");
    SET_PARTITION_MODE(NORMAL, &rc);
    return 1;
}
