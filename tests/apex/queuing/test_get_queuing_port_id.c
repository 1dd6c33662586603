/* SPDX-License-Identifier: Apache-2.0 */
/* GET_QUEUING_PORT_ID (ARINC 653 Part 1, 3.6.2.2): NO_ERROR with the identifier
 * CREATE_QUEUING_PORT gave; INVALID_CONFIG for a name that is no created queuing port of the
 * partition (output untouched); from the initialisation process and from a process. */
#include "apex_check.h"

static QUEUING_PORT_ID_TYPE port_a, port_b;

static void lookup(const char *phase, const char *check, const char *name,
                   QUEUING_PORT_ID_TYPE expect_id, RETURN_CODE_TYPE expect)
{
    QUEUING_PORT_ID_TYPE id = UNTOUCHED;
    RETURN_CODE_TYPE rc;
    char n[64];
    GET_QUEUING_PORT_ID(name, &id, &rc);
    snprintf(n, sizeof n, "%s.%s", phase, check);
    check_rc(n, expect, rc);
    snprintf(n, sizeof n, "%s.%s.id", phase, check);
    check_int(n, expect == NO_ERROR ? expect_id : UNTOUCHED, id);
}

static void lookups(const char *phase)
{
    lookup(phase, "source", "QP_A", port_a, NO_ERROR);
    lookup(phase, "destination", "QP_B", port_b, NO_ERROR);
    lookup(phase, "configured_not_created", "QP_UNUSED", 0, INVALID_CONFIG);
    lookup(phase, "unknown", "QP_NOPE", 0, INVALID_CONFIG);
    lookup(phase, "prefix", "QP_", 0, INVALID_CONFIG);
    lookup(phase, "empty", "", 0, INVALID_CONFIG);
    lookup(phase, "sampling_port", "SP_S", 0, INVALID_CONFIG);
}

static void in_normal(void) { lookups("normal"); }

int main(void)
{
    RETURN_CODE_TYPE rc;
    SAMPLING_PORT_ID_TYPE s;
    CREATE_QUEUING_PORT("QP_A", 8, 2, SOURCE, FIFO, &port_a, &rc);
    setup_rc("CREATE_QUEUING_PORT QP_A", rc);
    CREATE_QUEUING_PORT("QP_B", 8, 3, DESTINATION, PRIORITY, &port_b, &rc);
    setup_rc("CREATE_QUEUING_PORT QP_B", rc);
    CREATE_SAMPLING_PORT("SP_S", 8, SOURCE, 100 * MS, &s, &rc);
    setup_rc("CREATE_SAMPLING_PORT SP_S", rc);
    lookups("init");
    start_new_process("in_normal", in_normal, 10, INFINITE_TIME_VALUE);
    enter_normal();
    return 1;
}
