/* SPDX-License-Identifier: Apache-2.0 */
/* ARINC 653 Part 1 health monitoring services available so far, C binding. */
#ifndef APEX_ERROR
#define APEX_ERROR

#include "apex_types.h"

#define MAX_ERROR_MESSAGE_SIZE 128
typedef APEX_INTEGER ERROR_MESSAGE_SIZE_TYPE;
typedef APEX_BYTE ERROR_MESSAGE_TYPE[MAX_ERROR_MESSAGE_SIZE];

extern void REPORT_APPLICATION_MESSAGE(
    /*in */ MESSAGE_ADDR_TYPE MESSAGE_ADDR,
    /*in */ MESSAGE_SIZE_TYPE LENGTH,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE);

#endif /* APEX_ERROR */
