/* SPDX-License-Identifier: Apache-2.0 */
/* GET_MY_ID (ARINC 653 Part 1, 3.3.2): a process gets the identifier CREATE_PROCESS gave
 * it; the initialisation process has none (INVALID_MODE) and its output stays untouched. */
#include "apex_check.h"

static PROCESS_ID_TYPE alpha_id, beta_id;

static void who_am_i(const char *name, PROCESS_ID_TYPE created)
{
    PROCESS_ID_TYPE id = UNTOUCHED;
    RETURN_CODE_TYPE rc;
    char n[64];
    GET_MY_ID(&id, &rc);
    snprintf(n, sizeof n, "%s.rc", name);
    check_rc(n, NO_ERROR, rc);
    snprintf(n, sizeof n, "%s.id", name);
    check_int(n, created, id);
}

static void alpha(void) { who_am_i("alpha", alpha_id); }
static void beta(void) { who_am_i("beta", beta_id); }

int main(void)
{
    PROCESS_ID_TYPE id = UNTOUCHED;
    RETURN_CODE_TYPE rc;
    GET_MY_ID(&id, &rc);
    check_rc("init.rc", INVALID_MODE, rc);
    check_int("init.id_untouched", UNTOUCHED, id);
    alpha_id = start_new_process("alpha", alpha, 10, INFINITE_TIME_VALUE);
    beta_id = start_new_process("beta", beta, 10, INFINITE_TIME_VALUE);
    check_true("ids_distinct", alpha_id != beta_id);
    enter_normal();
    return 1;
}
