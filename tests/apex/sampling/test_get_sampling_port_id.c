/* SPDX-License-Identifier: Apache-2.0 */
/* GET_SAMPLING_PORT_ID (ARINC 653 Part 1, 3.6.2.1): NO_ERROR with the identifier
 * CREATE_SAMPLING_PORT gave; INVALID_CONFIG for a name that is no created sampling port of the
 * partition (output untouched); from the initialisation process and from a process. */
#include "apex_check.h"

static SAMPLING_PORT_ID_TYPE port_a, port_b;

static void lookup(const char *phase, const char *check, const char *name,
                   SAMPLING_PORT_ID_TYPE expect_id, RETURN_CODE_TYPE expect)
{
    SAMPLING_PORT_ID_TYPE id = UNTOUCHED;
    RETURN_CODE_TYPE rc;
    char n[64];
    GET_SAMPLING_PORT_ID(name, &id, &rc);
    snprintf(n, sizeof n, "%s.%s", phase, check);
    check_rc(n, expect, rc);
    snprintf(n, sizeof n, "%s.%s.id", phase, check);
    check_int(n, expect == NO_ERROR ? expect_id : UNTOUCHED, id);
}

static void lookups(const char *phase)
{
    lookup(phase, "source", "SP_A", port_a, NO_ERROR);
    lookup(phase, "destination", "SP_B", port_b, NO_ERROR);
    lookup(phase, "configured_not_created", "SP_UNUSED", 0, INVALID_CONFIG);
    lookup(phase, "unknown", "SP_NOPE", 0, INVALID_CONFIG);
    lookup(phase, "prefix", "SP_", 0, INVALID_CONFIG);
    lookup(phase, "empty", "", 0, INVALID_CONFIG);
    lookup(phase, "queuing_port", "QP_Q", 0, INVALID_CONFIG);
}

static void in_normal(void) { lookups("normal"); }

int main(void)
{
    RETURN_CODE_TYPE rc;
    QUEUING_PORT_ID_TYPE q;
    CREATE_SAMPLING_PORT("SP_A", 8, SOURCE, 100 * MS, &port_a, &rc);
    setup_rc("CREATE_SAMPLING_PORT SP_A", rc);
    CREATE_SAMPLING_PORT("SP_B", 8, DESTINATION, 100 * MS, &port_b, &rc);
    setup_rc("CREATE_SAMPLING_PORT SP_B", rc);
    CREATE_QUEUING_PORT("QP_Q", 8, 2, SOURCE, FIFO, &q, &rc);
    setup_rc("CREATE_QUEUING_PORT QP_Q", rc);
    lookups("init");
    start_new_process("in_normal", in_normal, 10, INFINITE_TIME_VALUE);
    enter_normal();
    return 1;
}
