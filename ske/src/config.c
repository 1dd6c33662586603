/* SPDX-License-Identifier: Apache-2.0 */
/* Loads an ARINC 653 module XML: schema validation through libxml2, then the rules of the
 * standard that a schema cannot say (schedule fits the major frame, channels agree, ...). */
#include "ske/config.h"

#include <errno.h>
#include <libgen.h>
#include <limits.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <libxml/parser.h>
#include <libxml/tree.h>
#include <libxml/xmlschemas.h>

#ifndef IMA_SCHEMA_DIR
#define IMA_SCHEMA_DIR "config/schema"
#endif

#define EXT_NS "urn:ima-testbed:arinc653-linux:1"
#define SCHEMA_FILE "ima653_module.xsd"

typedef struct {
    ske_module_cfg_t *m;
    ske_diag_t *diag;
    const ske_load_opts_t *opts;
    bool failed;
    char *text; /* the module file, to find where start tags begin */
    size_t text_len;
    size_t *line_at; /* offset of each line's first character, 1-based */
    int n_lines;
} loader_t;

static int tag_line(const loader_t *L, int line, const char *name);
static int line_of(const loader_t *L, const xmlNode *node);

/* ---- diagnostics ---------------------------------------------------------------------- */

static void diag_set(ske_diag_t *d, const char *file, int line, const char *element,
                     const char *rule, const char *fmt, ...) __attribute__((format(printf, 6, 7)));

static void diag_set(ske_diag_t *d, const char *file, int line, const char *element,
                     const char *rule, const char *fmt, ...)
{
    va_list ap;
    snprintf(d->file, sizeof d->file, "%s", file ? file : "?");
    d->line = line;
    snprintf(d->element, sizeof d->element, "%s", element ? element : "");
    snprintf(d->rule, sizeof d->rule, "%s", rule ? rule : "");
    va_start(ap, fmt);
    vsnprintf(d->message, sizeof d->message, fmt, ap);
    va_end(ap);
}

void ske_diag_format(const ske_diag_t *d, char *buf, size_t len)
{
    if (d->element[0] && d->rule[0])
        snprintf(buf, len, "%s:%d: error: %s: %s (rule: %s)", d->file, d->line, d->element,
                 d->message, d->rule);
    else if (d->element[0])
        snprintf(buf, len, "%s:%d: error: %s: %s", d->file, d->line, d->element, d->message);
    else if (d->rule[0])
        snprintf(buf, len, "%s:%d: error: %s (rule: %s)", d->file, d->line, d->message, d->rule);
    else
        snprintf(buf, len, "%s:%d: error: %s", d->file, d->line, d->message);
}

/* Fails the load at `node` unless an earlier rule already failed (the first error wins). */
static void fail(loader_t *L, const xmlNode *node, const char *rule, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));

static void fail(loader_t *L, const xmlNode *node, const char *rule, const char *fmt, ...)
{
    if (L->failed)
        return;
    char msg[768];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    diag_set(L->diag, L->m->path, node ? line_of(L, node) : 0,
             node ? (const char *)node->name : "", rule, "%s", msg);
    L->failed = true;
}

/* ---- source lines --------------------------------------------------------------------- */

/* libxml2 records the line where an element's start tag ends; a reader wants the line
 * where it begins, so look back from there for "<Name". */
static int tag_line(const loader_t *L, int line, const char *name)
{
    if (!L->text || line < 1 || line > L->n_lines || !name || !*name)
        return line;
    size_t n = strlen(name);
    for (int l = line; l >= 1 && l > line - 200; l--) {
        size_t from = L->line_at[l];
        size_t to = l < L->n_lines ? L->line_at[l + 1] : L->text_len;
        for (size_t i = from; i + 1 + n <= to; i++) {
            if (L->text[i] != '<')
                continue;
            const char *q = L->text + i + 1;
            const char *colon = memchr(q, ':', (size_t)(L->text + to - q));
            const char *local = q;
            /* accept a prefix: <ima:Linux */
            if (colon && colon < L->text + to && (size_t)(colon - q) < 32 &&
                strncmp(colon + 1, name, n) == 0)
                local = colon + 1;
            if (strncmp(local, name, n) == 0) {
                char after = local[n];
                if (after == ' ' || after == '\t' || after == '\n' || after == '\r' ||
                    after == '>' || after == '/')
                    return l;
            }
        }
    }
    return line;
}

static int line_of(const loader_t *L, const xmlNode *node)
{
    return tag_line(L, (int)xmlGetLineNo(node), (const char *)node->name);
}

static void index_lines(loader_t *L)
{
    FILE *f = fopen(L->m->path, "rb");
    if (!f)
        return;
    size_t cap = 1 << 16, len = 0;
    char *buf = malloc(cap);
    size_t r;
    while (buf && (r = fread(buf + len, 1, cap - len, f)) > 0) {
        len += r;
        if (len == cap) {
            char *nb = realloc(buf, cap * 2);
            if (!nb) {
                free(buf);
                buf = NULL;
                break;
            }
            buf = nb;
            cap *= 2;
        }
    }
    fclose(f);
    if (!buf)
        return;
    int lines = 1;
    for (size_t i = 0; i < len; i++)
        lines += buf[i] == '\n';
    L->line_at = malloc(((size_t)lines + 2) * sizeof *L->line_at);
    if (!L->line_at) {
        free(buf);
        return;
    }
    L->text = buf;
    L->text_len = len;
    L->n_lines = lines;
    L->line_at[1] = 0;
    int l = 1;
    for (size_t i = 0; i < len; i++)
        if (buf[i] == '\n')
            L->line_at[++l] = i + 1;
}

/* ---- numbers -------------------------------------------------------------------------- */

bool ske_parse_seconds(const char *s, int64_t *ns)
{
    if (!s || !*s)
        return false;
    int64_t whole = 0, frac = 0;
    int frac_digits = 0;
    const char *p = s;
    if (*p < '0' || *p > '9')
        return false;
    for (; *p >= '0' && *p <= '9'; p++) {
        if (whole > (INT64_MAX / 1000000000LL - 9) / 10)
            return false;
        whole = whole * 10 + (*p - '0');
    }
    if (*p == '.') {
        p++;
        if (*p < '0' || *p > '9')
            return false;
        for (; *p >= '0' && *p <= '9'; p++) {
            if (++frac_digits > 9)
                return false;
            frac = frac * 10 + (*p - '0');
        }
        for (int i = frac_digits; i < 9; i++)
            frac *= 10;
    }
    if (*p)
        return false;
    *ns = whole * 1000000000LL + frac;
    return true;
}

bool ske_parse_u64(const char *s, uint64_t *v)
{
    if (!s || *s < '0' || *s > '9')
        return false; /* no blank, no sign: strtoull would accept both */
    int base = (s[0] == '0' && (s[1] == 'x' || s[1] == 'X')) ? 16 : 10;
    if (base == 16 && !s[2])
        return false;
    char *end;
    errno = 0;
    unsigned long long x = strtoull(s, &end, base);
    if (errno || *end)
        return false;
    *v = x;
    return true;
}

/* ---- XML helpers ---------------------------------------------------------------------- */

static bool is_elem(const xmlNode *n, const char *name, bool ext)
{
    if (n->type != XML_ELEMENT_NODE || strcmp((const char *)n->name, name) != 0)
        return false;
    bool in_ext = n->ns && n->ns->href && strcmp((const char *)n->ns->href, EXT_NS) == 0;
    return ext ? in_ext : !n->ns;
}

/* Attribute value copied into buf; false when absent. */
static bool attr(const xmlNode *n, const char *name, char *buf, size_t len)
{
    xmlChar *v = xmlGetNoNsProp(n, (const xmlChar *)name);
    if (!v)
        return false;
    snprintf(buf, len, "%s", (const char *)v);
    xmlFree(v);
    return true;
}

static bool attr_seconds(loader_t *L, const xmlNode *n, const char *name, int64_t *ns, bool required)
{
    char buf[128];
    if (!attr(n, name, buf, sizeof buf)) {
        if (required)
            fail(L, n, "required attribute", "attribute %s is missing", name);
        return false;
    }
    if (!ske_parse_seconds(buf, ns)) {
        fail(L, n, "durations are decimal seconds",
             "%s='%s' is not a valid duration: expected decimal seconds such as 0.010, "
             "at most 9 decimals and at most %lld s", name, buf,
             (long long)(INT64_MAX / 1000000000LL - 10));
        return false;
    }
    return true;
}

static bool attr_u64(loader_t *L, const xmlNode *n, const char *name, uint64_t *v, uint64_t max,
                     bool required)
{
    char buf[128];
    if (!attr(n, name, buf, sizeof buf)) {
        if (required)
            fail(L, n, "required attribute", "attribute %s is missing", name);
        return false;
    }
    if (!ske_parse_u64(buf, v) || *v > max) {
        fail(L, n, "numbers are non-negative integers",
             "%s='%s' is not a valid number (expected an integer from 0 to %llu)", name, buf,
             (unsigned long long)max);
        return false;
    }
    return true;
}

static bool attr_bool(const xmlNode *n, const char *name, bool dflt)
{
    char buf[16];
    if (!attr(n, name, buf, sizeof buf))
        return dflt;
    return strcmp(buf, "true") == 0 || strcmp(buf, "1") == 0;
}

static bool attr_name(loader_t *L, const xmlNode *n, const char *name, char *out)
{
    char buf[256];
    if (!attr(n, name, buf, sizeof buf)) {
        fail(L, n, "required attribute", "attribute %s is missing", name);
        return false;
    }
    if (strlen(buf) >= SKE_NAME_MAX) {
        fail(L, n, "names have at most 30 characters", "%s='%s' is too long", name, buf);
        return false;
    }
    memcpy(out, buf, strlen(buf) + 1); /* fits: checked above */
    return true;
}

int ske_config_partition_by_id(const ske_module_cfg_t *m, int32_t id)
{
    for (int i = 0; i < m->n_partitions; i++)
        if (m->partitions[i].id == id)
            return i;
    return -1;
}

int ske_config_port_by_name(const ske_partition_cfg_t *p, const char *name)
{
    for (int i = 0; i < p->n_ports; i++)
        if (strcmp(p->ports[i].name, name) == 0)
            return i;
    return -1;
}

/* A partition reference: PartitionIdentifier and PartitionName must name the same one. */
static int partition_ref(loader_t *L, const xmlNode *n)
{
    uint64_t id;
    char name[SKE_NAME_MAX];
    if (!attr_u64(L, n, "PartitionIdentifier", &id, INT32_MAX, true) ||
        !attr_name(L, n, "PartitionName", name))
        return -1;
    int i = ske_config_partition_by_id(L->m, (int32_t)id);
    if (i < 0) {
        fail(L, n, "references name a declared Partition",
             "unknown partition: no Partition has PartitionIdentifier=%llu (PartitionName='%s')",
             (unsigned long long)id, name);
        return -1;
    }
    if (strcmp(L->m->partitions[i].name, name) != 0) {
        fail(L, n, "PartitionIdentifier and PartitionName name the same partition",
             "PartitionIdentifier=%llu is partition '%s', not '%s'", (unsigned long long)id,
             L->m->partitions[i].name, name);
        return -1;
    }
    return i;
}

/* ---- schema validation ---------------------------------------------------------------- */

static void schema_error(void *ctx, xmlErrorPtr err)
{
    loader_t *L = ctx;
    if (L->failed || !err)
        return;
    char msg[768];
    snprintf(msg, sizeof msg, "%s", err->message ? err->message : "schema error");
    size_t n = strlen(msg);
    while (n && (msg[n - 1] == '\n' || msg[n - 1] == ' '))
        msg[--n] = '\0';
    const char *elem = "";
    const xmlNode *node = err->node;
    char attr_buf[64] = "";
    const char *attr_name_s = NULL;
    if (node && node->type == XML_ATTRIBUTE_NODE && node->parent) {
        attr_name_s = (const char *)node->name;
        node = node->parent;
    } else {
        /* libxml2 reports attribute errors on the element and names the attribute in the
         * message: "Element 'X', attribute 'Y': ..." */
        const char *a = strstr(msg, "attribute '");
        if (a) {
            a += strlen("attribute '");
            const char *e = strchr(a, '\'');
            if (e && (size_t)(e - a) < sizeof attr_buf) {
                memcpy(attr_buf, a, (size_t)(e - a));
                attr_buf[e - a] = '\0';
                attr_name_s = attr_buf;
            }
        }
    }
    if (node && node->type == XML_ELEMENT_NODE)
        elem = (const char *)node->name;
    int line = node && node->type == XML_ELEMENT_NODE ? line_of(L, node) : err->line;
    /* Say what a malformed number means rather than quoting the schema's regular expression. */
    char value[128] = "";
    if (attr_name_s && node)
        attr(node, attr_name_s, value, sizeof value);
    size_t an = attr_name_s ? strlen(attr_name_s) : 0;
    bool value_error = strstr(msg, "is not a valid value") || strstr(msg, "[facet");
    const char *max = strstr(msg, "maximum value allowed ('");
    if (!value_error)
        attr_name_s = NULL; /* a missing or unexpected attribute: the validator says it best */
    if (attr_name_s && max) {
        char lim[32] = "";
        sscanf(max + strlen("maximum value allowed ('"), "%31[0-9]", lim);
        diag_set(L->diag, L->m->path, line, elem, "numbers are within their range",
                 "%s='%s' is too large: at most %s", attr_name_s, value, lim);
    } else if (attr_name_s && an > 7 && strcmp(attr_name_s + an - 7, "Seconds") == 0) {
        diag_set(L->diag, L->m->path, line, elem, "durations are decimal seconds",
                 "%s='%s' is not a valid duration: expected decimal seconds such as 0.010, "
                 "at most 9 decimals", attr_name_s, value);
    } else if (attr_name_s && (strstr(attr_name_s, "Identifier") || strstr(attr_name_s, "Size") ||
                               strstr(attr_name_s, "Nb") || strstr(attr_name_s, "Address"))) {
        diag_set(L->diag, L->m->path, line, elem, "numbers are positive integers",
                 "%s='%s' is not a valid number: expected a positive integer%s", attr_name_s,
                 value, strstr(attr_name_s, "Bytes") || strstr(attr_name_s, "Address") ||
                            strstr(attr_name_s, "StackSize") ? " (decimal or 0x-hexadecimal)" : "");
    } else {
        diag_set(L->diag, L->m->path, line, elem, "schema " SCHEMA_FILE, "%s", msg);
    }
    L->failed = true;
}

static void parse_error(void *ctx, xmlErrorPtr err)
{
    loader_t *L = ctx;
    if (L->failed || !err)
        return;
    char msg[768];
    snprintf(msg, sizeof msg, "%s", err->message ? err->message : "XML error");
    size_t n = strlen(msg);
    while (n && (msg[n - 1] == '\n' || msg[n - 1] == ' '))
        msg[--n] = '\0';
    diag_set(L->diag, L->m->path, err->line, "", "well-formed XML", "%s", msg);
    L->failed = true;
}

static void silent(void *ctx, const char *msg, ...) { (void)ctx; (void)msg; }

static int validate_schema(loader_t *L, xmlDocPtr doc)
{
    char xsd[SKE_PATH_MAX];
    const char *dir = L->opts && L->opts->schema_dir ? L->opts->schema_dir : IMA_SCHEMA_DIR;
    snprintf(xsd, sizeof xsd, "%s/%s", dir, SCHEMA_FILE);
    if (access(xsd, R_OK) != 0) {
        diag_set(L->diag, xsd, 0, "", "", "cannot read the module schema: %s", strerror(errno));
        return SKE_E_IO;
    }
    int rc = SKE_OK;
    xmlSchemaParserCtxtPtr pctx = xmlSchemaNewParserCtxt(xsd);
    xmlSchemaPtr schema = pctx ? xmlSchemaParse(pctx) : NULL;
    xmlSchemaValidCtxtPtr vctx = schema ? xmlSchemaNewValidCtxt(schema) : NULL;
    if (!vctx) {
        diag_set(L->diag, xsd, 0, "", "", "the module schema itself is invalid");
        rc = SKE_E_IO;
        goto out;
    }
    xmlSchemaSetValidStructuredErrors(vctx, schema_error, L);
    if (xmlSchemaValidateDoc(vctx, doc) != 0) {
        if (!L->failed)
            fail(L, xmlDocGetRootElement(doc), "schema " SCHEMA_FILE, "document does not validate");
        rc = SKE_E_CONFIG;
    }
out:
    if (vctx)
        xmlSchemaFreeValidCtxt(vctx);
    if (schema)
        xmlSchemaFree(schema);
    if (pctx)
        xmlSchemaFreeParserCtxt(pctx);
    return rc;
}

/* ---- elements ------------------------------------------------------------------------- */

static void split_args(loader_t *L, const xmlNode *n, ske_partition_cfg_t *p, const char *args)
{
    p->argv[0] = strdup(p->name);
    p->argc = 1;
    if (!args)
        return;
    char *copy = strdup(args), *save = NULL;
    for (char *tok = strtok_r(copy, " \t\n", &save); tok; tok = strtok_r(NULL, " \t\n", &save)) {
        if (p->argc >= SKE_MAX_ARGS - 1) {
            fail(L, n, "at most 30 arguments", "too many Arguments for partition '%s'", p->name);
            break;
        }
        p->argv[p->argc++] = strdup(tok);
    }
    free(copy);
}

static void load_port(loader_t *L, const xmlNode *n, ske_partition_cfg_t *p, ske_port_kind_t kind)
{
    if (p->n_ports >= SKE_MAX_PORTS) {
        fail(L, n, "at most 64 ports per partition", "too many ports in partition '%s'", p->name);
        return;
    }
    ske_port_cfg_t *port = &p->ports[p->n_ports];
    memset(port, 0, sizeof *port);
    port->kind = kind;
    port->channel = -1;
    port->line = line_of(L, n);
    if (!attr_name(L, n, "Name", port->name))
        return;
    if (ske_config_port_by_name(p, port->name) >= 0) {
        fail(L, n, "port names are unique within a partition",
             "partition '%s' declares port '%s' twice", p->name, port->name);
        return;
    }
    char dir[32] = "";
    attr(n, "Direction", dir, sizeof dir);
    port->dir = strcmp(dir, "DESTINATION") == 0 ? SKE_DIR_DESTINATION : SKE_DIR_SOURCE;
    uint64_t v;
    if (attr_u64(L, n, "MaxMessageSize", &v, 1u << 20, true)) {
        if (v == 0)
            fail(L, n, "MaxMessageSize is positive", "MaxMessageSize must be at least 1");
        port->max_size = (uint32_t)v;
    }
    if (kind == SKE_PORT_SAMPLING) {
        if (attr_seconds(L, n, "RefreshRateSeconds", &port->refresh_ns, true) && port->refresh_ns == 0)
            fail(L, n, "RefreshRateSeconds is positive", "RefreshRateSeconds must be greater than 0");
    } else if (attr_u64(L, n, "MaxNbMessages", &v, 1u << 20, true)) {
        if (v == 0)
            fail(L, n, "MaxNbMessages is positive", "MaxNbMessages must be at least 1");
        port->max_nb = (uint32_t)v;
        if ((uint64_t)port->max_nb * port->max_size > SKE_PORT_BYTES_MAX)
            fail(L, n, "a queuing port holds at most 64 MiB",
                 "MaxNbMessages=%u of %u bytes needs %llu MiB", port->max_nb, port->max_size,
                 (unsigned long long)((uint64_t)port->max_nb * port->max_size >> 20));
    }
    p->n_ports++;
}

static void load_partition(loader_t *L, const xmlNode *n)
{
    ske_module_cfg_t *m = L->m;
    if (m->n_partitions >= SKE_MAX_PARTITIONS) {
        fail(L, n, "at most 32 partitions", "too many partitions");
        return;
    }
    ske_partition_cfg_t *p = &m->partitions[m->n_partitions];
    memset(p, 0, sizeof *p);
    hm_partition_defaults(&p->hm);
    p->line = line_of(L, n);
    uint64_t id;
    if (!attr_u64(L, n, "PartitionIdentifier", &id, INT32_MAX, true) ||
        !attr_name(L, n, "PartitionName", p->name))
        return;
    p->id = (int32_t)id;
    for (int i = 0; i < m->n_partitions; i++) {
        if (m->partitions[i].id == p->id)
            fail(L, n, "partition identifiers are unique",
                 "PartitionIdentifier=%d is already used by partition '%s' (line %d)", p->id,
                 m->partitions[i].name, m->partitions[i].line);
        else if (strcmp(m->partitions[i].name, p->name) == 0)
            fail(L, n, "partition names are unique",
                 "PartitionName='%s' is already used (line %d)", p->name, m->partitions[i].line);
    }
    if (!attr(n, "Criticality", p->criticality, sizeof p->criticality))
        snprintf(p->criticality, sizeof p->criticality, "LEVEL_E");
    p->system_partition = attr_bool(n, "SystemPartition", false);
    xmlChar *sch = xmlGetNsProp(n, (const xmlChar *)"ScheduleChange", (const xmlChar *)EXT_NS);
    p->schedule_change = sch && (strcmp((const char *)sch, "true") == 0 || strcmp((const char *)sch, "1") == 0);
    if (sch)
        xmlFree(sch);
    attr(n, "EntryPoint", p->entry_point, sizeof p->entry_point);
    bool have_linux = false;
    for (const xmlNode *c = n->children; c; c = c->next) {
        if (is_elem(c, "Sampling_Port", false))
            load_port(L, c, p, SKE_PORT_SAMPLING);
        else if (is_elem(c, "Queuing_Port", false))
            load_port(L, c, p, SKE_PORT_QUEUING);
        else if (is_elem(c, "Process", false)) {
            if (p->n_processes < SKE_MAX_PORTS) {
                ske_process_cfg_t *pr = &p->processes[p->n_processes++];
                pr->line = line_of(L, c);
                attr_name(L, c, "Name", pr->name);
                uint64_t ss = 0;
                if (attr_u64(L, c, "StackSize", &ss, UINT32_MAX, false))
                    pr->stack_size = (uint32_t)ss;
            }
        } else if (is_elem(c, "Linux", true)) {
            if (have_linux) {
                fail(L, c, "each Partition has one ima:Linux element",
                     "partition '%s' names its program twice", p->name);
                continue;
            }
            have_linux = true;
            attr(c, "Executable", p->exe_name, sizeof p->exe_name);
            char args[2048];
            split_args(L, c, p, attr(c, "Arguments", args, sizeof args) ? args : NULL);
        }
    }
    if (!have_linux)
        fail(L, n, "each Partition has an ima:Linux element",
             "partition '%s' does not say which program runs it (ima:Linux Executable=...)", p->name);
    m->n_partitions++;
}

static void load_memory(loader_t *L, const xmlNode *n)
{
    int pi = partition_ref(L, n);
    if (pi < 0)
        return;
    ske_partition_cfg_t *p = &L->m->partitions[pi];
    for (const xmlNode *c = n->children; c; c = c->next) {
        if (!is_elem(c, "Memory_Requirements", false))
            continue;
        uint64_t sz;
        if (attr_u64(L, c, "SizeBytes", &sz, (uint64_t)1 << 40, true))
            p->memory_bytes += sz;
    }
}

static void load_schedule(loader_t *L, const xmlNode *n)
{
    ske_module_cfg_t *m = L->m;
    if (m->n_schedules >= SKE_MAX_SCHEDULES) {
        fail(L, n, "at most 8 module schedules", "too many Module_Schedule elements");
        return;
    }
    int si = m->n_schedules;
    ske_schedule_cfg_t *sc = &m->schedules[si];
    memset(sc, 0, sizeof *sc);
    sc->line = line_of(L, n);
    uint64_t sid = (uint64_t)si + 1;
    if (!attr_u64(L, n, "ScheduleIdentifier", &sid, INT32_MAX, false) && L->failed)
        return;
    sc->id = (int32_t)sid;
    char name[256];
    if (attr(n, "ScheduleName", name, sizeof name)) {
        if (!attr_name(L, n, "ScheduleName", sc->name))
            return;
    } else {
        snprintf(sc->name, sizeof sc->name, "SCHEDULE_%d", sc->id);
    }
    for (int i = 0; i < si; i++)
        if (m->schedules[i].id == sc->id || strcmp(m->schedules[i].name, sc->name) == 0) {
            fail(L, n, "module schedules have distinct identifiers and names",
                 "ScheduleIdentifier=%d / ScheduleName='%s' is already used (line %d)", sc->id,
                 sc->name, m->schedules[i].line);
            return;
        }
    sc->initial = attr_bool(n, "InitialModuleSchedule", false);
    int64_t maf;
    if (!attr_seconds(L, n, "MajorFrameSeconds", &maf, true))
        return;
    if (maf <= 0) {
        fail(L, n, "the major frame is positive", "MajorFrameSeconds must be greater than 0");
        return;
    }
    if (si > 0 && maf != m->major_frame_ns) {
        fail(L, n, "module schedules share the major frame",
             "schedule '%s' has a major frame of %lld ns, the first schedule %lld ns", sc->name,
             (long long)maf, (long long)m->major_frame_ns);
        return;
    }
    m->major_frame_ns = maf;
    m->n_schedules++;
    bool scheduled[SKE_MAX_PARTITIONS] = {false};
    for (const xmlNode *ps = n->children; ps && !L->failed; ps = ps->next) {
        if (!is_elem(ps, "Partition_Schedule", false))
            continue;
        int pi = partition_ref(L, ps);
        if (pi < 0)
            return;
        ske_partition_cfg_t *p = &m->partitions[pi];
        if (scheduled[pi]) {
            fail(L, ps, "one Partition_Schedule per partition",
                 "partition '%s' has a second Partition_Schedule", p->name);
            return;
        }
        scheduled[pi] = true;
        int64_t period;
        if (!attr_seconds(L, ps, "PeriodSeconds", &period, true))
            return;
        if (p->period_ns && period != p->period_ns) {
            fail(L, ps, "a partition has the same period in every module schedule",
                 "partition '%s' has period %lld ns here but %lld ns in another schedule",
                 p->name, (long long)period, (long long)p->period_ns);
            return;
        }
        p->period_ns = period;
        if (p->period_ns <= 0 || m->major_frame_ns % p->period_ns != 0) {
            fail(L, ps, "the partition period divides the major frame",
                 "PeriodSeconds of partition '%s' (%lld ns) does not divide the major frame "
                 "(%lld ns)", p->name, (long long)p->period_ns, (long long)m->major_frame_ns);
            return;
        }
        int64_t declared_duration = -1;
        if (attr_seconds(L, ps, "PeriodDurationSeconds", &declared_duration, false) == false &&
            L->failed)
            return;
        int64_t total = 0;
        bool anchor_set = false;
        for (const xmlNode *w = ps->children; w && !L->failed; w = w->next) {
            if (!is_elem(w, "Window_Schedule", false))
                continue;
            if (m->n_windows >= SKE_MAX_WINDOWS) {
                fail(L, w, "at most 256 windows", "too many windows");
                return;
            }
            ske_window_cfg_t *win = &m->windows[m->n_windows];
            memset(win, 0, sizeof *win);
            win->line = line_of(L, w);
            win->partition = pi;
            win->schedule = si;
            uint64_t wid;
            if (!attr_u64(L, w, "WindowIdentifier", &wid, INT32_MAX, true) ||
                !attr_seconds(L, w, "WindowStartSeconds", &win->offset_ns, true) ||
                !attr_seconds(L, w, "WindowDurationSeconds", &win->duration_ns, true))
                return;
            win->id = (int32_t)wid;
            for (int i = 0; i < m->n_windows; i++)
                if (m->windows[i].id == win->id && m->windows[i].schedule == si) {
                    fail(L, w, "window identifiers are unique",
                         "WindowIdentifier=%d is already used (line %d)", win->id,
                         m->windows[i].line);
                    return;
                }
            if (win->duration_ns <= 0) {
                fail(L, w, "windows have a positive duration", "WindowDurationSeconds must be "
                     "greater than 0");
                return;
            }
            if (win->offset_ns >= m->major_frame_ns ||
                win->duration_ns > m->major_frame_ns - win->offset_ns) {
                fail(L, w, "windows end within the major frame",
                     "window %d of partition '%s' runs from %lld ns to %lld ns, past the major "
                     "frame of %lld ns", win->id, p->name, (long long)win->offset_ns,
                     (long long)(win->offset_ns > INT64_MAX - win->duration_ns
                                     ? INT64_MAX : win->offset_ns + win->duration_ns),
                     (long long)m->major_frame_ns);
                return;
            }
            win->period_start = attr_bool(w, "PartitionPeriodStart", false);
            if (win->period_start && !anchor_set) {
                p->anchor_in[si] = win->offset_ns % p->period_ns;
                anchor_set = true;
            }
            total += win->duration_ns;
            p->n_windows++;
            p->windows_in[si]++;
            m->n_windows++;
        }
        if (!anchor_set) {
            /* No window is marked as a period start: the first one starts the period. */
            int64_t first = INT64_MAX;
            for (int i = 0; i < m->n_windows; i++)
                if (m->windows[i].partition == pi && m->windows[i].schedule == si &&
                    m->windows[i].offset_ns < first)
                    first = m->windows[i].offset_ns;
            p->anchor_in[si] = first == INT64_MAX ? 0 : first % p->period_ns;
        }
        int64_t periods = m->major_frame_ns / p->period_ns;
        p->duration_in[si] = total / periods;
        /* The initial schedule's are the partition's until the schedules are all read. */
        p->duration_ns = p->duration_in[si];
        p->period_anchor_ns = p->anchor_in[si];
        if (declared_duration >= 0 && declared_duration * periods != total) {
            fail(L, ps, "PeriodDurationSeconds is the window time per period",
                 "partition '%s' declares %lld ns per period but its windows give %lld ns per "
                 "period", p->name, (long long)declared_duration, (long long)(total / periods));
            return;
        }
        /* Every period of the partition gets the same window time (ARINC 653 Part 1, 2.3.1.3):
         * a window belongs to the period its start falls in, and may not cross into the next. */
        for (int64_t k = 0; k < periods && !L->failed; k++) {
            int64_t lo = p->period_anchor_ns + k * p->period_ns, hi = lo + p->period_ns, in = 0;
            for (int i = 0; i < m->n_windows; i++) {
                const ske_window_cfg_t *win = &m->windows[i];
                if (win->partition != pi || win->schedule != si)
                    continue;
                /* offsets before the anchor belong to the last period, wrapping the frame */
                int64_t off = win->offset_ns < p->period_anchor_ns ? win->offset_ns + m->major_frame_ns
                                                                   : win->offset_ns;
                if (off < lo || off >= hi)
                    continue;
                if (off + win->duration_ns > hi) {
                    L->failed = false;
                    diag_set(L->diag, m->path, win->line, "Window_Schedule",
                             "a window stays within its partition period",
                             "window %d of partition '%s' starts at %lld ns and ends past the end "
                             "of its partition period at %lld ns", win->id, p->name,
                             (long long)win->offset_ns, (long long)(hi % m->major_frame_ns));
                    L->failed = true;
                    return;
                }
                in += win->duration_ns;
            }
            if (in != p->duration_ns) {
                fail(L, ps, "every partition period gets the same window time",
                     "partition '%s' gets %lld ns in its period starting at %lld ns but %lld ns "
                     "per period on average (period %lld ns)", p->name, (long long)in,
                     (long long)(lo % m->major_frame_ns), (long long)p->duration_ns,
                     (long long)p->period_ns);
                return;
            }
        }
    }
}

static int cmp_window(const void *a, const void *b)
{
    const ske_window_cfg_t *x = a, *y = b;
    if (x->schedule != y->schedule)
        return (x->schedule > y->schedule) - (x->schedule < y->schedule);
    return (x->offset_ns > y->offset_ns) - (x->offset_ns < y->offset_ns);
}

static void check_windows(loader_t *L, const xmlNode *root)
{
    ske_module_cfg_t *m = L->m;
    qsort(m->windows, (size_t)m->n_windows, sizeof m->windows[0], cmp_window);
    for (int i = 1; i < m->n_windows; i++) {
        const ske_window_cfg_t *a = &m->windows[i - 1], *b = &m->windows[i];
        if (a->schedule == b->schedule && b->offset_ns < a->offset_ns + a->duration_ns) {
            /* Report at the later window, naming the one it overlaps. */
            const ske_window_cfg_t *late = a->line > b->line ? a : b;
            const ske_window_cfg_t *early = late == a ? b : a;
            L->failed = false; /* no earlier failure can reach here */
            diag_set(L->diag, m->path, late->line, "Window_Schedule",
                     "windows of a module schedule do not overlap",
                     "window %d of partition '%s' [%lld ns, %lld ns) overlaps window %d of "
                     "partition '%s' [%lld ns, %lld ns) (line %d)", late->id,
                     m->partitions[late->partition].name, (long long)late->offset_ns,
                     (long long)(late->offset_ns + late->duration_ns), early->id,
                     m->partitions[early->partition].name, (long long)early->offset_ns,
                     (long long)(early->offset_ns + early->duration_ns), early->line);
            L->failed = true;
            return;
        }
    }
    for (int i = 0; i < m->n_partitions; i++) {
        if (m->partitions[i].n_windows == 0) {
            L->failed = false;
            diag_set(L->diag, m->path, m->partitions[i].line, "Partition",
                     "every partition has at least one window",
                     "partition '%s' has no window in the Module_Schedule",
                     m->partitions[i].name);
            L->failed = true;
            return;
        }
    }
    /* Each schedule's windows, now grouped in schedule order; the initial schedule. */
    int initial = -1;
    for (int s = 0; s < m->n_schedules; s++) {
        ske_schedule_cfg_t *sc = &m->schedules[s];
        sc->first_window = -1;
        for (int i = 0; i < m->n_windows; i++)
            if (m->windows[i].schedule == s) {
                if (sc->first_window < 0)
                    sc->first_window = i;
                sc->n_windows++;
            }
        if (sc->first_window < 0)
            sc->first_window = 0;
        if (sc->initial) {
            if (initial >= 0) {
                L->failed = false;
                diag_set(L->diag, m->path, sc->line, "Module_Schedule",
                         "one initial module schedule",
                         "schedules '%s' and '%s' are both InitialModuleSchedule",
                         m->schedules[initial].name, sc->name);
                L->failed = true;
                return;
            }
            initial = s;
        }
    }
    m->initial_schedule = initial >= 0 ? initial : 0;
    for (int i = 0; i < m->n_partitions; i++) {
        ske_partition_cfg_t *p = &m->partitions[i];
        p->duration_ns = p->duration_in[m->initial_schedule];
        p->period_anchor_ns = p->anchor_in[m->initial_schedule];
    }
    (void)root;
}

static bool load_endpoint(loader_t *L, const xmlNode *ep, ske_endpoint_t *out)
{
    for (const xmlNode *c = ep->children; c; c = c->next) {
        if (!is_elem(c, "Standard_Partition", false))
            continue;
        int pi = partition_ref(L, c);
        if (pi < 0)
            return false;
        char port[SKE_NAME_MAX];
        if (!attr_name(L, c, "PortName", port))
            return false;
        int po = ske_config_port_by_name(&L->m->partitions[pi], port);
        if (po < 0) {
            fail(L, c, "a channel connects ports that partitions declare",
                 "partition '%s' declares no port named '%s'", L->m->partitions[pi].name, port);
            return false;
        }
        out->partition = pi;
        out->port = po;
        return true;
    }
    fail(L, ep, "a channel end names a Standard_Partition", "missing Standard_Partition");
    return false;
}

static ske_port_cfg_t *port_of(ske_module_cfg_t *m, ske_endpoint_t e)
{
    return &m->partitions[e.partition].ports[e.port];
}

static const char *kind_name(ske_port_kind_t k)
{
    return k == SKE_PORT_SAMPLING ? "sampling" : "queuing";
}

static void load_channel(loader_t *L, const xmlNode *n)
{
    ske_module_cfg_t *m = L->m;
    if (m->n_channels >= SKE_MAX_CHANNELS) {
        fail(L, n, "at most 256 channels", "too many channels");
        return;
    }
    ske_channel_cfg_t *ch = &m->channels[m->n_channels];
    memset(ch, 0, sizeof *ch);
    ch->line = line_of(L, n);
    uint64_t id;
    if (!attr_u64(L, n, "ChannelIdentifier", &id, INT32_MAX, true) ||
        !attr_name(L, n, "ChannelName", ch->name))
        return;
    ch->id = (int32_t)id;
    for (int i = 0; i < m->n_channels; i++)
        if (m->channels[i].id == ch->id) {
            fail(L, n, "channel identifiers are unique",
                 "ChannelIdentifier=%d is already used (line %d)", ch->id, m->channels[i].line);
            return;
        }
    const xmlNode *src_node = NULL;
    const xmlNode *dst_node[SKE_MAX_DESTINATIONS] = {NULL};
    for (const xmlNode *c = n->children; c && !L->failed; c = c->next) {
        if (is_elem(c, "Source", false)) {
            src_node = c;
            if (!load_endpoint(L, c, &ch->src))
                return;
        } else if (is_elem(c, "Destination", false)) {
            if (ch->n_dst >= SKE_MAX_DESTINATIONS) {
                fail(L, c, "at most 16 destinations per channel", "too many destinations");
                return;
            }
            if (!load_endpoint(L, c, &ch->dst[ch->n_dst]))
                return;
            dst_node[ch->n_dst++] = c;
        }
    }
    if (!src_node || ch->n_dst == 0) {
        fail(L, n, "a channel has one Source and at least one Destination",
             "channel '%s' lacks a %s", ch->name, src_node ? "Destination" : "Source");
        return;
    }
    ske_port_cfg_t *sp = port_of(m, ch->src);
    ch->kind = sp->kind;
    if (sp->dir != SKE_DIR_SOURCE) {
        fail(L, src_node, "a channel's Source is a SOURCE port",
             "port '%s' of partition '%s' is a DESTINATION port, it cannot be the source of "
             "channel '%s'", sp->name, m->partitions[ch->src.partition].name, ch->name);
        return;
    }
    if (sp->channel >= 0) {
        fail(L, src_node, "a port belongs to one channel",
             "port '%s' of partition '%s' is already the source of channel '%s'", sp->name,
             m->partitions[ch->src.partition].name, m->channels[sp->channel].name);
        return;
    }
    if (ch->kind == SKE_PORT_QUEUING && ch->n_dst > 1) {
        fail(L, n, "a queuing channel has exactly one destination",
             "queuing channel '%s' has %d destinations", ch->name, ch->n_dst);
        return;
    }
    sp->channel = m->n_channels;
    for (int d = 0; d < ch->n_dst; d++) {
        ske_port_cfg_t *dp = port_of(m, ch->dst[d]);
        const char *pname = m->partitions[ch->dst[d].partition].name;
        if (dp->kind != ch->kind) {
            fail(L, dst_node[d], "a channel connects ports of one kind",
                 "channel '%s' connects %s port '%s' to %s port '%s' of partition '%s'",
                 ch->name, kind_name(sp->kind), sp->name, kind_name(dp->kind), dp->name, pname);
            return;
        }
        if (dp->dir != SKE_DIR_DESTINATION) {
            fail(L, dst_node[d], "a channel's Destination is a DESTINATION port",
                 "port '%s' of partition '%s' is a SOURCE port, it cannot be a destination of "
                 "channel '%s'", dp->name, pname, ch->name);
            return;
        }
        if (dp->max_size != sp->max_size) {
            fail(L, dst_node[d], "the ports of a channel have the same MaxMessageSize",
                 "channel '%s': source port '%s' has MaxMessageSize=%u but destination port "
                 "'%s' of partition '%s' has %u", ch->name, sp->name, sp->max_size, dp->name,
                 pname, dp->max_size);
            return;
        }
        if (dp->channel >= 0) {
            fail(L, dst_node[d], "a port belongs to one channel",
                 "port '%s' of partition '%s' is already a destination of channel '%s'",
                 dp->name, pname, m->channels[dp->channel].name);
            return;
        }
        dp->channel = m->n_channels;
    }
    m->n_channels++;
}

/* Bare names are looked up in the partition path; names with a slash are relative to the
 * module file's folder. */
static void resolve_executable(loader_t *L, ske_partition_cfg_t *p)
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
    diag_set(L->diag, L->m->path, p->line, "Partition", "the partition's program exists",
             "partition '%s': executable '%s' not found%s%s", p->name, p->exe_name,
             strchr(p->exe_name, '/') ? "" : " in the partition path ",
             strchr(p->exe_name, '/') ? "" :
             (L->opts && L->opts->partition_path ? L->opts->partition_path : "(empty)"));
    L->failed = true;
}

/* ---- health-monitoring tables ---------------------------------------------------------- */

/* Visits each Error_ID_Level/Error_ID_Action of a table: calls fn(L, entry, state, error). */
typedef void (*hm_entry_fn)(loader_t *L, const xmlNode *e, hm_state_t st, hm_error_t err, void *arg);

static void load_hm_table(loader_t *L, const xmlNode *table, const char *entry_name, hm_entry_fn fn,
                          void *arg)
{
    bool seen[HM_STATE_COUNT][HM_ERR_COUNT] = {{false}};
    for (const xmlNode *sse = table->children; sse && !L->failed; sse = sse->next) {
        if (!is_elem(sse, "System_State_Entry", false))
            continue;
        uint64_t st;
        if (!attr_u64(L, sse, "SystemState", &st, HM_STATE_COUNT - 1, true))
            return;
        for (const xmlNode *e = sse->children; e && !L->failed; e = e->next) {
            if (!is_elem(e, entry_name, false))
                continue;
            uint64_t id;
            if (!attr_u64(L, e, "ErrorIdentifier", &id, HM_ERR_COUNT - 1, true))
                return;
            if (id == 0) {
                fail(L, e, "error identifiers are 1 to 10", "ErrorIdentifier=0 is not an error");
                return;
            }
            if (seen[st][id]) {
                fail(L, e, "one entry per error and system state",
                     "ErrorIdentifier=%llu (%s) appears twice in SystemState %llu",
                     (unsigned long long)id, hm_error_name((hm_error_t)id), (unsigned long long)st);
                return;
            }
            seen[st][id] = true;
            fn(L, e, (hm_state_t)st, (hm_error_t)id, arg);
        }
    }
}

static void system_entry(loader_t *L, const xmlNode *e, hm_state_t st, hm_error_t err, void *arg)
{
    (void)arg;
    char buf[32] = "";
    hm_level_t level;
    attr(e, "ErrorLevel", buf, sizeof buf);
    if (!hm_level_parse(buf, &level)) {
        fail(L, e, "ErrorLevel is MODULE, PARTITION or PROCESS", "ErrorLevel='%s'", buf);
        return;
    }
    if (level == HM_LEVEL_PROCESS &&
        (err == HM_ERR_WINDOW_OVERRUN || err == HM_ERR_PARTITION_EXIT || st == HM_STATE_MODULE_INIT ||
         st == HM_STATE_PARTITION_INIT || st == HM_STATE_ERROR_HANDLER)) {
        fail(L, e, "process level needs a process that can go on",
             "%s in state %s cannot be handled at PROCESS level (no ARINC process whose error "
             "handler could act)", hm_error_name(err), hm_state_name(st));
        return;
    }
    char code[32];
    hm_error_t named;
    if (attr(e, "ErrorCode", code, sizeof code) && hm_error_parse(code, &named) &&
        hm_apex_error_code(named) != hm_apex_error_code(err)) {
        fail(L, e, "ErrorCode agrees with ErrorIdentifier",
             "ErrorIdentifier=%d is %s, but ErrorCode says %s", (int)err, hm_error_name(err), code);
        return;
    }
    L->m->hm.level[st][err] = (uint8_t)level;
}

static void module_entry(loader_t *L, const xmlNode *e, hm_state_t st, hm_error_t err, void *arg)
{
    (void)arg;
    char buf[32] = "";
    hm_action_t act;
    attr(e, "Action", buf, sizeof buf);
    if (!hm_action_parse(buf, &act) || (act != HM_ACT_IGNORE && act != HM_ACT_SHUTDOWN && act != HM_ACT_RESET)) {
        fail(L, e, "module actions are IGNORE, SHUTDOWN or RESET", "Action='%s'", buf);
        return;
    }
    L->m->hm.module_action[st][err] = (uint8_t)act;
}

static void partition_entry(loader_t *L, const xmlNode *e, hm_state_t st, hm_error_t err, void *arg)
{
    ske_partition_cfg_t *p = arg;
    char buf[32] = "";
    hm_action_t act;
    attr(e, "Action", buf, sizeof buf);
    if (!hm_action_parse(buf, &act) || act > HM_ACT_COLD_START) {
        fail(L, e, "partition actions are IGNORE, IDLE, WARM_START or COLD_START", "Action='%s'", buf);
        return;
    }
    p->hm.action[st][err] = (uint8_t)act;
}

static void load_partition_hm(loader_t *L, const xmlNode *n, bool seen[])
{
    int pi = partition_ref(L, n);
    if (pi < 0)
        return;
    if (seen[pi]) {
        fail(L, n, "one Partition_HM_Table per partition", "partition '%s' has a second "
             "Partition_HM_Table", L->m->partitions[pi].name);
        return;
    }
    seen[pi] = true;
    load_hm_table(L, n, "Error_ID_Action", partition_entry, &L->m->partitions[pi]);
}

/* ---- modules -------------------------------------------------------------------------- */

static void load_module(loader_t *L, xmlNode *root)
{
    ske_module_cfg_t *m = L->m;
    attr(root, "ModuleName", m->module_name, sizeof m->module_name);
    snprintf(m->node, sizeof m->node, "node1");
    m->time_mode = SKE_TIME_EMULATED;
    hm_system_defaults(&m->hm);
    const xmlNode *schedule = NULL;
    for (xmlNode *c = root->children; c && !L->failed; c = c->next) {
        if (is_elem(c, "Module_Extension", true)) {
            char buf[SKE_NAME_MAX];
            if (attr(c, "Node", buf, sizeof buf))
                snprintf(m->node, sizeof m->node, "%s", buf);
            if (attr(c, "TimeMode", buf, sizeof buf) && strcmp(buf, "realtime") == 0)
                m->time_mode = SKE_TIME_REALTIME;
        } else if (is_elem(c, "Partition", false)) {
            load_partition(L, c);
        }
    }
    for (xmlNode *c = root->children; c && !L->failed; c = c->next) {
        if (is_elem(c, "Partition_Memory", false))
            load_memory(L, c);
        else if (is_elem(c, "Module_Schedule", false)) {
            schedule = c;
            load_schedule(L, c);
        }
    }
    if (!L->failed && schedule)
        check_windows(L, schedule);
    bool hm_seen[SKE_MAX_PARTITIONS] = {false};
    for (xmlNode *c = root->children; c && !L->failed; c = c->next) {
        if (is_elem(c, "System_HM_Table", false))
            load_hm_table(L, c, "Error_ID_Level", system_entry, NULL);
        else if (is_elem(c, "Module_HM_Table", false))
            load_hm_table(L, c, "Error_ID_Action", module_entry, NULL);
        else if (is_elem(c, "Partition_HM_Table", false))
            load_partition_hm(L, c, hm_seen);
    }
    for (xmlNode *c = root->children; c && !L->failed; c = c->next) {
        if (!is_elem(c, "Connection_Table", false))
            continue;
        for (xmlNode *ch = c->children; ch && !L->failed; ch = ch->next)
            if (is_elem(ch, "Channel", false))
                load_channel(L, ch);
    }
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
    loader_t L = {.m = m, .diag = diag, .opts = opts};
    index_lines(&L);

    if (access(path, R_OK) != 0) {
        diag_set(diag, path, 0, "", "", "cannot read the module: %s", strerror(errno));
        free(L.text);
        free(L.line_at);
        free(m);
        return SKE_E_IO;
    }
    xmlSetGenericErrorFunc(NULL, silent);
    xmlSetStructuredErrorFunc(&L, parse_error);
    xmlDocPtr doc = xmlReadFile(path, NULL, XML_PARSE_NONET | XML_PARSE_BIG_LINES);
    xmlSetStructuredErrorFunc(NULL, NULL);
    int rc = SKE_OK;
    if (!doc) {
        if (!L.failed)
            diag_set(diag, path, 0, "", "well-formed XML", "cannot parse the module");
        rc = SKE_E_CONFIG;
        goto out;
    }
    rc = validate_schema(&L, doc);
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
