/* SPDX-License-Identifier: Apache-2.0 */
/* Checks of the nodes' C unit tests (the CAN bus's, the DDS agent's): a failed one is reported
 * with its place and counted. */
#ifndef NODES_UNIT_CHECK_H
#define NODES_UNIT_CHECK_H

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
