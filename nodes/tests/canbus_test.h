/* SPDX-License-Identifier: Apache-2.0 */
/* Checks of the CAN bus tests: a failed one is reported with its place and counted. */
#ifndef CANBUS_TEST_H
#define CANBUS_TEST_H

#include <inttypes.h>
#include <stdio.h>

#include "rpas/unit_check.h"

#define CHECK_EQ(a, e)                                                                        \
    do {                                                                                      \
        intmax_t a_ = (intmax_t)(a), e_ = (intmax_t)(e);                                      \
        if (a_ != e_) {                                                                       \
            fprintf(stderr, "%s:%d: %s == %s: got %jd, expected %jd\n", __FILE__, __LINE__,   \
                    #a, #e, a_, e_);                                                          \
            unit_failures++;                                                                  \
        }                                                                                     \
    } while (0)

#endif
