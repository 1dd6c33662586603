/* SPDX-License-Identifier: Apache-2.0 */
/* Checks of the health monitor's unit tests: a failed one is reported with its place and
 * counted; the test program (test_hm.c) runs every file's tests. */
#ifndef HM_TEST_H
#define HM_TEST_H

#include <stdio.h>

extern int hm_test_failures;

#define CHECK(c)                                                                              \
    do {                                                                                      \
        if (!(c)) {                                                                           \
            fprintf(stderr, "%s:%d: check failed: %s\n", __FILE__, __LINE__, #c);             \
            hm_test_failures++;                                                               \
        }                                                                                     \
    } while (0)

/* test_hm_decide.c: hm_decide over the whole table. */
void hm_test_decide(void);

#endif /* HM_TEST_H */
