/* SPDX-License-Identifier: Apache-2.0 */
/* Minimal assertion helpers of the C unit tests (the partitions', the CAN bus's, the DDS
 * agent's: nodes/CMakeLists.txt unit_check): count failures, print where. */
#ifndef RPAS_UNIT_CHECK_H
#define RPAS_UNIT_CHECK_H

#include <math.h>
#include <stdio.h>

static int unit_failures;

#define CHECK(cond)                                                                                \
    do {                                                                                           \
        if (!(cond)) {                                                                             \
            fprintf(stderr, "%s:%d: CHECK failed: %s\n", __FILE__, __LINE__, #cond);               \
            unit_failures++;                                                                         \
        }                                                                                          \
    } while (0)

#define CHECK_NEAR(a, b, tol)                                                                      \
    do {                                                                                           \
        double a_ = (a), b_ = (b);                                                                 \
        if (!(fabs(a_ - b_) <= (tol))) {                                                           \
            fprintf(stderr, "%s:%d: CHECK_NEAR failed: %s = %.6g, %s = %.6g (tol %g)\n", __FILE__, \
                    __LINE__, #a, a_, #b, b_, (double)(tol));                                      \
            unit_failures++;                                                                         \
        }                                                                                          \
    } while (0)

#define RUN(test)                                                                                  \
    do {                                                                                           \
        int before_ = unit_failures;                                                                 \
        test();                                                                                    \
        printf("%s %s\n", unit_failures == before_ ? "ok  " : "FAIL", #test);                        \
    } while (0)

#define UNIT_RESULT() (unit_failures ? (fprintf(stderr, "%d check(s) failed\n", unit_failures), 1) : 0)

#endif /* RPAS_UNIT_CHECK_H */
