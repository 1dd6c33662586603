/* SPDX-License-Identifier: Apache-2.0 */
/* Minimal checks for the SKE unit tests, with no framework: a failed check prints
 * file:line, the expression and both values; the program's exit status counts failures. */
#ifndef SKE_TEST_H
#define SKE_TEST_H

#include <inttypes.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

/* One counter per test program (each program includes this header from one file). */
static int ske_test_failures;

static inline void ske_test_fail_(const char *file, int line, const char *what)
{
    fprintf(stderr, "%s:%d: check failed: %s\n", file, line, what);
    ske_test_failures++;
}

/* CHECK keeps going; REQUIRE returns from the (void) test function, for checks that later
 * ones depend on (a NULL module, a file that could not be written). */
#define CHECK(cond)                                                                           \
    do {                                                                                      \
        if (!(cond))                                                                          \
            ske_test_fail_(__FILE__, __LINE__, #cond);                                        \
    } while (0)

#define REQUIRE(cond)                                                                         \
    do {                                                                                      \
        if (!(cond)) {                                                                        \
            ske_test_fail_(__FILE__, __LINE__, #cond);                                        \
            return;                                                                           \
        }                                                                                     \
    } while (0)

/* Signed integers (any width up to 64 bits). */
#define CHECK_EQ(actual, expected)                                                            \
    do {                                                                                      \
        intmax_t ske_a_ = (intmax_t)(actual), ske_e_ = (intmax_t)(expected);                  \
        if (ske_a_ != ske_e_) {                                                               \
            fprintf(stderr, "%s:%d: check failed: %s == %s: got %jd, expected %jd\n",         \
                    __FILE__, __LINE__, #actual, #expected, ske_a_, ske_e_);                  \
            ske_test_failures++;                                                              \
        }                                                                                     \
    } while (0)

/* Unsigned integers and sizes. */
#define CHECK_EQ_U(actual, expected)                                                          \
    do {                                                                                      \
        uintmax_t ske_a_ = (uintmax_t)(actual), ske_e_ = (uintmax_t)(expected);               \
        if (ske_a_ != ske_e_) {                                                               \
            fprintf(stderr, "%s:%d: check failed: %s == %s: got %ju, expected %ju\n",         \
                    __FILE__, __LINE__, #actual, #expected, ske_a_, ske_e_);                  \
            ske_test_failures++;                                                              \
        }                                                                                     \
    } while (0)

#define CHECK_STR(actual, expected)                                                           \
    do {                                                                                      \
        const char *ske_a_ = (actual), *ske_e_ = (expected);                                  \
        if (!ske_a_ || strcmp(ske_a_, ske_e_) != 0) {                                         \
            fprintf(stderr, "%s:%d: check failed: %s == \"%s\": got \"%s\"\n", __FILE__,      \
                    __LINE__, #actual, ske_e_, ske_a_ ? ske_a_ : "(null)");                   \
            ske_test_failures++;                                                              \
        }                                                                                     \
    } while (0)

#define CHECK_CONTAINS(haystack, needle)                                                      \
    do {                                                                                      \
        const char *ske_h_ = (haystack), *ske_n_ = (needle);                                  \
        if (!ske_h_ || !strstr(ske_h_, ske_n_)) {                                             \
            fprintf(stderr, "%s:%d: check failed: %s contains \"%s\": got \"%s\"\n",          \
                    __FILE__, __LINE__, #haystack, ske_n_, ske_h_ ? ske_h_ : "(null)");       \
            ske_test_failures++;                                                              \
        }                                                                                     \
    } while (0)

/* Runs one test function and says which one failed. */
#define RUN(test)                                                                             \
    do {                                                                                      \
        int ske_before_ = ske_test_failures;                                                  \
        test();                                                                               \
        printf("%s %s\n", ske_test_failures == ske_before_ ? "ok  " : "FAIL", #test);         \
        fflush(stdout); /* in order with the failures on stderr */                            \
    } while (0)

static inline int ske_test_result(void)
{
    if (ske_test_failures)
        fprintf(stderr, "%d check(s) failed\n", ske_test_failures);
    return ske_test_failures ? 1 : 0;
}

#endif /* SKE_TEST_H */
