/* SPDX-License-Identifier: Apache-2.0 */
/* Checks of the DDS agent's unit tests: a failed one is reported with its place and counted. */
#ifndef DDS_TEST_H
#define DDS_TEST_H

#include <stdio.h>

static int failures;

#define CHECK(cond)                                                                           \
    do {                                                                                      \
        if (!(cond)) {                                                                        \
            fprintf(stderr, "%s:%d: check failed: %s\n", __FILE__, __LINE__, #cond);          \
            failures++;                                                                       \
        }                                                                                     \
    } while (0)

#endif
