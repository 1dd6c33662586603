/* SPDX-License-Identifier: Apache-2.0 */
/* GET_PROCESS_ID (ARINC 653 Part 1, 3.3.2): NO_ERROR with the identifier CREATE_PROCESS
 * gave, INVALID_CONFIG for a name no process has (output untouched); from the initialisation
 * process and from a process. */
#include "apex_check.h"

static PROCESS_ID_TYPE alpha_id, beta_id, long_id;
static NAME_TYPE long_name; /* 30 characters, no terminator: the whole NAME_TYPE */

static void lookup(const char *check, const char *name, PROCESS_ID_TYPE expect_id,
                   RETURN_CODE_TYPE expect)
{
    PROCESS_ID_TYPE id = UNTOUCHED;
    RETURN_CODE_TYPE rc;
    char n[64];
    GET_PROCESS_ID(name, &id, &rc);
    check_rc(check, expect, rc);
    snprintf(n, sizeof n, "%s.id", check);
    check_int(n, expect == NO_ERROR ? expect_id : UNTOUCHED, id);
}

static void lookups(const char *phase)
{
    char n[64];
    snprintf(n, sizeof n, "%s.alpha", phase);
    lookup(n, "alpha", alpha_id, NO_ERROR);
    snprintf(n, sizeof n, "%s.beta", phase);
    lookup(n, "beta", beta_id, NO_ERROR);
    snprintf(n, sizeof n, "%s.full_length_name", phase);
    lookup(n, long_name, long_id, NO_ERROR);
    snprintf(n, sizeof n, "%s.unknown", phase);
    lookup(n, "gamma", 0, INVALID_CONFIG);
    snprintf(n, sizeof n, "%s.prefix", phase);
    lookup(n, "alph", 0, INVALID_CONFIG);
    snprintf(n, sizeof n, "%s.longer", phase);
    lookup(n, "alphabet", 0, INVALID_CONFIG);
    snprintf(n, sizeof n, "%s.empty", phase);
    lookup(n, "", 0, INVALID_CONFIG);
}

static void alpha(void) { lookups("normal"); }
static void beta(void) {}

int main(void)
{
    memset(long_name, 'x', sizeof long_name);
    alpha_id = start_new_process("alpha", alpha, 10, INFINITE_TIME_VALUE);
    beta_id = new_process("beta", beta, 10, INFINITE_TIME_VALUE);
    PROCESS_ATTRIBUTE_TYPE a = process_attributes("", beta, 10, INFINITE_TIME_VALUE,
                                                  INFINITE_TIME_VALUE);
    memcpy(a.NAME, long_name, sizeof a.NAME);
    RETURN_CODE_TYPE rc;
    CREATE_PROCESS(&a, &long_id, &rc);
    setup_rc("CREATE_PROCESS with a 30-character name", rc);
    lookups("init");
    enter_normal();
    return 1;
}
