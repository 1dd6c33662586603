/* SPDX-License-Identifier: Apache-2.0 */
/* The trace writer (src/trace.c) writes, byte for byte, what the plain fprintf writer it
 * replaced wrote (kept here as the reference): every kind of field, strings that need
 * escaping (quotes, backslashes, new lines, control bytes, bytes past ASCII), strings longer
 * than its line pieces, the extreme integers. Traces of earlier runs stay comparable. */
#include "ske__trace.h"
#include "ske_test.h"

#include <stdlib.h>
#include <unistd.h>

/* ---- the reference: the writer as it was, one fprintf or fputc at a time ---------------- */

static void ref_escape(FILE *f, const char *s, size_t len)
{
    fputc('"', f);
    for (size_t i = 0; i < len; i++) {
        unsigned char c = (unsigned char)s[i];
        if (c == '"' || c == '\\')
            fprintf(f, "\\%c", c);
        else if (c == '\n')
            fputs("\\n", f);
        else if (c < 0x20 || c >= 0x7f)
            fprintf(f, "\\u%04x", c);
        else
            fputc(c, f);
    }
    fputc('"', f);
}

static void ref_begin(FILE *f, const char *node, int64_t t_ns, const char *src, const char *kind)
{
    fprintf(f, "{\"t_ns\":%" PRId64 ",\"node\":", t_ns);
    ref_escape(f, node, strlen(node));
    fputs(",\"src\":", f);
    ref_escape(f, src, strlen(src));
    fputs(",\"kind\":", f);
    ref_escape(f, kind, strlen(kind));
}

static void ref_strn(FILE *f, const char *key, const char *v, size_t len)
{
    fprintf(f, ",\"%s\":", key);
    ref_escape(f, v, len);
}

/* ---- both writers on the same events ------------------------------------------------------ */

static char *slurp(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    char *buf = malloc(1 << 20);
    *len = buf ? fread(buf, 1, 1 << 20, f) : 0;
    fclose(f);
    return buf;
}

static void test_same_bytes_as_the_reference(void)
{
    char dir[] = "/tmp/ske_test_trace.XXXXXX";
    REQUIRE(mkdtemp(dir) != NULL);
    char path[128], ref_path[128];
    snprintf(path, sizeof path, "%s/new.jsonl", dir);
    snprintf(ref_path, sizeof ref_path, "%s/ref.jsonl", dir);

    /* strings: plain, every byte value once (NUL too: the lengths are given), and long ones
     * (past a line piece's 256 bytes) */
    char every[256], longs[2][1000];
    for (int i = 0; i < 256; i++)
        every[i] = (char)i;
    for (int i = 0; i < 1000; i++) {
        longs[0][i] = (char)('a' + i % 26);
        longs[1][i] = (char)(i % 7 == 0 ? '"' : i % 11 == 0 ? 0x01 : 'x');
    }
    const int64_t ints[] = {0, 1, -1, 9, 10, 42, -42, 999999999, 1000000000, INT64_MAX, INT64_MIN,
                            INT64_MIN + 1, 350000000};

    ske_trace_t t;
    REQUIRE(ske_trace_open(&t, path, "node\"1\\") == 0);
    FILE *r = fopen(ref_path, "w");
    REQUIRE(r != NULL);
    const char *node = "node\"1\\";
    for (size_t k = 0; k < sizeof ints / sizeof ints[0]; k++) {
        int64_t v = ints[k];
        ske_trace_begin(&t, v, "ske", "window_end");
        ref_begin(r, node, v, "ske", "window_end");
        ske_trace_str(&t, "partition", "nav_fcs");
        ref_strn(r, "partition", "nav_fcs", 7);
        ske_trace_int(&t, "window", v);
        fprintf(r, ",\"%s\":%" PRId64, "window", v);
        ske_trace_bool(&t, "yielded", k % 2 == 0);
        fprintf(r, ",\"%s\":%s", "yielded", k % 2 == 0 ? "true" : "false");
        ske_trace_raw(&t, "members", "[1,2,3]");
        fprintf(r, ",\"%s\":%s", "members", "[1,2,3]");
        ske_trace_end(&t);
        fputs("}\n", r);
    }
    ske_trace_begin(&t, 5, "app\n", "a\x7f" "b");
    ref_begin(r, node, 5, "app\n", "a\x7f" "b");
    ske_trace_strn(&t, "text", every, sizeof every);
    ref_strn(r, "text", every, sizeof every);
    ske_trace_strn(&t, "long", longs[0], sizeof longs[0]);
    ref_strn(r, "long", longs[0], sizeof longs[0]);
    ske_trace_strn(&t, "escaped", longs[1], sizeof longs[1]);
    ref_strn(r, "escaped", longs[1], sizeof longs[1]);
    ske_trace_strn(&t, "empty", "", 0);
    ref_strn(r, "empty", "", 0);
    ske_trace_end(&t);
    fputs("}\n", r);
    /* ske_json_escape alone, as the statistics file uses it */
    ske_json_escape(t.f, every, sizeof every);
    ref_escape(r, every, sizeof every);
    CHECK_EQ(ske_trace_close(&t), 0);
    fclose(r);

    size_t n_new = 0, n_ref = 0;
    char *a = slurp(path, &n_new), *b = slurp(ref_path, &n_ref);
    REQUIRE(a != NULL && b != NULL);
    CHECK(n_ref > 6000);
    CHECK_EQ_U(n_new, n_ref);
    CHECK(n_new == n_ref && memcmp(a, b, n_new) == 0);
    free(a);
    free(b);
    unlink(path);
    unlink(ref_path);
    rmdir(dir);
}

int main(void)
{
    RUN(test_same_bytes_as_the_reference);
    return ske_test_result();
}
