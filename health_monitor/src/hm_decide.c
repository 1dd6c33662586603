/* SPDX-License-Identifier: Apache-2.0 */
/* The health monitor's decision on one error, from the tables: level, action, and why it
 * departs from the tables when it does (ARINC 653 Part 1, 2.4.2). */
#include "hm/hm.h"

/* The texts are those of the trace's `note` (hm events) and `hm_note` events. */
static const char note_escalated[] =
    "no process-level handling possible: escalated to the partition level";
static const char note_partition_idled[] =
    "IGNORE requested, but the failed initialisation cannot go on: the partition is idled";
static const char note_module_idled[] =
    "module IGNORE, but the failed initialisation cannot go on: the partition is idled";

hm_decision_t hm_decide(const hm_system_table_t *sys, const hm_partition_table_t *part,
                        hm_state_t state, hm_error_t err, hm_origin_t origin,
                        bool has_error_handler, bool fatal_context)
{
    hm_decision_t d = {.level = hm_level_of(sys, state, err),
                       .action = HM_ACT_IGNORE,
                       .partition_action = HM_ACT_IGNORE};
    if (d.level == HM_LEVEL_PROCESS) {
        /* Only the errors of the partition's processes go to its error handler; the
         * handler's own, the initialisation's and those the SKE detects cannot (2.4.2.3). */
        if (has_error_handler && origin == HM_ORIGIN_PROCESS) {
            d.action = HM_ACT_ERROR_HANDLER;
            return d;
        }
        d.level = HM_LEVEL_PARTITION;
        d.flags |= HM_DECIDE_ESCALATED;
        d.note = note_escalated;
    }
    if (d.level == HM_LEVEL_MODULE) {
        d.action = hm_module_action(sys, state, err);
        /* SHUTDOWN and RESET act on every partition; IGNORE leaves the failed one to go on,
         * which a context that cannot go on would not. */
        if (d.action == HM_ACT_IGNORE && fatal_context) {
            d.partition_action = HM_ACT_IDLE;
            d.flags |= HM_DECIDE_CANNOT_GO_ON;
            d.note = note_module_idled;
        }
        return d;
    }
    hm_partition_table_t defaults;
    if (!part) {
        hm_partition_defaults(&defaults);
        part = &defaults;
    }
    d.action = hm_partition_action(part, state, err);
    if (d.action == HM_ACT_IGNORE && fatal_context) {
        d.action = HM_ACT_IDLE;
        d.flags |= HM_DECIDE_CANNOT_GO_ON;
        d.note = note_partition_idled;
    }
    d.partition_action = d.action;
    return d;
}
