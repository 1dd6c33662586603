/* SPDX-License-Identifier: Apache-2.0 */
/* TIMED_WAIT (ARINC 653 Part 1, 3.4.2). Scenario "delay" (window 0-10 ms of a 20 ms
 * frame): NO_ERROR with the delay seen in GET_TIME, INVALID_PARAM for a negative or infinite
 * delay, INVALID_MODE in the initialisation process. Scenario "yield": a zero delay moves the
 * caller behind the ready processes of its own priority (round robin) and never lets a
 * lower-priority one run. */
#include <stdint.h>

#include "apex_check.h"

static int background_ran;

static void background(void) { background_ran = 1; }

static void waiter(void)
{
    RETURN_CODE_TYPE rc;
    SYSTEM_TIME_TYPE t0 = now_ns();
    TIMED_WAIT(3 * MS, &rc);
    check_rc("delay.rc", NO_ERROR, rc);
    check_int("delay.elapsed", 3 * MS, now_ns() - t0);
    check_int("delay.others_ran", 1, background_ran);

    t0 = now_ns();
    TIMED_WAIT(-5, &rc);
    check_rc("negative", INVALID_PARAM, rc);
    check_int("negative.elapsed", 0, now_ns() - t0);
    TIMED_WAIT(INFINITE_TIME_VALUE, &rc);
    check_rc("infinite", INVALID_PARAM, rc);
    check_int("infinite.elapsed", 0, now_ns() - t0);

    /* Due at 12 ms, after the window's end: the process runs again when the partition
     * next gets the CPU, at 20 ms. */
    TIMED_WAIT(9 * MS, &rc);
    check_rc("past_window_end.rc", NO_ERROR, rc);
    check_int("past_window_end.time", 20 * MS, now_ns());

    /* 20 ms + INT64_MAX is past the end of the clock: out of range. */
    t0 = now_ns();
    TIMED_WAIT(INT64_MAX, &rc);
    check_rc("beyond_clock", INVALID_PARAM, rc);
    check_int("beyond_clock.elapsed", 0, now_ns() - t0);
}

static char order[128];

static void log_step(const char *step)
{
    if (order[0])
        strncat(order, ",", sizeof order - strlen(order) - 1);
    strncat(order, step, sizeof order - strlen(order) - 1);
}

static int zero_wait_errors;
static SYSTEM_TIME_TYPE zero_wait_elapsed;

static void yield_now(void)
{
    RETURN_CODE_TYPE rc;
    SYSTEM_TIME_TYPE t0 = now_ns();
    TIMED_WAIT(0, &rc);
    zero_wait_errors += rc != NO_ERROR;
    zero_wait_elapsed += now_ns() - t0;
}

static void proc_a(void)
{
    log_step("A1");
    yield_now();
    log_step("A2");
    yield_now();
    log_step("A3");
}

static void proc_b(void)
{
    log_step("B1");
    yield_now();
    log_step("B2");
}

static void proc_c(void)
{
    log_step("C1");
    yield_now(); /* nobody else of its priority is ready: it goes on at once */
    log_step("C2");
    check_str("yield.order", "A1,B1,A2,B2,A3,C1,C2", order);
    check_int("yield.errors", 0, zero_wait_errors);
    check_int("yield.elapsed", 0, zero_wait_elapsed);
}

int main(int argc, char **argv)
{
    const char *scenario = argc > 1 ? argv[1] : "";
    if (strcmp(scenario, "delay") == 0) {
        RETURN_CODE_TYPE rc;
        TIMED_WAIT(1 * MS, &rc);
        check_rc("init.invalid_mode", INVALID_MODE, rc);
        start_new_process("waiter", waiter, 10, INFINITE_TIME_VALUE);
        start_new_process("background", background, 5, INFINITE_TIME_VALUE);
    } else if (strcmp(scenario, "yield") == 0) {
        start_new_process("A", proc_a, 20, INFINITE_TIME_VALUE);
        start_new_process("B", proc_b, 20, INFINITE_TIME_VALUE);
        start_new_process("C", proc_c, 10, INFINITE_TIME_VALUE);
    } else {
        report("SETUP unknown scenario '%s'", scenario);
    }
    enter_normal();
    return 1;
}
