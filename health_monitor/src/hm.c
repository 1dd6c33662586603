/* SPDX-License-Identifier: Apache-2.0 */
/* ARINC 653 health-monitoring tables: defaults, look-ups and names. */
#include "hm/hm.h"

#include <string.h>

static bool valid(hm_state_t s, hm_error_t e)
{
    return (unsigned)s < HM_STATE_COUNT && e >= 1 && e < HM_ERR_COUNT;
}

void hm_system_defaults(hm_system_table_t *t)
{
    memset(t, 0, sizeof *t);
    for (int s = 0; s < HM_STATE_COUNT; s++)
        for (int e = 1; e < HM_ERR_COUNT; e++) {
            t->level[s][e] = HM_LEVEL_PARTITION;
            t->module_action[s][e] = HM_ACT_IGNORE;
        }
}

void hm_partition_defaults(hm_partition_table_t *t)
{
    for (int s = 0; s < HM_STATE_COUNT; s++)
        for (int e = 0; e < HM_ERR_COUNT; e++)
            t->action[s][e] = e == HM_ERR_WINDOW_OVERRUN || e == HM_ERR_DEADLINE_MISSED
                                  ? HM_ACT_IGNORE
                                  : HM_ACT_IDLE;
}

hm_level_t hm_level_of(const hm_system_table_t *t, hm_state_t state, hm_error_t err)
{
    if (!valid(state, err))
        return HM_LEVEL_PARTITION;
    uint8_t l = t->level[state][err];
    return l <= HM_LEVEL_PROCESS ? (hm_level_t)l : HM_LEVEL_PARTITION;
}

hm_action_t hm_module_action(const hm_system_table_t *t, hm_state_t state, hm_error_t err)
{
    if (!valid(state, err))
        return HM_ACT_IGNORE;
    uint8_t a = t->module_action[state][err];
    return a == HM_ACT_SHUTDOWN || a == HM_ACT_RESET ? (hm_action_t)a : HM_ACT_IGNORE;
}

hm_action_t hm_partition_action(const hm_partition_table_t *t, hm_state_t state, hm_error_t err)
{
    if (!valid(state, err))
        return HM_ACT_IDLE;
    uint8_t a = t->action[state][err];
    return a <= HM_ACT_COLD_START ? (hm_action_t)a : HM_ACT_IDLE;
}

static const char *const error_names[HM_ERR_COUNT] = {
    NULL, "DEADLINE_MISSED", "APPLICATION_ERROR", "NUMERIC_ERROR", "ILLEGAL_REQUEST",
    "STACK_OVERFLOW", "MEMORY_VIOLATION", "HARDWARE_FAULT", "POWER_FAIL", "WINDOW_OVERRUN",
    "PARTITION_EXIT",
};
static const char *const state_names[HM_STATE_COUNT] = {
    "MODULE_INIT", "PARTITION_INIT", "PROCESS", "ERROR_HANDLER",
};
static const char *const level_names[] = {"MODULE", "PARTITION", "PROCESS"};
static const char *const action_names[] = {
    "IGNORE", "IDLE", "WARM_START", "COLD_START", "SHUTDOWN", "RESET", "ERROR_HANDLER",
};

const char *hm_error_name(hm_error_t err)
{
    return err >= 1 && err < HM_ERR_COUNT ? error_names[err] : NULL;
}

const char *hm_state_name(hm_state_t s) { return (unsigned)s < HM_STATE_COUNT ? state_names[s] : NULL; }

const char *hm_level_name(hm_level_t l) { return (unsigned)l <= HM_LEVEL_PROCESS ? level_names[l] : NULL; }

const char *hm_action_name(hm_action_t a)
{
    return (unsigned)a <= HM_ACT_ERROR_HANDLER ? action_names[a] : NULL;
}

bool hm_level_parse(const char *s, hm_level_t *out)
{
    for (int i = 0; i <= HM_LEVEL_PROCESS; i++)
        if (strcmp(s, level_names[i]) == 0) {
            *out = (hm_level_t)i;
            return true;
        }
    return false;
}

bool hm_action_parse(const char *s, hm_action_t *out)
{
    for (int i = 0; i <= HM_ACT_RESET; i++)
        if (strcmp(s, action_names[i]) == 0) {
            *out = (hm_action_t)i;
            return true;
        }
    return false;
}

bool hm_error_parse(const char *s, hm_error_t *out)
{
    for (int i = 1; i < HM_ERR_COUNT; i++)
        if (strcmp(s, error_names[i]) == 0) {
            *out = (hm_error_t)i;
            return true;
        }
    return false;
}

int hm_apex_error_code(hm_error_t err)
{
    /* ERROR_CODE_TYPE: DEADLINE_MISSED 0, APPLICATION_ERROR 1, NUMERIC_ERROR 2, ILLEGAL_REQUEST 3,
     * STACK_OVERFLOW 4, MEMORY_VIOLATION 5, HARDWARE_FAULT 6, POWER_FAIL 7. */
    switch (err) {
    case HM_ERR_WINDOW_OVERRUN: return 0; /* a window's time is the partition's deadline */
    case HM_ERR_PARTITION_EXIT: return 6; /* HARDWARE_FAULT: the standard has no code for an end */
    default: return err >= 1 && err <= HM_ERR_POWER_FAIL ? (int)err - 1 : 6;
    }
}
