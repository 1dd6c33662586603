/* SPDX-License-Identifier: Apache-2.0 */
/* The addresses a partition gives APEX services: a null pointer, or an address the partition
 * cannot read or write, is its ILLEGAL_REQUEST, never a fault of the library (a raw SIGSEGV
 * would be charged to the service as a MEMORY_VIOLATION). Inline, included by apex__rt.h
 * alone: every service call checks a few addresses, and a call costs tens of nanoseconds. */
#ifndef APEX__USER_H
#define APEX__USER_H

#define APEX__PAGE 4096u

/* Touches [p, p + n) inside apex__user_copy: a fault there is reported as the caller's
 * invalid address. Writing back the byte just read leaves the caller's data as it was, and
 * proves an output can be written before the service changes any state. One byte per page,
 * and the last one, so that a range ending on a new page is checked. */
static inline void apex__probe(const void *p, size_t n, bool write)
{
    if (n == 0)
        return;
    volatile APEX_BYTE *b = (volatile APEX_BYTE *)(uintptr_t)p;
    apex__user_copy(true);
    if ((uintptr_t)p / APEX__PAGE == ((uintptr_t)p + n - 1) / APEX__PAGE) {
        APEX_BYTE v = b[0]; /* within one page: one byte tells */
        if (write)
            b[0] = v;
    } else {
        for (size_t off = 0;; off += APEX__PAGE) {
            if (off >= n)
                off = n - 1;
            APEX_BYTE v = b[off];
            if (write)
                b[off] = v;
            if (off == n - 1)
                break;
        }
    }
    apex__user_copy(false);
}

/* A null address takes the path of any other address the caller cannot use: the health
 * monitor has its ILLEGAL_REQUEST, and the calling process stops there (apex__invalid_address
 * does not return). So every check below either passes or never comes back. */
static inline void apex__enter(RETURN_CODE_TYPE *rc)
{
    apex__sync();
    if (!rc)
        apex__invalid_address(NULL); /* nowhere to say anything */
    apex__probe(rc, sizeof *rc, true);
}

static inline void apex__check_addr(const void *p)
{
    if (!p)
        apex__invalid_address(NULL);
}

static inline void apex__check_out(void *p, size_t n)
{
    apex__check_addr(p);
    apex__probe(p, n, true);
}

static inline void apex__check_in(const void *p, size_t n)
{
    apex__check_addr(p);
    apex__probe(p, n, false);
}

/* A name parameter: readable up to its NUL or MAX_NAME_LENGTH characters. */
static inline void apex__check_name(const char *name)
{
    apex__check_addr(name);
    apex__user_copy(true);
    volatile size_t n = strnlen(name, MAX_NAME_LENGTH); /* volatile: the read must happen */
    apex__user_copy(false);
    (void)n;
}

#endif
