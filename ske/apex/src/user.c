/* SPDX-License-Identifier: Apache-2.0 */
/* The addresses a partition gives APEX services: a null pointer, or an address the partition
 * cannot read or write, is its ILLEGAL_REQUEST, never a fault of the library (a raw SIGSEGV
 * would be charged to the service as a MEMORY_VIOLATION). */
#include <string.h>

#include "apex__rt.h"

#define PAGE 4096u

/* Touches every page of [p, p + n) inside apex__user_copy: a fault there is reported as the
 * caller's invalid address. Writing back the byte just read leaves the caller's data as it
 * was, and proves an output can be written before the service changes any state. */
static void probe(const void *p, size_t n, bool write)
{
    if (n == 0)
        return;
    volatile APEX_BYTE *b = (volatile APEX_BYTE *)(uintptr_t)p;
    apex__user_copy(true);
    for (size_t off = 0;; off += PAGE) {
        if (off >= n)
            off = n - 1; /* the last byte, so that a range ending on a new page is checked */
        APEX_BYTE v = b[off];
        if (write)
            b[off] = v;
        if (off == n - 1)
            break;
    }
    apex__user_copy(false);
}

bool apex__enter(RETURN_CODE_TYPE *rc)
{
    apex__sync();
    if (!rc) {
        apex__invalid_address(NULL); /* nowhere to say INVALID_PARAM */
        return false;
    }
    probe(rc, sizeof *rc, true);
    return true;
}

/* A null address takes the path of any other address the caller cannot use: the health
 * monitor has its ILLEGAL_REQUEST and the call does not go on. The false return is for a
 * caller the health monitor let go on (an IGNORE of an error its process survives). */
static bool null_address(void)
{
    apex__invalid_address(NULL);
    return false;
}

bool apex__addr_ok(const void *p) { return p ? true : null_address(); }

bool apex__out_ok(void *p, size_t n)
{
    if (!p)
        return null_address();
    probe(p, n, true);
    return true;
}

bool apex__in_ok(const void *p, size_t n)
{
    if (!p)
        return null_address();
    probe(p, n, false);
    return true;
}

bool apex__name_ok(const char *name)
{
    if (!name)
        return null_address();
    apex__user_copy(true);
    volatile size_t n = strnlen(name, MAX_NAME_LENGTH); /* volatile: the read must happen */
    apex__user_copy(false);
    (void)n;
    return true;
}
