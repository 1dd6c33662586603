/* SPDX-License-Identifier: Apache-2.0 */
/* Minimal assertion helpers of the nav_fcs unit tests: count failures, print where. */
#ifndef NF_TEST_H
#define NF_TEST_H

#include <math.h>
#include <stdio.h>

static int nf_failures;

#define CHECK(cond)                                                                                \
    do {                                                                                           \
        if (!(cond)) {                                                                             \
            fprintf(stderr, "%s:%d: CHECK failed: %s\n", __FILE__, __LINE__, #cond);               \
            nf_failures++;                                                                         \
        }                                                                                          \
    } while (0)

#define CHECK_NEAR(a, b, tol)                                                                      \
    do {                                                                                           \
        double a_ = (a), b_ = (b);                                                                 \
        if (!(fabs(a_ - b_) <= (tol))) {                                                           \
            fprintf(stderr, "%s:%d: CHECK_NEAR failed: %s = %.6g, %s = %.6g (tol %g)\n", __FILE__, \
                    __LINE__, #a, a_, #b, b_, (double)(tol));                                      \
            nf_failures++;                                                                         \
        }                                                                                          \
    } while (0)

#define RUN(test)                                                                                  \
    do {                                                                                           \
        int before_ = nf_failures;                                                                 \
        test();                                                                                    \
        printf("%s %s\n", nf_failures == before_ ? "ok  " : "FAIL", #test);                        \
    } while (0)

#define NF_TEST_RESULT() (nf_failures ? (fprintf(stderr, "%d check(s) failed\n", nf_failures), 1) : 0)

#endif /* NF_TEST_H */
