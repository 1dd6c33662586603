/* SPDX-License-Identifier: Apache-2.0 */
/* Example partition: reads the producer's state each period and receives its commands,
 * checking sequence, checksum and freshness; reports a summary once a second. */
#include "example_msgs.h"

static SAMPLING_PORT_ID_TYPE state_port;
static QUEUING_PORT_ID_TYPE cmd_port;
static uint32_t cmds, cmd_errors, next_cmd;
static uint32_t reads, invalid, stale_seq, last_seq = UINT32_MAX;

static void sample(void)
{
    for (uint32_t n = 1;; n++) {
        RETURN_CODE_TYPE rc;
        example_state_t st;
        MESSAGE_SIZE_TYPE len;
        VALIDITY_TYPE v;
        READ_SAMPLING_MESSAGE(state_port, (MESSAGE_ADDR_TYPE)&st, &len, &v, &rc);
        if (rc == NO_ERROR) {
            reads++;
            if (v != VALID)
                invalid++;
            if (last_seq != UINT32_MAX && st.seq != last_seq + 1)
                stale_seq++;
            last_seq = st.seq;
        }
        if (n % 20 == 0)
            example_report("consumer: reads=%u invalid=%u seq_gaps=%u cmds=%u cmd_errors=%u last=%u",
                           reads, invalid, stale_seq, cmds, cmd_errors, last_seq);
        PERIODIC_WAIT(&rc);
    }
}

static void receive(void)
{
    for (;;) {
        RETURN_CODE_TYPE rc;
        example_cmd_t cmd;
        MESSAGE_SIZE_TYPE len;
        RECEIVE_QUEUING_MESSAGE(cmd_port, INFINITE_TIME_VALUE, (MESSAGE_ADDR_TYPE)&cmd, &len, &rc);
        if (rc != NO_ERROR && rc != INVALID_CONFIG) {
            cmd_errors++;
            continue;
        }
        cmds++;
        if (len != (MESSAGE_SIZE_TYPE)sizeof cmd || cmd.seq != next_cmd ||
            cmd.checksum != example_checksum(cmd.seq))
            cmd_errors++;
        next_cmd = cmd.seq + 1;
    }
}

int main(void)
{
    RETURN_CODE_TYPE rc;
    CREATE_SAMPLING_PORT("SP_STATE_IN", sizeof(example_state_t), DESTINATION, 100000000, &state_port, &rc);
    example_check(rc, "CREATE_SAMPLING_PORT SP_STATE_IN");
    CREATE_QUEUING_PORT("QP_CMD_IN", sizeof(example_cmd_t), 16, DESTINATION, FIFO, &cmd_port, &rc);
    example_check(rc, "CREATE_QUEUING_PORT QP_CMD_IN");
    PROCESS_ATTRIBUTE_TYPE a = {
        .PERIOD = 50000000, .TIME_CAPACITY = 50000000, .ENTRY_POINT = (SYSTEM_ADDRESS_TYPE)sample,
        .STACK_SIZE = 65536, .BASE_PRIORITY = 20, .DEADLINE = SOFT, .NAME = "sample"};
    PROCESS_ID_TYPE pid;
    CREATE_PROCESS(&a, &pid, &rc);
    example_check(rc, "CREATE_PROCESS sample");
    START(pid, &rc);
    example_check(rc, "START sample");
    PROCESS_ATTRIBUTE_TYPE b = {
        .PERIOD = INFINITE_TIME_VALUE, .TIME_CAPACITY = INFINITE_TIME_VALUE,
        .ENTRY_POINT = (SYSTEM_ADDRESS_TYPE)receive, .STACK_SIZE = 65536, .BASE_PRIORITY = 10,
        .DEADLINE = SOFT, .NAME = "receive"};
    CREATE_PROCESS(&b, &pid, &rc);
    example_check(rc, "CREATE_PROCESS receive");
    START(pid, &rc);
    example_check(rc, "START receive");
    SET_PARTITION_MODE(NORMAL, &rc);
    return 1;
}
