/* SPDX-License-Identifier: Apache-2.0 */
/* The loader's XML helpers: diagnostics with file, line and rule, the line where an element
 * begins, numbers and attributes, partition references, and schema validation. */
#include "ske__config.h"

#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <libxml/xmlschemas.h>

#ifndef IMA_SCHEMA_DIR
#define IMA_SCHEMA_DIR "config/schema"
#endif

/* ---- diagnostics ---------------------------------------------------------------------- */

void ske__diag_set(ske_diag_t *d, const char *file, int line, const char *element,
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
    /* One line, whatever the message quotes of the file (libxml2 quotes the input around
     * an error, newlines and all): control characters become single spaces. */
    char *out = d->message;
    for (const char *in = d->message; *in; in++) {
        bool blank = (unsigned char)*in < 0x20 || *in == 0x7f;
        if (blank && (out == d->message || out[-1] == ' '))
            continue;
        *out++ = blank ? ' ' : *in;
    }
    while (out > d->message && out[-1] == ' ')
        out--;
    *out = '\0';
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

void ske__fail(ske_loader_t *L, const xmlNode *node, const char *rule, const char *fmt, ...)
{
    if (L->failed)
        return;
    char msg[768];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    ske__diag_set(L->diag, L->m->path, node ? ske__line_of(L, node) : 0,
                  node ? (const char *)node->name : "", rule, "%s", msg);
    L->failed = true;
}

/* ---- source lines --------------------------------------------------------------------- */

/* libxml2 records the line where an element's start tag ends; a reader wants the line
 * where it begins, so look back from there for "<Name". */
static int tag_line(const ske_loader_t *L, int line, const char *name)
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

int ske__line_of(const ske_loader_t *L, const xmlNode *node)
{
    return tag_line(L, (int)xmlGetLineNo(node), (const char *)node->name);
}

void ske__index_lines(ske_loader_t *L)
{
    FILE *f = fopen(L->m->path, "rb");
    if (!f)
        return;
    size_t cap = 1 << 16, len = 0;
    char *buf = malloc(cap);
    size_t r;
    while (buf && (r = fread(buf + len, 1, cap - len, f)) > 0) {
        len += r;
        if (len > SKE_MODULE_MAX_BYTES) {
            L->too_big = true;
            break;
        }
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

bool ske__is_elem(const xmlNode *n, const char *name, bool ext)
{
    if (n->type != XML_ELEMENT_NODE || strcmp((const char *)n->name, name) != 0)
        return false;
    bool in_ext = n->ns && n->ns->href && strcmp((const char *)n->ns->href, SKE_EXT_NS) == 0;
    return ext ? in_ext : !n->ns;
}

/* Attribute value copied into buf; false when absent. */
bool ske__attr(const xmlNode *n, const char *name, char *buf, size_t len)
{
    xmlChar *v = xmlGetNoNsProp(n, (const xmlChar *)name);
    if (!v)
        return false;
    snprintf(buf, len, "%s", (const char *)v);
    xmlFree(v);
    return true;
}

bool ske__attr_seconds(ske_loader_t *L, const xmlNode *n, const char *name, int64_t *ns,
                       bool required)
{
    char buf[128];
    if (!ske__attr(n, name, buf, sizeof buf)) {
        if (required)
            ske__fail(L, n, "required attribute", "attribute %s is missing", name);
        return false;
    }
    if (!ske_parse_seconds(buf, ns)) {
        ske__fail(L, n, "durations are decimal seconds",
                  "%s='%s' is not a valid duration: expected decimal seconds such as 0.010, "
                  "at most 9 decimals and at most %lld s", name, buf,
                  (long long)(INT64_MAX / 1000000000LL - 10));
        return false;
    }
    return true;
}

bool ske__attr_u64(ske_loader_t *L, const xmlNode *n, const char *name, uint64_t *v, uint64_t max,
                   bool required)
{
    char buf[128];
    if (!ske__attr(n, name, buf, sizeof buf)) {
        if (required)
            ske__fail(L, n, "required attribute", "attribute %s is missing", name);
        return false;
    }
    if (!ske_parse_u64(buf, v) || *v > max) {
        ske__fail(L, n, "numbers are non-negative integers",
                  "%s='%s' is not a valid number (expected an integer from 0 to %llu)", name, buf,
                  (unsigned long long)max);
        return false;
    }
    return true;
}

bool ske__attr_bool(const xmlNode *n, const char *name, bool dflt)
{
    char buf[16];
    if (!ske__attr(n, name, buf, sizeof buf))
        return dflt;
    return strcmp(buf, "true") == 0 || strcmp(buf, "1") == 0;
}

bool ske__attr_name(ske_loader_t *L, const xmlNode *n, const char *name, char *out)
{
    char buf[256];
    if (!ske__attr(n, name, buf, sizeof buf)) {
        ske__fail(L, n, "required attribute", "attribute %s is missing", name);
        return false;
    }
    if (strlen(buf) >= SKE_NAME_MAX) {
        ske__fail(L, n, "names have at most 30 characters", "%s='%s' is too long", name, buf);
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
int ske__partition_ref(ske_loader_t *L, const xmlNode *n)
{
    uint64_t id;
    char name[SKE_NAME_MAX];
    if (!ske__attr_u64(L, n, "PartitionIdentifier", &id, INT32_MAX, true) ||
        !ske__attr_name(L, n, "PartitionName", name))
        return -1;
    int i = ske_config_partition_by_id(L->m, (int32_t)id);
    if (i < 0) {
        ske__fail(L, n, "references name a declared Partition",
                  "unknown partition: no Partition has PartitionIdentifier=%llu (PartitionName='%s')",
                  (unsigned long long)id, name);
        return -1;
    }
    if (strcmp(L->m->partitions[i].name, name) != 0) {
        ske__fail(L, n, "PartitionIdentifier and PartitionName name the same partition",
                  "PartitionIdentifier=%llu is partition '%s', not '%s'", (unsigned long long)id,
                  L->m->partitions[i].name, name);
        return -1;
    }
    return i;
}

/* ---- schema validation ---------------------------------------------------------------- */

static void schema_error(void *ctx, xmlErrorPtr err)
{
    ske_loader_t *L = ctx;
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
    int line = node && node->type == XML_ELEMENT_NODE ? ske__line_of(L, node) : err->line;
    /* Say what a malformed number means rather than quoting the schema's regular expression. */
    char value[128] = "";
    if (attr_name_s && node)
        ske__attr(node, attr_name_s, value, sizeof value);
    size_t an = attr_name_s ? strlen(attr_name_s) : 0;
    bool value_error = strstr(msg, "is not a valid value") || strstr(msg, "[facet");
    const char *max = strstr(msg, "maximum value allowed ('");
    if (!value_error)
        attr_name_s = NULL; /* a missing or unexpected attribute: the validator says it best */
    if (attr_name_s && max) {
        char lim[32] = "";
        sscanf(max + strlen("maximum value allowed ('"), "%31[0-9]", lim);
        ske__diag_set(L->diag, L->m->path, line, elem, "numbers are within their range",
                      "%s='%s' is too large: at most %s", attr_name_s, value, lim);
    } else if (attr_name_s && an > 7 && strcmp(attr_name_s + an - 7, "Seconds") == 0) {
        ske__diag_set(L->diag, L->m->path, line, elem, "durations are decimal seconds",
                      "%s='%s' is not a valid duration: expected decimal seconds such as 0.010, "
                      "at most 9 decimals", attr_name_s, value);
    } else if (attr_name_s && (strstr(attr_name_s, "Identifier") || strstr(attr_name_s, "Size") ||
                               strstr(attr_name_s, "Nb") || strstr(attr_name_s, "Address"))) {
        ske__diag_set(L->diag, L->m->path, line, elem, "numbers are positive integers",
                      "%s='%s' is not a valid number: expected a positive integer%s", attr_name_s,
                      value, strstr(attr_name_s, "Bytes") || strstr(attr_name_s, "Address") ||
                            strstr(attr_name_s, "StackSize") ? " (decimal or 0x-hexadecimal)" : "");
    } else {
        ske__diag_set(L->diag, L->m->path, line, elem, "schema " SKE_SCHEMA_FILE, "%s", msg);
    }
    L->failed = true;
}

void ske__parse_error(void *ctx, xmlErrorPtr err)
{
    ske_loader_t *L = ctx;
    if (L->failed || !err)
        return;
    char msg[768];
    snprintf(msg, sizeof msg, "%s", err->message ? err->message : "XML error");
    size_t n = strlen(msg);
    while (n && (msg[n - 1] == '\n' || msg[n - 1] == ' '))
        msg[--n] = '\0';
    ske__diag_set(L->diag, L->m->path, err->line, "", "well-formed XML", "%s", msg);
    L->failed = true;
}

void ske__xml_silent(void *ctx, const char *msg, ...) { (void)ctx; (void)msg; }

int ske__validate_schema(ske_loader_t *L, xmlDocPtr doc)
{
    char xsd[SKE_PATH_MAX];
    const char *dir = L->opts && L->opts->schema_dir ? L->opts->schema_dir : IMA_SCHEMA_DIR;
    snprintf(xsd, sizeof xsd, "%s/%s", dir, SKE_SCHEMA_FILE);
    if (access(xsd, R_OK) != 0) {
        ske__diag_set(L->diag, xsd, 0, "", "", "cannot read the module schema: %s",
                      strerror(errno));
        return SKE_E_IO;
    }
    int rc = SKE_OK;
    xmlSchemaParserCtxtPtr pctx = xmlSchemaNewParserCtxt(xsd);
    xmlSchemaPtr schema = pctx ? xmlSchemaParse(pctx) : NULL;
    xmlSchemaValidCtxtPtr vctx = schema ? xmlSchemaNewValidCtxt(schema) : NULL;
    if (!vctx) {
        ske__diag_set(L->diag, xsd, 0, "", "", "the module schema itself is invalid");
        rc = SKE_E_IO;
        goto out;
    }
    xmlSchemaSetValidStructuredErrors(vctx, schema_error, L);
    if (xmlSchemaValidateDoc(vctx, doc) != 0) {
        if (!L->failed)
            ske__fail(L, xmlDocGetRootElement(doc), "schema " SKE_SCHEMA_FILE,
                      "document does not validate");
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
