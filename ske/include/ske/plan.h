/* SPDX-License-Identifier: Apache-2.0 */
/* The cyclic plan of a module as a sequence of window activations in module time. */
#ifndef SKE_PLAN_H
#define SKE_PLAN_H

#include <stdint.h>

#include "ske/config.h"

/* One activation of a window: frame k, window index i of the frame (in offset order) in the
 * module schedule that frame runs. */
typedef struct {
    int64_t frame;
    int schedule; /* index into the module's schedules */
    int index;
    const ske_window_cfg_t *window;
    int64_t start_ns; /* module time */
    int64_t end_ns;
} ske_slot_t;

/* The first activation (frame 0, first window of the initial schedule). */
void ske_plan_first(const ske_module_cfg_t *m, ske_slot_t *slot);
/* The activation after `slot`, wrapping to the next major frame in the same schedule. */
void ske_plan_next(const ske_module_cfg_t *m, ske_slot_t *slot);
/* At the start of a frame (index 0): run schedule `schedule` from this frame on. */
void ske_plan_switch(const ske_module_cfg_t *m, ske_slot_t *slot, int schedule);
/* The activation that holds module time t, or the next one to start after t (initial
 * schedule). */
void ske_plan_at(const ske_module_cfg_t *m, int64_t t, ske_slot_t *slot);
/* Window time per major frame given to partition `pi` in a schedule, and time given to
 * nobody; the _initial forms are for the initial schedule. */
int64_t ske_plan_partition_ns_in(const ske_module_cfg_t *m, int schedule, int pi);
int64_t ske_plan_partition_ns(const ske_module_cfg_t *m, int pi);
int64_t ske_plan_idle_ns(const ske_module_cfg_t *m);

#endif /* SKE_PLAN_H */
