/* SPDX-License-Identifier: Apache-2.0 */
/* APEX health monitoring services available so far: REPORT_APPLICATION_MESSAGE
 * (ARINC 653 Part 1, 3.10.2). */
#include "apex__rt.h"

void REPORT_APPLICATION_MESSAGE(
    /*in */ MESSAGE_ADDR_TYPE MESSAGE_ADDR,
    /*in */ MESSAGE_SIZE_TYPE LENGTH,
    /*out*/ RETURN_CODE_TYPE *RETURN_CODE)
{
    apex__enter(RETURN_CODE);
    if (LENGTH < 0 || LENGTH > MAX_ERROR_MESSAGE_SIZE) {
        *RETURN_CODE = INVALID_PARAM;
        return;
    }
    if (LENGTH > 0)
        apex__check_addr(MESSAGE_ADDR);
    PROCESS_ID_TYPE id = apex__rt.current ? apex__rt.current->id : 0;
    apex__user_copy(true);
    apex__event(SKE_EV_APP_MESSAGE, id, 0, MESSAGE_ADDR, (uint32_t)LENGTH);
    apex__user_copy(false);
    *RETURN_CODE = NO_ERROR;
}
