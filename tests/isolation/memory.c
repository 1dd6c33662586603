/* SPDX-License-Identifier: Apache-2.0 */
/* Test partition of the isolation tests: what a partition sees when it allocates past its
 * Partition_Memory. Arguments="MIB": the limit the module gives it, in MiB (0: none).
 *
 * Initialisation: one allocation larger than the limit; then 1 MiB blocks, each written
 * through, until one fails; CREATE_PROCESS while the memory is used up; the blocks freed,
 * a large allocation again. Every result is a CHECK line. Then a periodic process allocates,
 * writes and frees 1 MiB in every period and reports "tick N ok". */
#include <errno.h>
#include <stdlib.h>
#include <sys/mman.h>

#include "apex_check.h"

#define MIB (1024L * 1024L)
#define MAX_BLOCKS 4096

static void *blocks[MAX_BLOCKS];

static void tick(void)
{
    for (long n = 0;; n++) {
        RETURN_CODE_TYPE rc;
        char *p = malloc(MIB);
        if (p)
            memset(p, (int)n, MIB);
        report("tick %ld %s", n, p ? "ok" : "no-memory");
        free(p);
        PERIODIC_WAIT(&rc);
    }
}

static void limited(long limit_mib)
{
    errno = 0;
    void *big = malloc((size_t)(limit_mib + 1) * MIB);
    check_str("big.malloc", "NULL", big ? "pointer" : "NULL");
    check_str("big.errno", "ENOMEM", errno == ENOMEM ? "ENOMEM" : strerror(errno));
    free(big);
    void *m = mmap(NULL, (size_t)(limit_mib + 1) * MIB, PROT_READ | PROT_WRITE,
                   MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    check_str("big.mmap", "ENOMEM",
              m != MAP_FAILED ? "mapped" : errno == ENOMEM ? "ENOMEM" : strerror(errno));
    if (m != MAP_FAILED)
        munmap(m, (size_t)(limit_mib + 1) * MIB);

    int n = 0;
    while (n < MAX_BLOCKS && (blocks[n] = malloc(MIB)) != NULL) {
        memset(blocks[n], 0x5a, MIB); /* the memory granted is really there */
        n++;
    }
    observe_int("fill.mib", n);
    check_str("fill.errno", "ENOMEM", errno == ENOMEM ? "ENOMEM" : strerror(errno));

    /* The APEX library's storage for a process stack comes from the same budget. */
    PROCESS_ATTRIBUTE_TYPE a =
        process_attributes("late", tick, 10, INFINITE_TIME_VALUE, INFINITE_TIME_VALUE);
    a.STACK_SIZE = 2 * MIB;
    PROCESS_ID_TYPE id;
    RETURN_CODE_TYPE rc;
    CREATE_PROCESS(&a, &id, &rc);
    check_rc("full.create_process", INVALID_CONFIG, rc);

    for (int i = 0; i < n; i++)
        free(blocks[i]);
    void *again = malloc((size_t)(limit_mib / 2) * MIB);
    check_true("after_free.malloc", again != NULL);
    if (again)
        memset(again, 1, (size_t)(limit_mib / 2) * MIB);
    free(again);
}

int main(int argc, char **argv)
{
    long limit_mib = argc > 1 ? strtol(argv[1], NULL, 10) : 0;
    if (limit_mib > 0) {
        limited(limit_mib);
    } else {
        /* No Partition_Memory: no limit (well past the other partition's). */
        void *p = malloc(96 * MIB);
        check_true("unlimited.malloc", p != NULL);
        if (p)
            memset(p, 1, 96 * MIB);
        free(p);
    }
    PARTITION_STATUS_TYPE st;
    RETURN_CODE_TYPE rc;
    GET_PARTITION_STATUS(&st, &rc);
    start_new_process("tick", tick, 10, st.PERIOD);
    enter_normal();
    return 1;
}
