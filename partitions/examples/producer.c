/* SPDX-License-Identifier: Apache-2.0 */
/* Example partition: publishes its state on a sampling port and a command on a queuing
 * port once per period. */
#include "example_msgs.h"

static SAMPLING_PORT_ID_TYPE state_port;
static QUEUING_PORT_ID_TYPE cmd_port;

static void produce(void)
{
    uint32_t seq = 0;
    for (;;) {
        RETURN_CODE_TYPE rc;
        SYSTEM_TIME_TYPE now;
        GET_TIME(&now, &rc);
        example_state_t st = {.seq = seq, .t_ns = now, .value = (double)(seq % 100) * 0.5};
        WRITE_SAMPLING_MESSAGE(state_port, (MESSAGE_ADDR_TYPE)&st, sizeof st, &rc);
        if (rc != NO_ERROR)
            example_report("write state rc=%d", (int)rc);
        example_cmd_t cmd = {.seq = seq, .checksum = example_checksum(seq), .t_ns = now};
        SEND_QUEUING_MESSAGE(cmd_port, (MESSAGE_ADDR_TYPE)&cmd, sizeof cmd, 0, &rc);
        if (rc != NO_ERROR)
            example_report("send cmd %u rc=%d", seq, (int)rc);
        seq++;
        PERIODIC_WAIT(&rc);
    }
}

int main(void)
{
    RETURN_CODE_TYPE rc;
    CREATE_SAMPLING_PORT("SP_STATE", sizeof(example_state_t), SOURCE, 100000000, &state_port, &rc);
    example_check(rc, "CREATE_SAMPLING_PORT SP_STATE");
    CREATE_QUEUING_PORT("QP_CMD", sizeof(example_cmd_t), 8, SOURCE, FIFO, &cmd_port, &rc);
    example_check(rc, "CREATE_QUEUING_PORT QP_CMD");
    PROCESS_ATTRIBUTE_TYPE a = {
        .PERIOD = 50000000, .TIME_CAPACITY = 50000000, .ENTRY_POINT = (SYSTEM_ADDRESS_TYPE)produce,
        .STACK_SIZE = 65536, .BASE_PRIORITY = 10, .DEADLINE = SOFT, .NAME = "produce"};
    PROCESS_ID_TYPE pid;
    CREATE_PROCESS(&a, &pid, &rc);
    example_check(rc, "CREATE_PROCESS produce");
    START(pid, &rc);
    example_check(rc, "START produce");
    SET_PARTITION_MODE(NORMAL, &rc);
    example_check(rc, "SET_PARTITION_MODE");
    return 1;
}
