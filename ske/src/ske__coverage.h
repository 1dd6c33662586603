/* SPDX-License-Identifier: Apache-2.0 */
/* A partition's gcov counters in coverage builds (cmake -DIMA_COVERAGE=ON); nothing at all in
 * normal builds. */
#ifndef SKE__COVERAGE_H
#define SKE__COVERAGE_H

#include <sys/types.h>

#ifdef IMA_COVERAGE
/* Asks the partition's process to write its counters and exit, and waits (briefly) until it
 * has; the caller kills and reaps it as always. */
void ske__coverage_dump(pid_t pid);
/* In a partition's process between fork and exec: forgets the counters copied from ima-ske
 * (counted by ima-ske itself), then writes what the child ran before its exec or _exit, which
 * would otherwise lose it. */
void ske__coverage_child_start(void);
void ske__coverage_child_flush(void);
#else
static inline void ske__coverage_dump(pid_t pid) { (void)pid; }
static inline void ske__coverage_child_start(void) {}
static inline void ske__coverage_child_flush(void) {}
#endif

#endif /* SKE__COVERAGE_H */
