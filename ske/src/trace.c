/* SPDX-License-Identifier: Apache-2.0 */
/* JSON-lines trace writer of the SKE. */
#include "ske__trace.h"

#include <errno.h>
#include <inttypes.h>
#include <string.h>

int ske_trace_open(ske_trace_t *t, const char *path, const char *node)
{
    memset(t, 0, sizeof *t);
    snprintf(t->node, sizeof t->node, "%s", node);
    if (!path)
        return 0;
    if (strcmp(path, "-") == 0) {
        t->f = stdout;
        return 0;
    }
    t->f = fopen(path, "w");
    if (!t->f)
        return -errno;
    t->owned = true;
    setvbuf(t->f, NULL, _IOFBF, 1 << 16);
    return 0;
}

int ske_trace_close(ske_trace_t *t)
{
    int rc = 0;
    if (t->f) {
        if (fflush(t->f) != 0 || ferror(t->f))
            rc = -(errno ? errno : EIO);
        if (t->owned && fclose(t->f) != 0 && rc == 0)
            rc = -(errno ? errno : EIO);
    }
    t->f = NULL;
    return rc;
}

void ske_json_escape(FILE *f, const char *s, size_t len)
{
    fputc('"', f);
    for (size_t i = 0; i < len; i++) {
        unsigned char c = (unsigned char)s[i];
        if (c == '"' || c == '\\')
            fprintf(f, "\\%c", c);
        else if (c == '\n')
            fputs("\\n", f);
        else if (c < 0x20 || c >= 0x7f)
            fprintf(f, "\\u%04x", c); /* bytes, not UTF-8: keep the line valid JSON */
        else
            fputc(c, f);
    }
    fputc('"', f);
}

void ske_trace_begin(ske_trace_t *t, int64_t t_ns, const char *src, const char *kind)
{
    if (!t->f)
        return;
    fprintf(t->f, "{\"t_ns\":%" PRId64 ",\"node\":", t_ns);
    ske_json_escape(t->f, t->node, strlen(t->node));
    fputs(",\"src\":", t->f);
    ske_json_escape(t->f, src, strlen(src));
    fputs(",\"kind\":", t->f);
    ske_json_escape(t->f, kind, strlen(kind));
}

void ske_trace_strn(ske_trace_t *t, const char *key, const char *val, size_t len)
{
    if (!t->f)
        return;
    fprintf(t->f, ",\"%s\":", key);
    ske_json_escape(t->f, val, len);
}

void ske_trace_str(ske_trace_t *t, const char *key, const char *val)
{
    ske_trace_strn(t, key, val, strlen(val));
}

void ske_trace_int(ske_trace_t *t, const char *key, int64_t v)
{
    if (t->f)
        fprintf(t->f, ",\"%s\":%" PRId64, key, v);
}

void ske_trace_bool(ske_trace_t *t, const char *key, bool v)
{
    if (t->f)
        fprintf(t->f, ",\"%s\":%s", key, v ? "true" : "false");
}

void ske_trace_raw(ske_trace_t *t, const char *key, const char *json)
{
    if (t->f)
        fprintf(t->f, ",\"%s\":%s", key, json);
}

void ske_trace_end(ske_trace_t *t)
{
    if (t->f)
        fputs("}\n", t->f);
}

void ske_trace_maybe_flush(ske_trace_t *t, int64_t mono_ns)
{
    if (t->f && mono_ns - t->last_flush_mono_ns > 50000000LL) {
        fflush(t->f);
        t->last_flush_mono_ns = mono_ns;
    }
}
