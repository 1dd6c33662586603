/* SPDX-License-Identifier: Apache-2.0 */
/* The recorder's C path (include/trace_mcap/trace_mcap.h): what it writes for a bus line and
 * an SKE line, numbers as orjson writes them, a chunk filling up between a frame's two
 * messages, and mutated lines by the thousand (run under ASan+UBSan too): every line is either
 * converted or handed back, nothing is read or written out of bounds. The byte-for-byte
 * comparison with the Python is tests/recording/test_fast.py. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "trace_mcap/trace_mcap.h"
#include "rpas/unit_check.h"

static const char FRAME[] =
    "{\"t_ns\":480000,\"node\":\"canbus\",\"src\":\"canbus\",\"kind\":\"can_tx\","
    "\"start_ns\":320000,\"id\":291,\"ext\":true,\"len\":4,\"data\":\"d2040cfe\","
    "\"from\":\"world\",\"client\":1}";
static const char EXTRA[] = ",\"error\":false,\"name\":\"M\"";

static void check_double(double x, const char *want)
{
    char buf[40];
    size_t n = tm_format_double(x, buf);
    buf[n] = '\0';
    if (strcmp(buf, want) != 0) {
        fprintf(stderr, "tm_format_double(%.17g): '%s', want '%s'\n", x, buf, want);
        unit_failures++;
    }
}

/* A converter of the bus's trace that knows message 291 (M: A u16 scale 0.01, B s16 plain)
 * and its frames' added fields. */
static tm_conv_t *can_converter(void)
{
    tm_conv_t *c = tm_new(TM_CAN);
    CHECK(c != NULL);
    tm_set_channel(c, TM_CAN_FRAMES, 1);
    CHECK(tm_can_message(c, 291, 4, 2, 1) == 0);
    CHECK(tm_can_signal(c, 291, 0, 16, 0, 0, 0.01, 0.0, "\"A\":") == 0);
    CHECK(tm_can_signal(c, 291, 16, 16, 1, 1, 1.0, 0.0, "\"B\":") == 0);
    CHECK(tm_can_key(c, 291, 1, EXTRA, strlen(EXTRA)) == 0);
    return c;
}

/* The data of the k-th message record of out (its header is 31 bytes). */
static const char *record_data(const tm_result_t *r, int k, size_t *n)
{
    size_t off = 0;
    for (int i = 0;; i++) {
        CHECK(off + 31 <= r->out_len && r->out[off] == 0x05);
        uint64_t len = 0;
        for (int b = 0; b < 8; b++)
            len |= (uint64_t)r->out[off + 1 + b] << (8 * b);
        if (i == k) {
            *n = (size_t)len - 22;
            return (const char *)r->out + off + 31;
        }
        off += 9 + (size_t)len;
    }
}

static void test_a_frame(void)
{
    tm_conv_t *c = can_converter();
    char text[512];
    snprintf(text, sizeof text, "%s\n", FRAME);
    tm_result_t r;
    CHECK(tm_convert(c, (const uint8_t *)text, strlen(text), 7, 100, 1 << 20, 0, &r) == TM_DONE);
    CHECK(r.lines == 1 && r.consumed == strlen(text));
    size_t n;
    const char *d = record_data(&r, 0, &n);
    char want[512];
    snprintf(want, sizeof want, "%.*s%s,\"seq\":7}", (int)strlen(FRAME) - 1, FRAME, EXTRA);
    CHECK(n == strlen(want) && memcmp(d, want, n) == 0);
    d = record_data(&r, 1, &n);
    static const char sig[] = "{\"A\":12.34,\"B\":-500,\"t_ns\":480000,\"from\":\"world\"}";
    CHECK(n == strlen(sig) && memcmp(d, sig, n) == 0);
    const uint16_t *cids;
    const uint64_t *pairs;
    CHECK(tm_channels(c, &cids) == 2 && cids[0] == 1 && cids[1] == 2);
    CHECK(tm_entries(c, 1, &pairs) == 2 && pairs[0] == 480000 && pairs[1] == 100);
    /* the chunk is full after the frame's first message: its second comes on resuming */
    CHECK(tm_convert(c, (const uint8_t *)text, strlen(text), 7, 0, 10, 0, &r) == TM_FULL);
    CHECK(r.part == 1 && r.lines == 0 && r.consumed == 0);
    CHECK(tm_convert(c, (const uint8_t *)text, strlen(text), 7, 0, 1 << 20, 1, &r) == TM_DONE);
    d = record_data(&r, 0, &n);
    CHECK(r.lines == 1 && n == strlen(sig) && memcmp(d, sig, n) == 0);
    /* an id it was not told about, an event: the Python's */
    static const char other[] = "{\"t_ns\":1,\"kind\":\"can_tx\",\"id\":5,\"data\":\"\"}\n";
    CHECK(tm_convert(c, (const uint8_t *)other, strlen(other), 0, 0, 1 << 20, 0, &r) ==
          TM_PYTHON);
    CHECK(r.lines == 0 && r.out_len == 0);
    tm_free(c);
}

static void test_an_ske_line(void)
{
    tm_conv_t *c = tm_new(TM_SKE);
    static const char text[] = "{\"t_ns\":5000000,\"kind\":\"window_start\",\"window\":1}\n"
                               "{\"t_ns\":6000000,\"kind\":\"hm\"}\n";
    tm_result_t r;
    CHECK(tm_convert(c, (const uint8_t *)text, strlen(text), 0, 0, 1 << 20, 0, &r) ==
          TM_PYTHON); /* no channel yet */
    tm_set_channel(c, TM_SKE_SCHEDULE, 4);
    tm_set_channel(c, TM_SKE_HM, 5);
    tm_set_channel(c, TM_SKE_OTHER, 6);
    CHECK(tm_convert(c, (const uint8_t *)text, strlen(text), 0, 0, 1 << 20, 0, &r) == TM_DONE);
    CHECK(r.lines == 2);
    const uint16_t *cids;
    CHECK(tm_channels(c, &cids) == 2 && cids[0] == 4 && cids[1] == 5);
    tm_free(c);
}

static void test_numbers(void)
{
    check_double(0.0, "0.0");
    check_double(-0.0, "-0.0");
    check_double(1.0, "1.0");
    check_double(12.34, "12.34");
    check_double(12.340000000000002, "12.340000000000002");
    check_double(1e-5, "0.00001");
    check_double(1e-6, "1e-6");
    check_double(1e16, "1e+16");
    check_double(1234567890123456.0, "1234567890123456.0");
    check_double(-1.5e300, "-1.5e+300");
    check_double(5e-324, "5e-324");
    char buf[40];
    CHECK(tm_format_double(0.0 / 0.0, buf) == 0);
    CHECK(tm_format_double(1.0 / 0.0, buf) == 0);
}

/* Thousands of mutated lines: each is converted or handed back, within bounds. */
static void test_mutated_lines(void)
{
    static const char ske[] = "{\"t_ns\":5000000,\"node\":\"node1\",\"kind\":\"window_end\"}";
    static const char alphabet[] = "{}[]\":,\\-0123456789.eE tfnul\x01\xff";
    unsigned seed = 12345;
    for (int kind = TM_CAN; kind <= TM_SKE; kind++) {
        tm_conv_t *c = kind == TM_CAN ? can_converter() : tm_new(TM_SKE);
        for (int w = 0; w < 3; w++)
            tm_set_channel(c, w, (uint16_t)(3 + w));
        const char *seed_line = kind == TM_CAN ? FRAME : ske;
        int converted = 0;
        for (int i = 0; i < 20000; i++) {
            char line[600];
            size_t n = strlen(seed_line);
            memcpy(line, seed_line, n);
            for (int m = 0; m < 1 + (int)(rand_r(&seed) % 4); m++) {
                size_t at = n ? rand_r(&seed) % n : 0;
                switch (rand_r(&seed) % 4) {
                case 0: line[at] = alphabet[rand_r(&seed) % (sizeof alphabet - 1)]; break;
                case 1: n = at; break;                                  /* cut */
                case 2:                                                 /* insert */
                    if (n < sizeof line - 2) {
                        memmove(line + at + 1, line + at, n - at);
                        line[at] = alphabet[rand_r(&seed) % (sizeof alphabet - 1)];
                        n++;
                    }
                    break;
                default: if (n) memmove(line + at, line + at + 1, n - at - 1), n--; break;
                }
            }
            for (size_t k = 0; k < n; k++)
                if (line[k] == '\n')
                    line[k] = ' ';
            uint8_t *text = malloc(n + 1); /* exactly the line: ASan sees any overread */
            memcpy(text, line, n);
            text[n] = '\n';
            tm_result_t r;
            int rc = tm_convert(c, text, n + 1, (uint64_t)i, 0, 1 << 20, 0, &r);
            CHECK(rc == TM_DONE || rc == TM_PYTHON);
            CHECK((rc == TM_DONE && r.lines == 1 && r.consumed == n + 1) ||
                  (rc == TM_PYTHON && r.lines == 0 && r.out_len == 0));
            converted += rc == TM_DONE;
            free(text);
        }
        /* the mutations reach past the reader: a fair share still converts */
        fprintf(stderr, "%s lines: %d of 20000 converted\n", kind == TM_CAN ? "bus" : "SKE",
                converted);
        CHECK(converted > 1000);
        tm_free(c);
    }
}

/* ---- flight data recorder records (tm_fdr) ---- */

static uint32_t test_crc32(const uint8_t *p, size_t n)
{
    uint32_t c = 0xFFFFFFFFu;
    for (size_t i = 0; i < n; i++) {
        c ^= p[i];
        for (int k = 0; k < 8; k++)
            c = c & 1 ? 0xEDB88320u ^ (c >> 1) : c >> 1;
    }
    return ~c;
}

static void put32(uint8_t *p, uint32_t v) { memcpy(p, &v, 4); }
static void put64(uint8_t *p, uint64_t v) { memcpy(p, &v, 8); }

/* A record: header (magic, version, kind, seq, body length, t_ns), zero body, CRC. */
static void fdr_record(uint8_t *rec, uint16_t kind, uint32_t body_len, int64_t t_ns)
{
    memset(rec, 0, 320);
    put32(rec, 0x31524446u);
    rec[4] = 1;
    memcpy(rec + 6, &kind, 2);
    put32(rec + 8, 7);
    put32(rec + 12, body_len);
    put64(rec + 16, (uint64_t)t_ns);
}

static void fdr_seal(uint8_t *rec) { put32(rec + 316, test_crc32(rec, 316)); }

static void test_fdr_records(void)
{
    uint8_t file[4 * 320];
    fdr_record(file, 2, 248, 100); /* a frame with its navigation message only */
    put32(file + 24, 3);
    put32(file + 28, 1);
    double nav[4] = {1.5, 0.0 / 0.0, 0.1, 1e-7};
    put64(file + 32, (uint64_t)-5);
    put32(file + 40, 9);
    memcpy(file + 48, nav, sizeof nav);
    fdr_seal(file);
    fdr_record(file + 320, 2, 248, 200); /* torn: a bad CRC */
    fdr_record(file + 640, 2, 100, 300); /* torn: a body too short for a frame */
    fdr_seal(file + 640);
    fdr_record(file + 960, 1, 48, 400); /* a start record: the Python's */
    fdr_seal(file + 960);

    tm_conv_t *c = tm_new(TM_FDR);
    CHECK(c != NULL);
    tm_result_t r;
    CHECK(tm_fdr(c, file, 4, 0, 0, 0, 1 << 20, &r) == TM_PYTHON); /* no channel yet */
    CHECK(r.consumed == 0 && r.lines == 0);
    tm_set_channel(c, TM_FDR_RECORDS, 6);
    CHECK(tm_fdr(c, file, 4, 0, 11, 50, 1 << 20, &r) == TM_PYTHON);
    CHECK(r.consumed == 3 && r.lines == 1);
    size_t n;
    const char *d = record_data(&r, 0, &n);
    const char *want =
        "{\"kind\":\"frame\",\"seq\":7,\"t_ns\":100,\"offset\":0,\"frame\":3,\"nav\":"
        "{\"t_ns\":-5,\"flags\":9,\"lat_deg\":1.5,\"lon_deg\":null,\"alt_ft\":0.1,"
        "\"ias_kt\":1e-7,\"gs_kt\":0.0,\"trk_deg\":0.0,\"hdg_deg\":0.0,\"vs_fpm\":0.0,"
        "\"roll_deg\":0.0,\"pitch_deg\":0.0,\"wind_n_kt\":0.0,\"wind_e_kt\":0.0},"
        "\"status\":null,\"mission\":null}";
    CHECK(d && n == strlen(want) && memcmp(d, want, n) == 0);
    const uint64_t *pairs;
    CHECK(tm_entries(c, 6, &pairs) == 2 && pairs[0] == 100 && pairs[1] == 50);
    CHECK(tm_fdr(c, file, 4, 4, 12, 0, 1 << 20, &r) == TM_DONE && r.consumed == 4);
    /* no room: one record all the same (the caller's chunk is then full), then TM_FULL */
    CHECK(tm_fdr(c, file, 4, 0, 0, 0, 0, &r) == TM_FULL && r.consumed == 1 && r.lines == 1);
    CHECK(tm_fdr(c, file, 1, 0, 0, 0, 0, &r) == TM_DONE && r.consumed == 1 && r.lines == 1);
    tm_conv_t *ske = tm_new(TM_SKE); /* another kind of converter: nothing done */
    CHECK(tm_fdr(ske, file, 4, 0, 0, 0, 1 << 20, &r) == TM_NOMEM && r.lines == 0);
    CHECK(tm_convert(c, (const uint8_t *)"x\n", 2, 0, 0, 1 << 20, 0, &r) == TM_NOMEM);
    CHECK(r.lines == 0 && r.out_len == 0);
    tm_free(ske);

    /* frame records of random content with a good CRC, each in a buffer of its own size: every
     * one converted, nothing read out of bounds (ASan) */
    unsigned seed = 777;
    for (int i = 0; i < 5000; i++) {
        uint8_t *rec = malloc(320);
        fdr_record(rec, 2, 248 + rand_r(&seed) % 45, (int64_t)rand_r(&seed) - RAND_MAX / 2);
        for (int k = 24; k < 316; k++)
            rec[k] = (uint8_t)rand_r(&seed);
        fdr_seal(rec);
        CHECK(tm_fdr(c, rec, 1, 0, 0, 0, 1 << 20, &r) == TM_DONE && r.lines == 1);
        free(rec);
    }
    tm_free(c);
}

/* tm_count_lines against a count a byte at a time, on random text of newlines and NULs and
 * on every length and offset around memchr's vector widths. */
static void test_count_lines(void)
{
    CHECK(tm_count_lines((const uint8_t *)"", 0) == 0);
    CHECK(tm_count_lines((const uint8_t *)"\n", 1) == 1);
    CHECK(tm_count_lines((const uint8_t *)"a\nb", 3) == 1);
    uint8_t buf[300];
    unsigned x = 7;
    for (int round = 0; round < 200; round++) {
        for (size_t i = 0; i < sizeof buf; i++) {
            x = x * 1103515245u + 12345u;
            unsigned v = (x >> 16) % 5;
            buf[i] = v == 0 ? '\n' : v == 1 ? 0 : (uint8_t)('a' + v);
        }
        size_t from = (size_t)round % 70, len = sizeof buf - from - (size_t)round % 33;
        uint64_t want = 0;
        for (size_t i = from; i < from + len; i++)
            want += buf[i] == '\n';
        CHECK(tm_count_lines(buf + from, len) == want);
    }
}

int main(void)
{
    test_count_lines();
    test_fdr_records();
    test_numbers();
    test_a_frame();
    test_an_ske_line();
    test_mutated_lines();
    if (unit_failures)
        fprintf(stderr, "%d failure(s)\n", unit_failures);
    return unit_failures ? 1 : 0;
}
