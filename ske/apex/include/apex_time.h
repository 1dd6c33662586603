/* SPDX-License-Identifier: Apache-2.0 */
/* ARINC 653 Part 1 time management services, C binding. */
#ifndef APEX_TIME
#define APEX_TIME

#include "apex_types.h"

#ifdef __cplusplus
extern "C" {
#endif

extern void TIMED_WAIT(
    /*in */ SYSTEM_TIME_TYPE DELAY_TIME,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE);

extern void PERIODIC_WAIT(
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE);

extern void GET_TIME(
    /*out*/ SYSTEM_TIME_TYPE *SYSTEM_TIME,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE);

extern void REPLENISH(
    /*in */ SYSTEM_TIME_TYPE BUDGET_TIME,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE);

#ifdef __cplusplus
}
#endif

#endif /* APEX_TIME */
