/* SPDX-License-Identifier: Apache-2.0 */
/* Benchmark partition: the cost of WRITE_SAMPLING_MESSAGE then READ_SAMPLING_MESSAGE of
 * 64 bytes through a channel from this partition to itself, measured in batches on
 * CLOCK_MONOTONIC; reports the median per pair to the trace. */
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "ARINC653.h"

#define BATCH 64
#define BATCHES 4001

static SAMPLING_PORT_ID_TYPE out, in;

static int64_t mono_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (int64_t)ts.tv_sec * 1000000000LL + ts.tv_nsec;
}

static int cmp(const void *a, const void *b)
{
    int64_t x = *(const int64_t *)a, y = *(const int64_t *)b;
    return (x > y) - (x < y);
}

static void measure(void)
{
    static int64_t per_pair[BATCHES];
    APEX_BYTE msg[64] = {0}, buf[64];
    RETURN_CODE_TYPE rc, rc2;
    MESSAGE_SIZE_TYPE len;
    VALIDITY_TYPE v;
    int errors = 0;
    for (int b = 0; b < BATCHES; b++) {
        int64_t t0 = mono_ns();
        for (int i = 0; i < BATCH; i++) {
            msg[0] = (APEX_BYTE)i;
            WRITE_SAMPLING_MESSAGE(out, msg, sizeof msg, &rc);
            READ_SAMPLING_MESSAGE(in, buf, &len, &v, &rc2);
            errors += rc != NO_ERROR || rc2 != NO_ERROR || buf[0] != (APEX_BYTE)i;
        }
        per_pair[b] = (mono_ns() - t0) / BATCH;
    }
    qsort(per_pair, BATCHES, sizeof per_pair[0], cmp);
    char text[MAX_ERROR_MESSAGE_SIZE];
    int n = snprintf(text, sizeof text, "sampling_rw_ns_median=%lld p99=%lld errors=%d",
                     (long long)per_pair[BATCHES / 2], (long long)per_pair[BATCHES * 99 / 100], errors);
    REPORT_APPLICATION_MESSAGE((MESSAGE_ADDR_TYPE)text, n, &rc);
    for (;;)
        PERIODIC_WAIT(&rc);
}

int main(void)
{
    RETURN_CODE_TYPE rc;
    CREATE_SAMPLING_PORT("BENCH_OUT", 64, SOURCE, 1000000000, &out, &rc);
    if (rc != NO_ERROR)
        return 2;
    CREATE_SAMPLING_PORT("BENCH_IN", 64, DESTINATION, 1000000000, &in, &rc);
    if (rc != NO_ERROR)
        return 2;
    PROCESS_ATTRIBUTE_TYPE a = {
        .PERIOD = 1000000000, .TIME_CAPACITY = 1000000000, .ENTRY_POINT = (SYSTEM_ADDRESS_TYPE)measure,
        .STACK_SIZE = 65536, .BASE_PRIORITY = 10, .DEADLINE = SOFT, .NAME = "measure"};
    PROCESS_ID_TYPE pid;
    CREATE_PROCESS(&a, &pid, &rc);
    START(pid, &rc);
    SET_PARTITION_MODE(NORMAL, &rc);
    return 1;
}
