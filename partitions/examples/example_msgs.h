/* SPDX-License-Identifier: Apache-2.0 */
/* Message layouts shared by the example module's partitions. */
#ifndef EXAMPLE_MSGS_H
#define EXAMPLE_MSGS_H

#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "ARINC653.h"

/* Sampling message: the producer's state, 64 bytes on the wire. */
typedef struct {
    uint32_t seq;
    uint32_t pad;
    int64_t t_ns; /* producer's GET_TIME when written */
    double value; /* a slowly varying signal */
    uint8_t fill[40];
} example_state_t;

/* Queuing message: a command, 32 bytes. */
typedef struct {
    uint32_t seq;
    uint32_t checksum; /* seq * 2654435761 */
    int64_t t_ns;
    uint8_t fill[16];
} example_cmd_t;

static inline uint32_t example_checksum(uint32_t seq) { return seq * 2654435761u; }

/* Reports a line to the module's trace (REPORT_APPLICATION_MESSAGE). */
static inline void example_report(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
#include <stdarg.h>
static inline void example_report(const char *fmt, ...)
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

/* Stops the partition with a message when an APEX call fails during initialisation. */
static inline void example_check(RETURN_CODE_TYPE rc, const char *what)
{
    if (rc != NO_ERROR) {
        fprintf(stderr, "%s failed: return code %d\n", what, (int)rc);
        example_report("init failed: %s rc=%d", what, (int)rc);
        SET_PARTITION_MODE(IDLE, &rc);
    }
}

#endif /* EXAMPLE_MSGS_H */
