/* SPDX-License-Identifier: Apache-2.0 */
/* Test partition linked with the APEX library that ends before it can attach to the SKE:
 * a constructor with a priority runs before the library's own (unprioritised) one. */
#include <unistd.h>

#include "ARINC653.h"

__attribute__((constructor(101))) static void leave_early(void) { _exit(4); }

int main(void)
{
    RETURN_CODE_TYPE rc;
    SET_PARTITION_MODE(NORMAL, &rc);
    return 1;
}
