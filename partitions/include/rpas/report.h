/* SPDX-License-Identifier: Apache-2.0 */
/* printf-style REPORT_APPLICATION_MESSAGE for the RPAS partitions (one line in the node's
 * trace, cut at the APEX message size). */
#ifndef RPAS_REPORT_H
#define RPAS_REPORT_H

#include <stdarg.h>
#include <stdio.h>

#include "ARINC653.h"

static inline void rpas_report(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
static inline void rpas_report(const char *fmt, ...)
{
    char buf[MAX_ERROR_MESSAGE_SIZE];
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    if (n < 0)
        return;
    if (n >= (int)sizeof buf)
        n = (int)sizeof buf - 1;
    RETURN_CODE_TYPE rc;
    REPORT_APPLICATION_MESSAGE((MESSAGE_ADDR_TYPE)buf, n, &rc);
}

#endif
