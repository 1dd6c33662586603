/* SPDX-License-Identifier: Apache-2.0 */
/* Test program that is not linked with the APEX library: it never attaches to the SKE. */
#include <stdio.h>

int main(void)
{
    puts("an ordinary Linux program");
    return 0;
}
