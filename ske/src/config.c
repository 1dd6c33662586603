/* SPDX-License-Identifier: Apache-2.0 */
/* Loads an ARINC 653 module XML: schema validation through libxml2, then the rules of the
 * standard that a schema cannot say (schedule fits the major frame, channels agree, ...).
 * This file reads partitions, their ports, memory and programs, and the module as a whole;
 * config_xml.c, config_schedule.c, config_channels.c and config_hm.c do the rest. */
#include "ske__config.h"

#include <errno.h>
#include <libgen.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <libxml/parser.h>

/* ---- elements ------------------------------------------------------------------------- */

static void split_args(ske_loader_t *L, const xmlNode *n, ske_partition_cfg_t *p, const char *args)
{
    p->argv[0] = strdup(p->name);
    p->argc = 1;
    if (!args)
        return;
    char *copy = strdup(args), *save = NULL;
    for (char *tok = strtok_r(copy, " \t\n", &save); tok; tok = strtok_r(NULL, " \t\n", &save)) {
        if (p->argc >= SKE_MAX_ARGS - 1) {
            ske__fail(L, n, "at most 30 arguments", "too many Arguments for partition '%s'",
                      p->name);
            break;
        }
        p->argv[p->argc++] = strdup(tok);
    }
    free(copy);
}

static void load_port(ske_loader_t *L, const xmlNode *n, ske_partition_cfg_t *p,
                      ske_port_kind_t kind)
{
    if (p->n_ports >= SKE_MAX_PORTS) {
        ske__fail(L, n, "at most 64 ports per partition", "too many ports in partition '%s'",
                  p->name);
        return;
    }
    ske_port_cfg_t *port = &p->ports[p->n_ports];
    memset(port, 0, sizeof *port);
    port->kind = kind;
    port->channel = -1;
    port->line = ske__line_of(L, n);
    if (!ske__attr_name(L, n, "Name", port->name))
        return;
    if (ske_config_port_by_name(p, port->name) >= 0) {
        ske__fail(L, n, "port names are unique within a partition",
                  "partition '%s' declares port '%s' twice", p->name, port->name);
        return;
    }
    char dir[32] = "";
    ske__attr(n, "Direction", dir, sizeof dir);
    port->dir = strcmp(dir, "DESTINATION") == 0 ? SKE_DIR_DESTINATION : SKE_DIR_SOURCE;
    uint64_t v;
    if (ske__attr_u64(L, n, "MaxMessageSize", &v, 1u << 20, true)) {
        if (v == 0)
            ske__fail(L, n, "MaxMessageSize is positive", "MaxMessageSize must be at least 1");
        port->max_size = (uint32_t)v;
    }
    if (kind == SKE_PORT_SAMPLING) {
        if (ske__attr_seconds(L, n, "RefreshRateSeconds", &port->refresh_ns, true) &&
            port->refresh_ns == 0)
            ske__fail(L, n, "RefreshRateSeconds is positive",
                      "RefreshRateSeconds must be greater than 0");
    } else if (ske__attr_u64(L, n, "MaxNbMessages", &v, 1u << 20, true)) {
        if (v == 0)
            ske__fail(L, n, "MaxNbMessages is positive", "MaxNbMessages must be at least 1");
        port->max_nb = (uint32_t)v;
        if ((uint64_t)port->max_nb * port->max_size > SKE_PORT_BYTES_MAX)
            ske__fail(L, n, "a queuing port holds at most 64 MiB",
                      "MaxNbMessages=%u of %u bytes needs %llu MiB", port->max_nb, port->max_size,
                      (unsigned long long)((uint64_t)port->max_nb * port->max_size >> 20));
    }
    p->n_ports++;
}

static void load_partition(ske_loader_t *L, const xmlNode *n)
{
    ske_module_cfg_t *m = L->m;
    if (m->n_partitions >= SKE_MAX_PARTITIONS) {
        ske__fail(L, n, "at most 32 partitions", "too many partitions");
        return;
    }
    ske_partition_cfg_t *p = &m->partitions[m->n_partitions];
    memset(p, 0, sizeof *p);
    hm_partition_defaults(&p->hm);
    p->line = ske__line_of(L, n);
    uint64_t id;
    if (!ske__attr_u64(L, n, "PartitionIdentifier", &id, INT32_MAX, true) ||
        !ske__attr_name(L, n, "PartitionName", p->name))
        return;
    p->id = (int32_t)id;
    for (int i = 0; i < m->n_partitions; i++) {
        if (m->partitions[i].id == p->id)
            ske__fail(L, n, "partition identifiers are unique",
                      "PartitionIdentifier=%d is already used by partition '%s' (line %d)", p->id,
                      m->partitions[i].name, m->partitions[i].line);
        else if (strcmp(m->partitions[i].name, p->name) == 0)
            ske__fail(L, n, "partition names are unique",
                      "PartitionName='%s' is already used (line %d)", p->name,
                      m->partitions[i].line);
    }
    if (!ske__attr(n, "Criticality", p->criticality, sizeof p->criticality))
        snprintf(p->criticality, sizeof p->criticality, "LEVEL_E");
    p->system_partition = ske__attr_bool(n, "SystemPartition", false);
    xmlChar *sch = xmlGetNsProp(n, (const xmlChar *)"ScheduleChange", (const xmlChar *)SKE_EXT_NS);
    p->schedule_change =
        sch && (strcmp((const char *)sch, "true") == 0 || strcmp((const char *)sch, "1") == 0);
    if (sch)
        xmlFree(sch);
    ske__attr(n, "EntryPoint", p->entry_point, sizeof p->entry_point);
    bool have_linux = false;
    for (const xmlNode *c = n->children; c; c = c->next) {
        if (ske__is_elem(c, "Sampling_Port", false))
            load_port(L, c, p, SKE_PORT_SAMPLING);
        else if (ske__is_elem(c, "Queuing_Port", false))
            load_port(L, c, p, SKE_PORT_QUEUING);
        else if (ske__is_elem(c, "Process", false)) {
            if (p->n_processes < SKE_MAX_PORTS) {
                ske_process_cfg_t *pr = &p->processes[p->n_processes++];
                pr->line = ske__line_of(L, c);
                ske__attr_name(L, c, "Name", pr->name);
                uint64_t ss = 0;
                if (ske__attr_u64(L, c, "StackSize", &ss, UINT32_MAX, false))
                    pr->stack_size = (uint32_t)ss;
            }
        } else if (ske__is_elem(c, "Linux", true)) {
            if (have_linux) {
                ske__fail(L, c, "each Partition has one ima:Linux element",
                          "partition '%s' names its program twice", p->name);
                continue;
            }
            have_linux = true;
            ske__attr(c, "Executable", p->exe_name, sizeof p->exe_name);
            ske__attr(c, "OutputFile", p->output_file, sizeof p->output_file);
            ske__attr(c, "HealthMonitorLogPort", p->hm_log_port_name,
                      sizeof p->hm_log_port_name);
            char args[2048];
            split_args(L, c, p, ske__attr(c, "Arguments", args, sizeof args) ? args : NULL);
        }
    }
    if (!have_linux)
        ske__fail(L, n, "each Partition has an ima:Linux element",
                  "partition '%s' does not say which program runs it (ima:Linux Executable=...)",
                  p->name);
    m->n_partitions++;
}

static void load_memory(ske_loader_t *L, const xmlNode *n)
{
    int pi = ske__partition_ref(L, n);
    if (pi < 0)
        return;
    ske_partition_cfg_t *p = &L->m->partitions[pi];
    for (const xmlNode *c = n->children; c; c = c->next) {
        if (!ske__is_elem(c, "Memory_Requirements", false))
            continue;
        uint64_t sz;
        if (!ske__attr_u64(L, c, "SizeBytes", &sz, (uint64_t)1 << 40, true))
            continue;
        if (sz == 0) {
            /* (a limit of 0 would mean none at all) */
            ske__fail(L, c, "a memory requirement is at least one byte",
                      "SizeBytes=\"0\": a requirement of no memory");
            continue;
        }
        p->memory_bytes += sz;
    }
}

/* ima:Linux HealthMonitorLogPort names one of the partition's own destination queuing
 * ports, connected to no channel (the SKE is its source), large enough for a decision. */
static void check_hm_log_port(ske_loader_t *L, ske_partition_cfg_t *p)
{
    p->hm_log_port = -1;
    if (!p->hm_log_port_name[0])
        return;
    const char *rule = "the health-monitor log port is one of the partition's destination "
                       "queuing ports, on no channel, of at least the size of a decision";
    for (int k = 0; k < p->n_ports; k++) {
        const ske_port_cfg_t *pc = &p->ports[k];
        if (strcmp(pc->name, p->hm_log_port_name) != 0)
            continue;
        if (pc->kind != SKE_PORT_QUEUING || pc->dir != SKE_DIR_DESTINATION || pc->channel >= 0 ||
            pc->max_size < sizeof(ske_hm_log_t)) {
            ske__diag_set(L->diag, L->m->path, pc->line, "Queuing_Port", rule,
                          "partition '%s': HealthMonitorLogPort '%s' must be a destination "
                          "queuing port on no channel with MaxMessageSize of at least %zu",
                          p->name, pc->name, sizeof(ske_hm_log_t));
            L->failed = true;
            return;
        }
        p->hm_log_port = k;
        return;
    }
    ske__diag_set(L->diag, L->m->path, p->line, "Partition", rule,
                  "partition '%s': HealthMonitorLogPort '%s' is not one of its ports", p->name,
                  p->hm_log_port_name);
    L->failed = true;
}

/* Bare names are looked up in the partition path; names with a slash are relative to the
 * module file's folder. */
static void resolve_executable(ske_loader_t *L, ske_partition_cfg_t *p)
{
    char cand[2 * SKE_PATH_MAX + 2];
    if (strchr(p->exe_name, '/')) {
        if (p->exe_name[0] == '/') {
            snprintf(cand, sizeof cand, "%s", p->exe_name);
        } else {
            char dir[SKE_PATH_MAX];
            snprintf(dir, sizeof dir, "%s", L->m->path);
            snprintf(cand, sizeof cand, "%s/%s", dirname(dir), p->exe_name);
        }
        if (access(cand, X_OK) == 0 && realpath(cand, p->executable))
            return;
    } else {
        const char *path = L->opts && L->opts->partition_path ? L->opts->partition_path : "";
        char *copy = strdup(path), *save = NULL;
        for (char *d = strtok_r(copy, ":", &save); d; d = strtok_r(NULL, ":", &save)) {
            snprintf(cand, sizeof cand, "%s/%s", d, p->exe_name);
            if (access(cand, X_OK) == 0 && realpath(cand, p->executable)) {
                free(copy);
                return;
            }
        }
        free(copy);
    }
    L->failed = false;
    ske__diag_set(L->diag, L->m->path, p->line, "Partition", "the partition's program exists",
                  "partition '%s': executable '%s' not found%s%s", p->name, p->exe_name,
                  strchr(p->exe_name, '/') ? "" : " in the partition path ",
                  strchr(p->exe_name, '/') ? "" :
                  (L->opts && L->opts->partition_path ? L->opts->partition_path : "(empty)"));
    L->failed = true;
}

/* ---- modules -------------------------------------------------------------------------- */

static void load_module(ske_loader_t *L, xmlNode *root)
{
    ske_module_cfg_t *m = L->m;
    char name[256];
    if (!ske__attr(root, "ModuleName", name, sizeof name) || !name[0] ||
        strlen(name) >= sizeof m->module_name) {
        ske__fail(L, root, "a module name of 1 to 63 characters",
                  "ModuleName is %s", name[0] ? "longer than 63 characters" : "empty");
        return;
    }
    memcpy(m->module_name, name, strlen(name) + 1);
    snprintf(m->node, sizeof m->node, "node1");
    m->time_mode = SKE_TIME_EMULATED;
    hm_system_defaults(&m->hm);
    const xmlNode *schedule = NULL;
    for (xmlNode *c = root->children; c && !L->failed; c = c->next) {
        if (ske__is_elem(c, "Module_Extension", true)) {
            char buf[SKE_NAME_MAX];
            if (ske__attr(c, "Node", buf, sizeof buf))
                snprintf(m->node, sizeof m->node, "%s", buf);
            if (ske__attr(c, "TimeMode", buf, sizeof buf) && strcmp(buf, "realtime") == 0)
                m->time_mode = SKE_TIME_REALTIME;
        } else if (ske__is_elem(c, "Partition", false)) {
            load_partition(L, c);
        }
    }
    for (xmlNode *c = root->children; c && !L->failed; c = c->next) {
        if (ske__is_elem(c, "Partition_Memory", false))
            load_memory(L, c);
        else if (ske__is_elem(c, "Module_Schedule", false)) {
            schedule = c;
            ske__load_schedule(L, c);
        }
    }
    if (!L->failed && schedule)
        ske__check_windows(L, schedule);
    bool hm_seen[SKE_MAX_PARTITIONS] = {false};
    for (xmlNode *c = root->children; c && !L->failed; c = c->next) {
        if (ske__is_elem(c, "System_HM_Table", false))
            ske__load_system_hm(L, c);
        else if (ske__is_elem(c, "Module_HM_Table", false))
            ske__load_module_hm(L, c);
        else if (ske__is_elem(c, "Partition_HM_Table", false))
            ske__load_partition_hm(L, c, hm_seen);
    }
    for (xmlNode *c = root->children; c && !L->failed; c = c->next) {
        if (!ske__is_elem(c, "Connection_Table", false))
            continue;
        for (xmlNode *ch = c->children; ch && !L->failed; ch = ch->next)
            if (ske__is_elem(ch, "Channel", false))
                ske__load_channel(L, ch);
    }
    for (int i = 0; i < m->n_partitions && !L->failed; i++)
        check_hm_log_port(L, &m->partitions[i]);
    if (L->failed || !(L->opts && L->opts->resolve_executables))
        return;
    for (int i = 0; i < m->n_partitions && !L->failed; i++)
        resolve_executable(L, &m->partitions[i]);
}

int ske_config_load(const char *path, const ske_load_opts_t *opts, ske_module_cfg_t **out,
                    ske_diag_t *diag)
{
    memset(diag, 0, sizeof *diag);
    *out = NULL;
    ske_module_cfg_t *m = calloc(1, sizeof *m);
    if (!m)
        return SKE_E_NOMEM;
    snprintf(m->path, sizeof m->path, "%s", path);
    ske_loader_t L = {.m = m, .diag = diag, .opts = opts};
    ske__index_lines(&L);

    if (access(path, R_OK) != 0) {
        ske__diag_set(diag, path, 0, "", "", "cannot read the module: %s", strerror(errno));
        free(L.text);
        free(L.line_at);
        free(m);
        return SKE_E_IO;
    }
    /* Before the parser sees it: a bounded size, and no document type declaration. Module
     * files need no DTD; one could define entities that expand beyond any bound, so none is
     * processed at all. */
    if (L.too_big) {
        ske__diag_set(diag, path, 0, "", "a module file of at most 8 MiB",
                      "the module file is larger than 8 MiB");
        free(L.text);
        free(L.line_at);
        free(m);
        return SKE_E_CONFIG;
    }
    const char *dtd = L.text ? memmem(L.text, L.text_len, "<!DOCTYPE", 9) : NULL;
    if (dtd) {
        int line = 1;
        for (const char *q = L.text; q < dtd; q++)
            line += *q == '\n';
        ske__diag_set(diag, path, line, "", "no document type declaration",
                      "a DOCTYPE: module files need no DTD, and the SKE processes none");
        free(L.text);
        free(L.line_at);
        free(m);
        return SKE_E_CONFIG;
    }
    xmlSetGenericErrorFunc(NULL, ske__xml_silent);
    xmlSetStructuredErrorFunc(&L, ske__parse_error);
    const int flags = XML_PARSE_NONET | XML_PARSE_BIG_LINES;
    xmlDocPtr doc = L.text ? xmlReadMemory(L.text, (int)L.text_len, path, NULL, flags)
                           : xmlReadFile(path, NULL, flags);
    xmlSetStructuredErrorFunc(NULL, NULL);
    int rc = SKE_OK;
    if (!doc) {
        if (!L.failed)
            ske__diag_set(diag, path, 0, "", "well-formed XML", "cannot parse the module");
        rc = SKE_E_CONFIG;
        goto out;
    }
    rc = ske__validate_schema(&L, doc);
    if (rc != SKE_OK)
        goto out;
    load_module(&L, xmlDocGetRootElement(doc));
    if (L.failed)
        rc = SKE_E_CONFIG;
out:
    if (doc)
        xmlFreeDoc(doc);
    free(L.text);
    free(L.line_at);
    if (rc != SKE_OK) {
        ske_config_free(m);
        return rc;
    }
    *out = m;
    return SKE_OK;
}

void ske_config_free(ske_module_cfg_t *m)
{
    if (!m)
        return;
    for (int i = 0; i < m->n_partitions; i++)
        for (int a = 0; a < m->partitions[i].argc; a++)
            free(m->partitions[i].argv[a]);
    free(m);
}
