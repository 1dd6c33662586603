/* SPDX-License-Identifier: Apache-2.0 */
/* GET_TIME (ARINC 653 Part 1, 3.4.2): NO_ERROR, the time of the window start when the
 * partition gets the CPU, of the release point when a periodic process is released; in
 * emulated time, computation inside a window takes no time. The partition's one window
 * starts its 20 ms period, at the offset (in ms) given as the partition's argument. */
#include <stdlib.h>

#include "apex_check.h"

static SYSTEM_TIME_TYPE offset;

static void cyclic(void)
{
    for (int k = 0; k < 4; k++) {
        SYSTEM_TIME_TYPE t = -1;
        RETURN_CODE_TYPE rc;
        char n[32];
        GET_TIME(&t, &rc);
        snprintf(n, sizeof n, "release.%d.rc", k);
        check_rc(n, NO_ERROR, rc);
        snprintf(n, sizeof n, "release.%d", k);
        check_int(n, offset + k * 20 * MS, t);
        PERIODIC_WAIT(&rc);
    }
}

int main(int argc, char **argv)
{
    offset = argc > 1 ? atoi(argv[1]) * MS : 0;
    SYSTEM_TIME_TYPE t = -1;
    RETURN_CODE_TYPE rc;
    GET_TIME(&t, &rc);
    check_rc("init.rc", NO_ERROR, rc);
    check_int("init", offset, t);
    volatile unsigned long spin = 0;
    for (unsigned long i = 0; i < 200000; i++)
        spin += i;
    check_int("init.after_computing", offset, now_ns());
    start_new_process("cyclic", cyclic, 10, 20 * MS);
    enter_normal();
    return 1;
}
