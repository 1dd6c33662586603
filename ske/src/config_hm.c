/* SPDX-License-Identifier: Apache-2.0 */
/* The health-monitoring tables of the module XML (System_HM_Table, Module_HM_Table,
 * Partition_HM_Table), with the loader's rules on levels and actions. */
#include "ske__config.h"

#include <string.h>

/* Visits each Error_ID_Level/Error_ID_Action of a table: calls fn(L, entry, state, error). */
typedef void (*hm_entry_fn)(ske_loader_t *L, const xmlNode *e, hm_state_t st, hm_error_t err,
                            void *arg);

static void load_hm_table(ske_loader_t *L, const xmlNode *table, const char *entry_name,
                          hm_entry_fn fn, void *arg)
{
    bool seen[HM_STATE_COUNT][HM_ERR_COUNT] = {{false}};
    for (const xmlNode *sse = table->children; sse && !L->failed; sse = sse->next) {
        if (!ske__is_elem(sse, "System_State_Entry", false))
            continue;
        uint64_t st;
        if (!ske__attr_u64(L, sse, "SystemState", &st, HM_STATE_COUNT - 1, true))
            return;
        for (const xmlNode *e = sse->children; e && !L->failed; e = e->next) {
            if (!ske__is_elem(e, entry_name, false))
                continue;
            uint64_t id;
            if (!ske__attr_u64(L, e, "ErrorIdentifier", &id, HM_ERR_COUNT - 1, true))
                return;
            if (id == 0) {
                ske__fail(L, e, "error identifiers are 1 to 10",
                          "ErrorIdentifier=0 is not an error");
                return;
            }
            if (seen[st][id]) {
                ske__fail(L, e, "one entry per error and system state",
                          "ErrorIdentifier=%llu (%s) appears twice in SystemState %llu",
                          (unsigned long long)id, hm_error_name((hm_error_t)id),
                          (unsigned long long)st);
                return;
            }
            seen[st][id] = true;
            fn(L, e, (hm_state_t)st, (hm_error_t)id, arg);
        }
    }
}

static void system_entry(ske_loader_t *L, const xmlNode *e, hm_state_t st, hm_error_t err,
                         void *arg)
{
    (void)arg;
    char buf[32] = "";
    hm_level_t level;
    ske__attr(e, "ErrorLevel", buf, sizeof buf);
    if (!hm_level_parse(buf, &level)) {
        ske__fail(L, e, "ErrorLevel is MODULE, PARTITION or PROCESS", "ErrorLevel='%s'", buf);
        return;
    }
    if (level == HM_LEVEL_PROCESS &&
        (err == HM_ERR_WINDOW_OVERRUN || err == HM_ERR_PARTITION_EXIT ||
         st == HM_STATE_MODULE_INIT || st == HM_STATE_PARTITION_INIT ||
         st == HM_STATE_ERROR_HANDLER)) {
        ske__fail(L, e, "process level needs a process that can go on",
                  "%s in state %s cannot be handled at PROCESS level (no ARINC process whose error "
                  "handler could act)", hm_error_name(err), hm_state_name(st));
        return;
    }
    char code[32];
    hm_error_t named;
    if (ske__attr(e, "ErrorCode", code, sizeof code) && hm_error_parse(code, &named) &&
        hm_apex_error_code(named) != hm_apex_error_code(err)) {
        ske__fail(L, e, "ErrorCode agrees with ErrorIdentifier",
                  "ErrorIdentifier=%d is %s, but ErrorCode says %s", (int)err, hm_error_name(err),
                  code);
        return;
    }
    L->m->hm.level[st][err] = (uint8_t)level;
}

static void module_entry(ske_loader_t *L, const xmlNode *e, hm_state_t st, hm_error_t err,
                         void *arg)
{
    (void)arg;
    char buf[32] = "";
    hm_action_t act;
    ske__attr(e, "Action", buf, sizeof buf);
    if (!hm_action_parse(buf, &act) ||
        (act != HM_ACT_IGNORE && act != HM_ACT_SHUTDOWN && act != HM_ACT_RESET)) {
        ske__fail(L, e, "module actions are IGNORE, SHUTDOWN or RESET", "Action='%s'", buf);
        return;
    }
    L->m->hm.module_action[st][err] = (uint8_t)act;
}

static void partition_entry(ske_loader_t *L, const xmlNode *e, hm_state_t st, hm_error_t err,
                            void *arg)
{
    ske_partition_cfg_t *p = arg;
    char buf[32] = "";
    hm_action_t act;
    ske__attr(e, "Action", buf, sizeof buf);
    if (!hm_action_parse(buf, &act) || act > HM_ACT_COLD_START) {
        ske__fail(L, e, "partition actions are IGNORE, IDLE, WARM_START or COLD_START",
                  "Action='%s'", buf);
        return;
    }
    p->hm.action[st][err] = (uint8_t)act;
}

void ske__load_system_hm(ske_loader_t *L, const xmlNode *n)
{
    load_hm_table(L, n, "Error_ID_Level", system_entry, NULL);
}

void ske__load_module_hm(ske_loader_t *L, const xmlNode *n)
{
    load_hm_table(L, n, "Error_ID_Action", module_entry, NULL);
}

void ske__load_partition_hm(ske_loader_t *L, const xmlNode *n, bool seen[])
{
    int pi = ske__partition_ref(L, n);
    if (pi < 0)
        return;
    if (seen[pi]) {
        ske__fail(L, n, "one Partition_HM_Table per partition", "partition '%s' has a second "
                  "Partition_HM_Table", L->m->partitions[pi].name);
        return;
    }
    seen[pi] = true;
    load_hm_table(L, n, "Error_ID_Action", partition_entry, &L->m->partitions[pi]);
}
