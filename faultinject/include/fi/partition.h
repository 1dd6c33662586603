/* SPDX-License-Identifier: Apache-2.0 */
/* The misbehaviours a partition can be made to commit, each done for real in the calling
 * process (a signal, a spin, a denied system call, ...), so that whatever detects it in the
 * product detects a real event. Shared by the APEX library's fault hook and the rogue example
 * partition. C library and Linux only: nothing here knows the APEX services; those that need
 * one (a queue flood) take it as a function. */
#ifndef FI_PARTITION_H
#define FI_PARTITION_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* The process ends at once as a crash would: abort(), SIGABRT, uncaught. Never returns. */
void fi_crash(void) __attribute__((noreturn));

/* A write to address 0x10, which no partition owns: SIGSEGV. Returns only if the write
 * did not fault (a handler that resumed). */
void fi_memory_violation(void);

/* A write of one byte to `addr` (the byte read there first, so that a writable address is
 * left as it was): on a read-only mapping, SIGSEGV. */
void fi_write_byte(volatile void *addr);

/* The start of the first read-only mapping of port memory the SKE gave the partition (a
 * destination port), found in /proc/self/maps; NULL if none, or if the file cannot be read
 * (only a system partition may open it). */
void *fi_readonly_port_mapping(void);

/* An integer division by zero: SIGFPE. */
void fi_numeric_error(void);

/* Recursion with 1 KiB frames until the stack's guard page: SIGSEGV there. Returns a value
 * only to keep the recursion from being optimised away; never in practice. */
int fi_stack_overflow(void);

/* Spins on the CPU for ever. Never returns. */
void fi_spin_forever(void) __attribute__((noreturn));

/* Spins until the calling process has used `ns` more nanoseconds of CPU time (its CPU clock:
 * time it is stopped does not count). Returns the CPU time used, or -1 if the clock failed. */
int64_t fi_spin_cpu(int64_t ns);

/* A system call the partitions' sandbox denies: socket() for a partition that may not do
 * I/O, kill(parent, 0) for a system partition (a signal to another process; signal 0 only
 * asks whether it could be sent). Returns the call's result if it was allowed after all. */
long fi_illegal_request(bool system_partition);
/* fork(): denied to every partition. The child, if ever there is one, exits at once. */
long fi_fork(void);
/* kill(getppid(), SIGKILL): the SKE, or whoever the parent is. Denied to every partition. */
long fi_kill_parent(void);

/* Allocates 1 MiB blocks (untouched) until malloc refuses: the memory limit is reached.
 * Keeps them (a leak, as a careless program would). Returns the MiB obtained; stops at
 * `max_mib` if the limit is not reached by then (0: no bound). */
size_t fi_exhaust_memory(size_t max_mib);
/* What a careless program does next: writes through the null pointer malloc returned:
 * SIGSEGV near address 0. */
void fi_write_through_null(void);

/* Corrupts a message in place: every byte XOR 0x5A. */
void fi_corrupt_bytes(void *buf, size_t len);

/* One send of a flood: true if the message was taken, false if refused (queue full). */
typedef bool (*fi_send_fn)(void *ctx);
typedef struct {
    int sent;
    int refused;
} fi_flood_result_t;
/* Sends `attempts` times as fast as it can; with `stop_when_full`, stops at the first
 * refusal. */
fi_flood_result_t fi_flood(fi_send_fn send, void *ctx, int attempts, bool stop_when_full);

#ifdef __cplusplus
}
#endif

#endif /* FI_PARTITION_H */
